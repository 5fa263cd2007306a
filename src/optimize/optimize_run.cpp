#include "poundsim/optimize/optimize_run.hpp"

#include <algorithm>
#include <array>
#include <chrono>
#include <exception>
#include <cmath>
#include <limits>
#include <map>
#include <string_view>
#include <string>
#include <utility>

#include <fmt/format.h>
#include <nlopt.hpp>

#include "poundsim/error.hpp"
#include "poundsim/analysis/frequency_response.hpp"
#include "poundsim/io/frequency_response_run.hpp"
#include "poundsim/io/output_files.hpp"
#include "poundsim/io/study_run.hpp"
#include "poundsim/analysis/response_metrics.hpp"

namespace poundsim::optimize {

using namespace io;  // the reader, the study points and the output files of a run

namespace {

using nlohmann::json;

/// Objective value of an evaluation that could not be run (a combination the input rejects).
constexpr double kRejected = 1e30;

nlopt::algorithm algorithm(const std::string& name, const RunInput& input, const char* key) {
  const int a = static_cast<int>(nlopt_algorithm_from_string(name.c_str()));
  if (a < 0) {
    throw InputError(fmt::format("{}: optimize.{}: \"{}\" is not an NLopt algorithm name (e.g. "
                                 "GN_DIRECT_L, GN_CRS2_LM, LN_BOBYQA, LN_NELDERMEAD)",
                                 input.source.string(), key, name));
  }
  if (name.size() > 1 && name[1] == 'D') {  // GD_… and LD_…
    throw InputError(fmt::format("{}: optimize.{}: \"{}\" needs gradients, which a pounding response "
                                 "does not have; use a derivative-free (GN_/LN_) algorithm",
                                 input.source.string(), key, name));
  }
  return static_cast<nlopt::algorithm>(a);
}

/// The overrides that set the design variables to `x`.
PointValues point_values(const OptimizeSettings& settings, const std::vector<double>& x) {
  PointValues values;
  for (std::size_t i = 0; i < x.size(); ++i) values.push_back(make_setting(settings.variables[i].key, {x[i]}));
  return values;
}

constexpr double kNone = std::numeric_limits<double>::quiet_NaN();

/// What evaluating a design gave, wherever and whenever it was computed (this process, another
/// rank, an earlier run of the same input whose database this run reads).
struct Outcome {
  std::string status = "done", error;  ///< done | rejected (the input refuses the design) | failed
  PointFigures figures;
  bool from_database = false;
  std::vector<double> metrics;  ///< Per Problem::metrics(); NaN when not done or not a figure.
};

/// One design as a stage of the search asked for it: its outcome and the values of the figures
/// the goals ask for. A speculative one (no outcome) is a guess the search made while designs it
/// needs are computed: it never outlives that search (see Problem).
struct Evaluation {
  std::vector<double> x;
  std::string stage, status, error;
  const PointFigures* figures = nullptr;  ///< The outcome's, which outlives the evaluation.
  std::vector<double> metrics;            ///< Per Problem::metrics(); NaN when not done or not a figure.
  bool from_database = false;
};

/// Figures already as bytes (to_bytes), carried inside a CBOR document as a byte string, and back.
json as_binary(const std::string& bytes) { return json::binary(std::vector<std::uint8_t>(bytes.begin(), bytes.end())); }
std::string from_binary(const json& value) {
  const auto& binary = value.get_binary();
  return {binary.begin(), binary.end()};
}

/// The bytes of an outcome, as the database keeps it and the ranks send it.
std::string outcome_bytes(const Outcome& o) {
  json value{{"status", o.status}, {"error", o.error}};
  if (o.status == "done") value["figures"] = as_binary(to_bytes(o.figures));
  return io::cbor_bytes(value);
}

Outcome outcome_from_bytes(const std::string& bytes) {
  const json value = json::from_cbor(bytes);
  Outcome o{value.at("status").get<std::string>(), value.at("error").get<std::string>(), {}, false, {}};
  if (value.contains("figures")) o.figures = point_figures_from_bytes(from_binary(value["figures"]));
  return o;
}

/// A limit on metric `metric` (an index into Problem::metrics()), as NLopt's c(x) ≤ 0.
struct Bound {
  std::size_t metric = 0;
  double limit = 0;
  bool upper = true;
  /// How far `value` breaks the limit, relative to it (absolute for a limit of 0); kRejected
  /// when there is no value.
  [[nodiscard]] double violation(double value) const {
    if (std::isnan(value)) return kRejected;
    const double scale = limit != 0 ? std::abs(limit) : 1.0;
    const double v = (upper ? value - limit : limit - value) / scale;
    return std::isfinite(v) ? v : kRejected;
  }
};

/// What one optimisation minimises, subject to what.
struct Goal {
  std::size_t objective = 0;  ///< An index into Problem::metrics().
  std::vector<Bound> bounds;
  std::string label;          ///< Prefix of its stages' names ("" for the main one).
};

/// A design's evaluation run here, with `threads` for its frequencies or records.
/// On a rank, any other error is an outcome too ("error"): the design may be a guess the search
/// never asks for, whose error must not end the job (Problem::evaluate_pending).
Outcome compute_design(const RunInput& input, const std::vector<double>& x, int threads, bool on_a_rank) {
  Outcome o;
  try {
    o.figures = point_figures(with_settings(input, point_values(*input.optimize, x)), threads, nullptr);
  } catch (const InputError& e) {
    o.status = "rejected";
    o.error = e.what();
  } catch (const SimulationError& e) {
    o.status = "failed";
    o.error = e.what();
  } catch (const std::exception& e) {
    if (!on_a_rank) throw;
    o.status = "error";
    o.error = e.what();
  }
  return o;
}

/// A task for any rank: a whole design (x), or one record of an ensemble design (x, the record
/// and its scale factor). Its result: the design's outcome, or the record's figures or the
/// error that stopped it.
std::string design_task(const std::vector<double>& x) { return io::cbor_bytes(json{{"x", x}}); }
std::string record_task(const std::vector<double>& x, std::size_t record, std::optional<double> factor) {
  return io::cbor_bytes(json{{"x", x}, {"record", record}, {"factor", factor ? json(*factor) : json()}});
}

/// The point of the last design a rank computed records of: an evaluation's records come one
/// after another, and reading the input with a design's values costs more than a short record.
struct LastPoint {
  std::vector<double> x;
  std::optional<RunInput> point;
};

std::string compute_task(const RunInput& input, const std::string& task_bytes, LastPoint& last) {
  const json task = json::from_cbor(task_bytes);
  const std::vector<double> x = task.at("x").get<std::vector<double>>();
  if (!task.contains("record")) return outcome_bytes(compute_design(input, x, 1, true));
  json result;
  try {
    if (!last.point || last.x != x) {
      last.point.reset();
      last.point = with_settings(input, point_values(*input.optimize, x));
      last.x = x;
    }
    const std::optional<double> factor = task.at("factor").is_null() ? std::nullopt : std::optional<double>(task.at("factor").get<double>());
    result = json{{"figures", as_binary(to_bytes(record_figures(*last.point, task.at("record").get<std::size_t>(), factor)))}};
  } catch (const InputError& e) {
    result = json{{"rejected", e.what()}};
  } catch (const SimulationError& e) {
    result = json{{"failed", e.what()}};
  } catch (const std::exception& e) {
    result = json{{"error", e.what()}};
  }
  return io::cbor_bytes(result);
}

/// The designs a search needs but has not evaluated: it stops (thrown through NLopt) so that
/// they are computed, then starts again from the beginning.
struct NeedEvaluations {};

/// Every evaluation of the search, asked for in the order NLopt asks for them.
///
/// NLopt asks for one design at a time, and its next design may depend on the last one's
/// value; but it is deterministic: the same seed and the same values give the same designs. So
/// the search is run as a replay. Outcomes known (computed, or read from the database of an
/// earlier run of the same input) are answered at once; the first unknown design is where the
/// search really is: alone, it is computed there and the search goes on (one pass, no replay);
/// with ranks to fill, the search goes on past it, answering unknown designs
/// with a guess (a rejected evaluation: late in a search most trial designs are worse, and a
/// population's designs do not depend on the values at all) and collecting them, one batch for
/// the ranks; then the batch is computed at once and the search replayed from its start. A
/// guessed design the replay does not ask for is computed in vain but recorded nowhere but the
/// database: the evaluations, their order and the optimum are those of a search on one process,
/// bit for bit, and a killed run replays from its database with nothing computed twice.
class Problem {
 public:
  Problem(const RunInput& input, std::vector<std::string> metrics, const std::function<void(int, int)>& progress,
          int budget, io::PointDistribution* ranks, io::StudyDatabase& database)
      : input_(input), settings_(*input.optimize), metrics_(std::move(metrics)), progress_(progress), budget_(budget),
        ranks_(ranks), database_(database) {
    for (const auto& [design, outcome] : database_.evaluations()) {
      // The fingerprint matched, so a row that does not read is damage, not another input's.
      std::vector<double> x;
      Outcome o;
      try {
        x = json::from_cbor(design).get<std::vector<double>>();
        o = outcome_from_bytes(outcome);
      } catch (const json::exception& e) {
        throw InputError(fmt::format("{}: a damaged optimisation database (an evaluation does not read: {}); move it "
                                     "away or choose another output folder",
                                     database_.file().string(), e.what()));
      }
      if (x.size() != settings_.variables.size()) {
        throw InputError(fmt::format("{}: a damaged optimisation database (a design of {} values, not {}); move it away "
                                     "or choose another output folder",
                                     database_.file().string(), x.size(), settings_.variables.size()));
      }
      o.from_database = true;
      remember(x, std::move(o));
    }
    const std::size_t records = input.ensemble ? input.ensemble->records.size() : 1;
    if (ranks_ != nullptr) {
      // A design per rank; an ensemble's records already fill the ranks, so fewer designs then.
      batch_ = settings_.each == PointRun::ensemble ? std::max<std::size_t>(1, static_cast<std::size_t>(ranks_->ranks()) / records)
                                                    : static_cast<std::size_t>(ranks_->ranks());
    }
  }

  /// Starts the search again from the beginning: no evaluation asked for yet.
  void replay() {
    evaluations_.clear();
    memo_.clear();
    pending_.clear();
  }

  /// The evaluation at x. An unknown design is pending: the search is stopped (NeedEvaluations)
  /// once a batch of them is collected.
  const Evaluation& operator()(const std::vector<double>& x, const std::string& stage) {
    if (auto it = memo_.find(x); it != memo_.end()) return evaluations_[it->second];
    Evaluation e{x, stage, "speculative", "", nullptr, std::vector<double>(metrics_.size(), kNone), false};
    auto known = known_.find(x);
    if (known == known_.end() && batch_ == 1 && pending_.empty()) {
      // Nothing to batch: computed here, and the search goes on (no replay).
      pending_ = {x};
      evaluate_pending();
      known = known_.find(x);
    }
    if (known != known_.end()) {
      const Outcome& o = known->second;
      e.status = o.status;
      e.error = o.error;
      e.figures = &o.figures;
      e.metrics = o.metrics;
      e.from_database = o.from_database;
    } else {
      pending_.push_back(x);
      if (pending_.size() >= batch_) throw NeedEvaluations{};
    }
    memo_[x] = evaluations_.size();
    evaluations_.push_back(std::move(e));
    // Progress is the search's own, not its guesses'.
    if (pending_.empty() && evaluations_.size() > reported_) {
      reported_ = evaluations_.size();
      if (progress_) progress_(static_cast<int>(evaluations_.size()), budget_);
    }
    return evaluations_.back();
  }

  /// Computes x now unless it is known (the start, before any search).
  void require(const std::vector<double>& x) {
    if (known_.contains(x)) return;
    pending_ = {x};
    evaluate_pending();
  }

  /// The designs the search is waiting for, the first of them where it really is.
  [[nodiscard]] bool waiting() const { return !pending_.empty(); }

  /// Computes the pending designs (all at once, over the ranks when there are ranks) and
  /// records each in the database as it is known.
  void evaluate_pending() {
    std::vector<std::vector<double>> designs;
    designs.swap(pending_);
    if (ranks_ == nullptr) {
      for (const std::vector<double>& x : designs) learn(x, compute_design(input_, x, settings_.threads, false));
      return;
    }
    // The first design is where the search is; the others are guesses. A guess's error other
    // than a rejection or a failure is dropped (the search may never ask for it); the first
    // design's ends the run, as on one process. Each design is recorded as soon as it is known,
    // so that a job killed during a batch loses none that finished.
    std::optional<std::string> search_error;
    const auto known = [&](std::size_t d, Outcome outcome) {
      if (outcome.status != "error") {
        learn(designs[d], std::move(outcome));
      } else if (d == 0) {
        search_error = outcome.error;
      }
    };
    // A design's tasks: itself, or its records; a design the input rejects has none.
    struct Planned {
      std::size_t first_task = 0;
      std::vector<TimeHistoryFigures> records;
      std::vector<std::optional<std::pair<std::string, std::string>>> errors;  ///< A record's (status, message).
      std::size_t arrived = 0;  ///< Records whose result came.
    };
    std::vector<Planned> planned(designs.size());
    std::vector<std::string> tasks;
    std::vector<std::size_t> task_design;
    for (std::size_t d = 0; d < designs.size(); ++d) {
      Planned& p = planned[d];
      p.first_task = tasks.size();
      if (settings_.each != PointRun::ensemble) {
        tasks.push_back(design_task(designs[d]));
        task_design.push_back(d);
        continue;
      }
      try {
        const RunInput point = with_settings(input_, point_values(settings_, designs[d]));
        const std::vector<double> factors = record_factors(point);
        for (std::size_t r = 0; r < point.ensemble->records.size(); ++r) {
          tasks.push_back(record_task(designs[d], r, factors.empty() ? std::nullopt : std::optional<double>(factors[r])));
          task_design.push_back(d);
        }
        p.records.resize(point.ensemble->records.size());
        p.errors.resize(point.ensemble->records.size());
      } catch (const InputError& e) {
        known(d, Outcome{"rejected", e.what(), {}, false, {}});
      } catch (const SimulationError& e) {
        known(d, Outcome{"failed", e.what(), {}, false, {}});
      }
    }
    LastPoint last;
    ranks_->run_phase(
        tasks, [&](const std::string& task) { return compute_task(input_, task, last); },
        [&](std::size_t t, const std::string& bytes) {
          const std::size_t d = task_design[t];
          Planned& p = planned[d];
          if (settings_.each != PointRun::ensemble) {
            known(d, outcome_from_bytes(bytes));
            return;
          }
          const std::size_t r = t - p.first_task;
          const json result = json::from_cbor(bytes);
          if (result.contains("figures")) {
            p.records[r] = time_history_figures_from_bytes(from_binary(result["figures"]));
          } else {
            for (const char* status : {"rejected", "failed", "error"}) {
              if (result.contains(status)) p.errors[r].emplace(status, result[status].get<std::string>());
            }
          }
          if (++p.arrived < p.records.size()) return;
          // Every record is in: the first record's error, whichever rank ran it (as on one
          // process), else the records' figures aggregated in record order.
          Outcome o;
          const auto error = std::find_if(p.errors.begin(), p.errors.end(), [](const auto& e) { return e.has_value(); });
          if (error != p.errors.end()) {
            o.status = (*error)->first;
            o.error = (*error)->second;
          } else {
            o.figures.response = ensemble_figures(p.records);
          }
          known(d, std::move(o));
        },
        {});
    if (search_error) throw std::runtime_error(*search_error);
  }

  /// Designs computed by this run (the search's and its guesses'), and evaluations of the
  /// search read from the database.
  [[nodiscard]] long computed() const { return computed_; }
  [[nodiscard]] long reused() const {
    return std::count_if(evaluations_.begin(), evaluations_.end(), [](const Evaluation& e) { return e.from_database; });
  }

  [[nodiscard]] double objective(const Evaluation& e, const Goal& goal) const {
    const double value = e.metrics[goal.objective];
    return e.status == "done" && !std::isnan(value) ? value : kRejected;
  }
  /// The largest relative violation of the goal's bounds (≤ 0: all hold), kRejected for an
  /// evaluation that did not run.
  [[nodiscard]] double violation(const Evaluation& e, const Goal& goal) const {
    if (e.status != "done") return kRejected;
    double worst = -std::numeric_limits<double>::infinity();
    for (const Bound& b : goal.bounds) worst = std::max(worst, b.violation(e.metrics[b.metric]));
    return worst;
  }
  [[nodiscard]] bool feasible(const Evaluation& e, const Goal& goal) const {
    return e.status == "done" && (goal.bounds.empty() || violation(e, goal) <= settings_.constraint_tolerance);
  }

  /// The goal's best design among every evaluation so far: the feasible one of least objective,
  /// or, when none is feasible, the one that breaks the bounds least.
  [[nodiscard]] const Evaluation* best(const Goal& goal) const {
    const Evaluation* b = nullptr;
    for (const Evaluation& e : evaluations_) {
      if (e.status != "done") continue;
      if (b == nullptr) {
        b = &e;
        continue;
      }
      const bool fe = feasible(e, goal), fb = feasible(*b, goal);
      if (fe != fb) {
        if (fe) b = &e;
      } else if (fe ? objective(e, goal) < objective(*b, goal) : violation(e, goal) < violation(*b, goal)) {
        b = &e;
      }
    }
    return b;
  }

  [[nodiscard]] const std::vector<Evaluation>& evaluations() const { return evaluations_; }
  [[nodiscard]] const std::vector<std::string>& metrics() const { return metrics_; }

 private:
  void learn(const std::vector<double>& x, Outcome outcome) {
    database_.record_evaluation(io::cbor_bytes(json(x)), outcome_bytes(outcome));
    remember(x, std::move(outcome));
    ++computed_;
  }

  /// Keeps an outcome with the values of the figures the goals ask for (read once: a replay
  /// asks for every evaluation again).
  void remember(const std::vector<double>& x, Outcome outcome) {
    outcome.metrics.assign(metrics_.size(), kNone);
    if (outcome.status == "done") {
      for (const FigureColumn& c : outcome.figures.columns()) {
        for (std::size_t m = 0; m < metrics_.size(); ++m) {
          if (c.name == metrics_[m]) outcome.metrics[m] = c.value;
        }
      }
    }
    known_.emplace(x, std::move(outcome));
  }

  const RunInput& input_;
  const OptimizeSettings& settings_;
  std::vector<std::string> metrics_;
  std::function<void(int, int)> progress_;
  int budget_;
  io::PointDistribution* ranks_;  ///< Share the designs of a batch; none: this process.
  io::StudyDatabase& database_;
  std::size_t batch_ = 1;  ///< Designs computed at once.
  /// Every outcome known, by design (std::map: an outcome never moves, evaluations point at it).
  std::map<std::vector<double>, Outcome> known_;
  std::vector<std::vector<double>> pending_;
  long computed_ = 0;
  // The search as replayed so far: its evaluations in order, by design.
  std::map<std::vector<double>, std::size_t> memo_;
  std::vector<Evaluation> evaluations_;
  std::size_t reported_ = 0;  ///< Evaluations reported to progress (never twice across replays).
};

/// The coordinates NLopt searches: a variable's value, or its logarithm (scale = "log"), so that
/// a stiffness over decades is searched with steps of a fraction of a decade.
struct SearchSpace {
  std::vector<bool> log;
  std::vector<double> lower, upper;  ///< The design's bounds, which the designs are clamped to.
  [[nodiscard]] std::vector<double> to_search(std::vector<double> x) const {
    for (std::size_t i = 0; i < x.size(); ++i) {
      if (log[i]) x[i] = std::log(x[i]);
    }
    return x;
  }
  [[nodiscard]] std::vector<double> to_design(std::vector<double> y) const {
    for (std::size_t i = 0; i < y.size(); ++i) {
      if (log[i]) y[i] = std::clamp(std::exp(y[i]), lower[i], upper[i]);
    }
    return y;
  }
};

/// What NLopt's callbacks of one stage share.
struct Stage {
  Problem* problem;
  const Goal* goal;
  std::string name;
  const SearchSpace* space;  ///< NLopt's coordinates → designs.
  /// What ended the stage from inside an evaluation (RunStopped from the caller's progress, or
  /// any error), rethrown once NLopt has returned.
  std::exception_ptr error;
};

struct BoundCallback {
  Stage* stage;
  const Bound* bound;
};

/// Runs `f` for NLopt: an exception (RunStopped from the caller's progress, NeedEvaluations, or
/// an error) is kept and becomes forced_stop, which ends the stage; run_stage rethrows it
/// (NLopt's C++ wrapper would turn it into a generic failure and lose its message). Some
/// algorithms look at the stop only between phases (CRS2 evaluates its whole first population):
/// once stopped, nothing more is evaluated.
template <class F>
double nlopt_guarded(Stage& stage, F&& f) {
  if (stage.error) throw nlopt::forced_stop();
  try {
    return f();
  } catch (...) {
    stage.error = std::current_exception();
    throw nlopt::forced_stop();
  }
}

double objective_callback(const std::vector<double>& y, std::vector<double>& /*gradient*/, void* data) {
  auto* stage = static_cast<Stage*>(data);
  return nlopt_guarded(*stage, [&] {
    return stage->problem->objective((*stage->problem)(stage->space->to_design(y), stage->name), *stage->goal);
  });
}

double bound_callback(unsigned n, const double* y, double* /*gradient*/, void* data) {
  auto* c = static_cast<BoundCallback*>(data);
  const std::vector<double> point = c->stage->space->to_design(std::vector<double>(y, y + n));
  return nlopt_guarded(*c->stage, [&] {
    const Evaluation& e = (*c->stage->problem)(point, c->stage->name);
    return e.status == "done" ? c->bound->violation(e.metrics[c->bound->metric]) : kRejected;
  });
}

/// One NLopt stage of `goal` from the design x (in NLopt's coordinates: SearchSpace): the
/// algorithm alone when it takes constraints (or there are none), else inside AUGLAG. Returns
/// the stage as it ran.
OptimizationStage run_stage(const nlopt::algorithm algorithm, const std::string& algorithm_name, bool global,
                            const SearchSpace& space, int budget, const OptimizeSettings& s, Problem& problem,
                            const Goal& goal, const std::string& name, const std::vector<double>& design) {
  const auto n = static_cast<unsigned>(design.size());
  const std::vector<double> lower = space.to_search(space.lower), upper = space.to_search(space.upper);
  std::vector<double> x = space.to_search(design);
  // A start from another stage may lie outside the box by rounding (COBYLA's steps can cross a
  // bound by an ulp), which NLopt refuses.
  for (unsigned i = 0; i < n; ++i) x[i] = std::clamp(x[i], lower[i], upper[i]);
  Stage stage{&problem, &goal, goal.label + name, &space, nullptr};
  std::vector<BoundCallback> callbacks;
  callbacks.reserve(goal.bounds.size());
  for (const Bound& b : goal.bounds) callbacks.push_back({&stage, &b});
  const auto configure = [&](nlopt::opt& opt, int evaluations) {
    opt.set_lower_bounds(lower);
    opt.set_upper_bounds(upper);
    opt.set_maxeval(evaluations);
    if (!global) {
      opt.set_ftol_rel(s.relative_tolerance);
      std::vector<double> step;
      for (unsigned i = 0; i < n; ++i) step.push_back(0.1 * (upper[i] - lower[i]));
      opt.set_initial_step(step);
    }
  };
  nlopt::opt opt(algorithm, n);
  configure(opt, budget);
  std::string ran = algorithm_name;
  try {
    for (BoundCallback& c : callbacks) opt.add_inequality_constraint(bound_callback, &c, 0.0);
  } catch (const std::invalid_argument&) {
    // The algorithm takes no constraints: the augmented Lagrangian minimises penalised
    // objectives with it, each subproblem to the relative tolerance. A global one has no such
    // test: it searches the first penalised objective with the whole budget (its next ones
    // would sample the same points again), and the local stage then meets the constraints.
    nlopt::opt sub(algorithm, n);
    configure(sub, budget);
    sub.set_ftol_rel(s.relative_tolerance);
    opt = nlopt::opt(nlopt::AUGLAG, n);
    opt.set_lower_bounds(lower);
    opt.set_upper_bounds(upper);
    opt.set_maxeval(budget);
    opt.set_ftol_rel(s.relative_tolerance);
    opt.set_local_optimizer(sub);
    for (BoundCallback& c : callbacks) opt.add_inequality_constraint(bound_callback, &c, 0.0);
    ran = fmt::format("AUGLAG({})", algorithm_name);
  }
  opt.set_min_objective(objective_callback, &stage);
  const std::size_t before = problem.evaluations().size();
  std::string outcome;
  double value = 0;
  try {
    outcome = nlopt_result_to_string(static_cast<nlopt_result>(opt.optimize(x, value)));
  } catch (const nlopt::roundoff_limited&) {
    outcome = "ROUNDOFF_LIMITED";
  } catch (const nlopt::forced_stop&) {
    if (stage.error) std::rethrow_exception(stage.error);
    outcome = "FORCED_STOP";
  } catch (const std::invalid_argument& e) {
    if (stage.error) std::rethrow_exception(stage.error);
    throw SimulationError(fmt::format("NLopt rejected the {} stage: {}", stage.name, e.what()));
  }
  if (stage.error) std::rethrow_exception(stage.error);
  return {stage.name, ran, outcome, static_cast<long>(problem.evaluations().size() - before)};
}

/// The algorithms and budgets of the two stages, and the space they search.
struct Stages {
  std::optional<std::pair<nlopt::algorithm, std::string>> global, local;
  SearchSpace space;
};

/// Minimises `goal` from x with the global stage, then the local one from the goal's best point;
/// returns the goal's best evaluation.
const Evaluation& optimise(const Stages& stages, const OptimizeSettings& s, Problem& problem, const Goal& goal,
                           const std::vector<double>& x, std::vector<OptimizationStage>& ran) {
  if (stages.global) {
    ran.push_back(run_stage(stages.global->first, stages.global->second, true, stages.space, s.global_evaluations, s,
                            problem, goal, "global", x));
  }
  if (stages.local) {
    const Evaluation* best = problem.best(goal);
    ran.push_back(run_stage(stages.local->first, stages.local->second, false, stages.space, s.local_evaluations, s,
                            problem, goal, "local", best != nullptr ? best->x : x));
  }
  const Evaluation* best = problem.best(goal);
  if (best == nullptr) throw SimulationError("optimize: no evaluation succeeded");
  return *best;
}

/// "{where}: "name" is not a figure …" unless every evaluation of this kind has it.
void require_figure(const std::string& name, const std::string& where, const Evaluation& start,
                    const OptimizeSettings& s, const RunInput& input) {
  for (const FigureColumn& c : start.figures->columns()) {
    if (c.name == name) return;
  }
  std::vector<std::string> names;
  for (const FigureColumn& c : start.figures->columns()) names.push_back(c.name);
  std::sort(names.begin(), names.end());
  throw InputError(fmt::format("{}: \"{}\" is not a figure of an evaluation (each = \"{}\") of this model; its "
                               "figures are: {}",
                               where.empty() ? input.source.string() + ": optimize.objective" : where, name,
                               to_string(s.each), fmt::join(names, ", ")));
}

/// Whether figure `name` is an acceleration (docs/studies.md: peak_abs_acc_…, amp_acc_…,
/// ratio_to_bare_acc_…, an ensemble's max_… of them).
bool is_acceleration_figure(std::string_view name) {
  return name.find("abs_acc") != std::string_view::npos || name.find("amp_acc") != std::string_view::npos ||
         name.find("bare_acc") != std::string_view::npos;
}

/// A figure the search steers by (objective, constraint, front) that is an acceleration, in a
/// model whose impacts are rigid, needs their equivalent pulse: without analysis.impact_duration
/// the accelerations leave the impacts out, and a design that still pounds would seem to meet
/// an acceleration limit.
void refuse_accelerations_without_impacts(const OptimizeSettings& s, const RunInput& input) {
  if (s.each == PointRun::frf || input.analysis.options.impact_duration > 0) return;
  if (!input.model.has_rigid_impacts()) return;
  const auto check = [&](const std::string& name, const std::string& where) {
    if (!is_acceleration_figure(name)) return;
    throw InputError(fmt::format(
        "{}: \"{}\" is a floor acceleration, and this model's impacts are rigid (law = \"paper\": bare "
        "pounding, or an element reaching its stop): an impact's velocity jump is not in an acceleration taken "
        "at states, so designs that still pound would pass. Set analysis.impact_duration (the duration of the "
        "half-sine pulse an impact is spread over, e.g. 0.002 s), or steer by max_velocity_jump_m_s or impacts",
        where.empty() ? input.source.string() + ": optimize.objective" : where, name));
  };
  check(s.objective, s.objective_where);
  for (const io::OptimizeConstraint& c : s.constraints) check(c.metric, c.where);
  if (s.pareto) {
    check(s.pareto->objective, s.pareto->objective_where.empty() ? s.objective_where : s.pareto->objective_where);
    check(s.pareto->metric, s.pareto->where);
  }
}

/// Marks the points of the front that another point dominates (no worse in both figures,
/// better in one); infeasible points neither dominate nor count.
void mark_dominated(std::vector<ParetoPoint>& points) {
  for (ParetoPoint& p : points) {
    p.dominated = !p.feasible;
    for (const ParetoPoint& q : points) {
      if (&p == &q || !q.feasible || p.dominated) continue;
      if (q.objective <= p.objective && q.metric <= p.metric && (q.objective < p.objective || q.metric < p.metric)) {
        p.dominated = true;
      }
    }
  }
}

std::vector<ConstraintOutcome> constraint_outcomes(const OptimizeSettings& s, const PointFigures& figures) {
  std::vector<ConstraintOutcome> out;
  for (const io::OptimizeConstraint& c : s.constraints) {
    ConstraintOutcome o{c, figures.figure(c.metric), false};
    if (o.value) {
      const double tolerance = s.constraint_tolerance;
      const auto within = [&](double limit, bool upper) {
        return Bound{0, limit, upper}.violation(*o.value) <= tolerance;
      };
      o.holds = (!c.min || within(*c.min, false)) && (!c.max || within(*c.max, true));
    }
    out.push_back(std::move(o));
  }
  return out;
}

}  // namespace

void serve_optimization(const RunInput& input, io::PointDistribution& ranks) {
  LastPoint last;
  ranks.serve_until_finished([&](const std::string& task) { return compute_task(input, task, last); });
}

namespace {

/// A Pareto front by the ε-constraint method: the front's objective minimised under the main
/// constraints (the main optimum when it is the same figure), then under each limit of the second
/// figure — given, or spaced between the two anchors' values — each point the best design of every
/// evaluation the runs made for its goal.
ParetoResult trace_front(Stages& stages, const OptimizeSettings& s, Problem& problem, const Goal& main_goal,
                         const Evaluation& first_optimum, std::size_t front_objective, std::size_t front_metric,
                         std::vector<OptimizationStage>& ran) {
  ParetoResult front;
  // The front's objective minimised under the constraints alone: the main optimum, or its own.
  Goal front_goal{.objective = front_objective, .bounds = main_goal.bounds, .label = "pareto_objective."};
  const Evaluation front_optimum =
      front_objective == 0 ? first_optimum : optimise(stages, s, problem, front_goal, first_optimum.x, ran);
  std::vector<double> limits = s.pareto->limits;
  if (limits.empty()) {
    // The ε-constraint method between the two anchors: the second figure at the objective's
    // optimum (its largest useful limit) and its own least value.
    Goal anchor{.objective = front_metric, .bounds = main_goal.bounds, .label = "pareto_metric."};
    const Evaluation least = optimise(stages, s, problem, anchor, front_optimum.x, ran);
    const double hi = front_optimum.metrics[front_metric], lo = least.metrics[front_metric];
    if (!std::isfinite(hi) || !std::isfinite(lo)) {
      throw SimulationError(fmt::format("optimize.pareto: {} is not a figure of the anchors' designs ({}, {}): no "
                                        "limits between them", s.pareto->metric, lo, hi));
    }
    // Anchors that agree leave no trade-off: the front is the objective's optimum alone.
    const int points = hi > lo ? s.pareto->points : 1;
    for (int j = 0; j + 1 < points; ++j) limits.push_back(lo + (hi - lo) * j / (points - 1));
  }
  std::vector<Goal> goals;
  for (std::size_t j = 0; j < limits.size(); ++j) {
    Goal goal = front_goal;
    goal.bounds.push_back({front_metric, limits[j], true});
    goal.label = fmt::format("pareto[{}].", j + 1);
    static_cast<void>(optimise(stages, s, problem, goal, front_optimum.x, ran));
    goals.push_back(std::move(goal));
  }
  goals.push_back(front_goal);
  // Each point is its goal's best design of every evaluation the runs made (a later run may
  // have found a better one for an earlier limit).
  front.objective = s.pareto->objective;
  front.metric = s.pareto->metric;
  for (std::size_t j = 0; j < goals.size(); ++j) {
    const Evaluation& e = *problem.best(goals[j]);
    front.points.push_back({.limit = j < limits.size() ? std::optional<double>(limits[j]) : std::nullopt,
                            .optimum = e.x,
                            .objective = e.metrics[front_objective],
                            .metric = e.metrics[front_metric],
                            .feasible = problem.feasible(e, goals[j])});
  }
  mark_dominated(front.points);
  return front;
}

/// evaluations.csv: every evaluation in order — its stage, variables, figures (the objective's
/// first), whether it meets the constraints, its status and error.
io::Table evaluation_table(const Problem& problem, const OptimizeSettings& s, const std::vector<std::string>& metrics,
                           const Goal& main_goal) {
  io::Table table;
  const std::size_t n = s.variables.size();
  const std::vector<Evaluation>& all = problem.evaluations();
  auto& number = table.integers("evaluation");
  auto& stage = table.texts("stage");
  for (std::size_t k = 0; k < all.size(); ++k) {
    number.push_back(static_cast<std::int64_t>(k + 1));
    stage.push_back(all[k].stage);
  }
  for (std::size_t i = 0; i < n; ++i) {
    auto& values = table.numbers(s.variables[i].key, io::column_unit(s.variables[i].key));
    for (const Evaluation& e : all) values.push_back(e.x[i]);
  }
  for (std::size_t m = 0; m < metrics.size(); ++m) {
    auto& values = table.numbers(m == 0 ? "objective" : metrics[m], io::column_unit(metrics[m]));
    for (const Evaluation& e : all) values.push_back(e.status == "done" ? e.metrics[m] : kNone);  // none: an empty field
  }
  if (!main_goal.bounds.empty()) {
    auto& feasible = table.integers("feasible");
    for (const Evaluation& e : all) feasible.push_back(problem.feasible(e, main_goal) ? 1 : 0);
  }
  auto& status = table.texts("status");
  auto& error = table.texts("error");
  for (const Evaluation& e : all) {
    status.push_back(e.status);
    error.push_back(e.error);
  }
  return table;
}

/// pareto.csv: each point of the front — its limit, both figures, feasibility, dominance and
/// its design.
io::Table pareto_table_of(const ParetoResult& front, const OptimizeSettings& s) {
  const std::size_t n = s.variables.size();
  io::Table t;
  auto& point = t.integers("point");
  auto& limit = t.numbers("limit", io::column_unit(front.metric));
  auto& objective = t.numbers(front.objective, io::column_unit(front.objective));
  auto& metric = t.numbers(front.metric, io::column_unit(front.metric));
  auto& feasible = t.integers("feasible");
  auto& dominated = t.integers("dominated");
  for (std::size_t j = 0; j < front.points.size(); ++j) {
    const ParetoPoint& p = front.points[j];
    point.push_back(static_cast<std::int64_t>(j + 1));
    limit.push_back(p.limit.value_or(kNone));  // the objective's own optimum: no limit
    objective.push_back(p.objective);
    metric.push_back(p.metric);
    feasible.push_back(p.feasible ? 1 : 0);
    dominated.push_back(p.dominated ? 1 : 0);
  }
  for (std::size_t i = 0; i < n; ++i) {
    auto& values = t.numbers(s.variables[i].key, io::column_unit(s.variables[i].key));
    for (const ParetoPoint& p : front.points) values.push_back(p.optimum[i]);
  }
  return t;
}

/// The variables' bounds and scales into `space`, and the starting design: each variable's start,
/// else the middle of its range as NLopt searches it (the geometric mean on a log scale).
std::vector<double> search_space(const OptimizeSettings& s, SearchSpace& space) {
  std::vector<double> x;
  for (const OptimizeVariable& v : s.variables) {
    space.lower.push_back(v.min);
    space.upper.push_back(v.max);
    space.log.push_back(v.log);
    x.push_back(v.start.value_or(v.log ? std::sqrt(v.min * v.max) : 0.5 * (v.min + v.max)));
  }
  return x;
}

/// The optimum's response against bare pounding: bare pounding's figures, and for a frequency
/// response both responses as tables (optimum_frf.csv, bare_frf.csv), the bare one's figures from
/// the same sweep.
struct OptimumAgainstBare {
  PointFigures bare_figures;
  std::optional<io::Table> optimum_frf, bare_frf;
};
OptimumAgainstBare against_bare(const RunInput& best_point, const OptimizeSettings& s,
                                const std::function<void(int, int)>& still) {
  OptimumAgainstBare out;
  if (s.each == PointRun::frf) {
    FrequencyResponseOptions o = frequency_response_options(best_point);
    o.threads = s.threads;
    o.progress = still;
    out.optimum_frf = io::frf_table(best_point.model, frequency_response(best_point.model, o));
    const Model bare = bare_pounding_model(best_point);
    const std::vector<FrfPoint> bare_response = frequency_response(bare, o);
    out.bare_frf = io::frf_table(bare, bare_response);
    out.bare_figures.response = frf_figures(bare, bare_response, s.band_min, s.band_max);
  } else {
    out.bare_figures = baseline_figures(best_point, s.threads);
  }
  return out;
}

/// The variable whose value made reading `x` fail, or "" (the error is not blamed on one, or
/// came later, from the run). Reading again is cheap and gives the error's typed blame, which the
/// outcome (kept as text in the database and sent between ranks) does not carry.
std::string blamed_variable(const RunInput& input, const std::vector<double>& x) {
  try {
    (void)with_settings(input, point_values(*input.optimize, x));
  } catch (const InputError& e) {
    return e.setting();
  }
  return {};
}

/// The starting point is rejected: reported where the file defines the variable whose value was
/// rejected, else at the file, with every variable's value.
[[noreturn]] void reject_start(const Evaluation& first, const OptimizeSettings& s, const RunInput& input,
                               const std::vector<double>& x) {
  const std::string blamed = blamed_variable(input, x);
  std::string where = input.source.string(), values;
  for (std::size_t i = 0; i < s.variables.size(); ++i) {
    const OptimizeVariable& v = s.variables[i];
    values += fmt::format("{}{} = {}", i == 0 ? "" : ", ", v.key, toml_float(x[i]));
    if (!v.where.empty() && v.key == blamed) where = v.where;
  }
  throw InputError(fmt::format("{}: the starting point ({}) is rejected: {}", where, values, first.error));
}

/// The figures the objective, the constraints and the front name must be figures of an
/// evaluation that ran (`done`).
void require_figures(const Evaluation& done, const OptimizeSettings& s, const RunInput& input) {
  require_figure(s.objective, s.objective_where, done, s, input);
  for (const io::OptimizeConstraint& c : s.constraints) require_figure(c.metric, c.where, done, s, input);
  if (s.pareto) {
    require_figure(s.pareto->objective, s.pareto->objective_where.empty() ? s.objective_where : s.pareto->objective_where,
                   done, s, input);
    require_figure(s.pareto->metric, s.pareto->where, done, s, input);
  }
}

/// What identifies an optimisation's database beside the input's fingerprint: its file, kind,
/// what each evaluation runs and its variables.
json database_definition(const RunInput& input, const OptimizeSettings& s) {
  json keys = json::array();
  for (const OptimizeVariable& v : s.variables) keys.push_back(v.key);
  return json{{"input", input.source.string()}, {"kind", "optimize"}, {"each", to_string(s.each)}, {"variables", keys}};
}

/// The figures the goals ask for (the objective, each constraint's, the front's second one),
/// and the main goal with its bounds as indices into them.
struct Goals {
  std::vector<std::string> metrics;
  Goal main;
  std::size_t front_objective = 0, front_metric = 0;
};

Goals goals_of(const OptimizeSettings& s) {
  Goals goals{.metrics = {s.objective}, .main = Goal{.objective = 0, .bounds = {}, .label = ""}};
  const auto metric_index = [&](const std::string& name) {
    const auto it = std::find(goals.metrics.begin(), goals.metrics.end(), name);
    if (it != goals.metrics.end()) return static_cast<std::size_t>(it - goals.metrics.begin());
    goals.metrics.push_back(name);
    return goals.metrics.size() - 1;
  };
  for (const io::OptimizeConstraint& c : s.constraints) {
    const std::size_t m = metric_index(c.metric);
    if (c.min) goals.main.bounds.push_back({m, *c.min, false});
    if (c.max) goals.main.bounds.push_back({m, *c.max, true});
  }
  goals.front_objective = s.pareto ? metric_index(s.pareto->objective) : 0;
  goals.front_metric = s.pareto ? metric_index(s.pareto->metric) : 0;
  return goals;
}

/// The evaluations the search may take: the starting point, then each optimisation's stages —
/// the main one, and for a front its objective's own optimum (unless the main one's), the
/// second figure's (points) and one per limit.
int evaluation_budget(const OptimizeSettings& s, const Stages& stages, const Goals& goals) {
  const int runs = !s.pareto ? 1
                             : 1 + (goals.front_objective != 0 ? 1 : 0) +
                                   (s.pareto->limits.empty() ? s.pareto->points : static_cast<int>(s.pareto->limits.size()));
  return 1 + runs * ((stages.global ? s.global_evaluations : 0) + (stages.local ? s.local_evaluations : 0));
}

/// Settings the search cannot start without, refused before anything is written.
void check_search(const RunInput& input) {
  if (!input.optimize) throw InputError(fmt::format("{}: no [optimize] table", input.source.string()));
  const OptimizeSettings& s = *input.optimize;
  if (s.variables.empty()) {
    throw InputError(fmt::format("{}: optimize: no [[optimize.variable]]", input.source.string()));
  }
  if (s.global_algorithm == "none" && s.local_algorithm == "none") {
    throw InputError(fmt::format("{}: optimize: both stages are \"none\"", input.source.string()));
  }
  refuse_accelerations_without_impacts(s, input);
}

/// The stages that ran and, for a front, the front.
struct SearchOutcome {
  std::vector<OptimizationStage> ran;
  std::optional<ParetoResult> pareto;
};

/// The whole search, from the start, on NLopt's evaluations, each known or pending (Problem).
SearchOutcome search(Stages& stages, const RunInput& input, Problem& problem, const Goals& goals,
                     std::vector<double> x) {
  const OptimizeSettings& s = *input.optimize;
  SearchOutcome outcome;
  const Evaluation& first = problem(x, "start");
  if (first.status == "rejected") reject_start(first, s, input, x);
  // The figures named must be figures of an evaluation: of the start, or (when it failed) of the
  // first evaluation that ran, checked once the search is over.
  const bool start_ran = first.status == "done";
  if (start_ran) require_figures(first, s, input);
  nlopt::srand(s.seed);
  // Kept by value: the evaluations grow as the front's runs go on.
  const Evaluation first_optimum = optimise(stages, s, problem, goals.main, x, outcome.ran);
  if (!start_ran && !problem.waiting()) {
    const auto done = std::find_if(problem.evaluations().begin(), problem.evaluations().end(),
                                   [](const Evaluation& e) { return e.status == "done"; });
    require_figures(*done, s, input);  // optimise found one, or threw
  }
  if (s.pareto) {
    outcome.pareto = trace_front(stages, s, problem, goals.main, first_optimum, goals.front_objective,
                                 goals.front_metric, outcome.ran);
  }
  return outcome;
}

/// The search replayed on the known evaluations until it needs none it does not have: each pass
/// computes the designs it waited for (all at once, over the threads or ranks).
SearchOutcome search_to_end(Stages& stages, const RunInput& input, Problem& problem, const Goals& goals,
                            const std::vector<double>& x) {
  // The starting point is computed first, so that a bad key or figure is reported before any search.
  problem.require(x);
  for (;;) {
    problem.replay();
    try {
      SearchOutcome outcome = search(stages, input, problem, goals, x);
      if (!problem.waiting()) return outcome;  // it ran to its end on known evaluations alone
    } catch (const NeedEvaluations&) {
    } catch (...) {
      // An error on the way to a pending design is the guesses', not the search's.
      if (!problem.waiting()) throw;
    }
    problem.evaluate_pending();
  }
}

/// The result's files, all or none: the optimum's responses, the front, every evaluation.
void write_optimization(OutputTransaction& out, const OptimizationResult& result, const RunInput& input) {
  if (result.optimum_frf) write_table(out, "optimum_frf.csv", *result.optimum_frf);
  if (result.bare_frf) write_table(out, "bare_frf.csv", *result.bare_frf);
  if (result.pareto_table) write_table(out, "pareto.csv", *result.pareto_table);
  write_table(out, "evaluations.csv", result.evaluation_table);
  out.write_json("optimize.json", to_json(result));
  // Its variables name keys of the file's own form: the file as written (to_toml_as_written).
  out.open("input.toml").text(to_toml_as_written(input));
  out.commit();
}

}  // namespace

OptimizationResult run_optimization(const RunInput& input, const std::filesystem::path& out_dir,
                                    const std::function<void(int, int)>& progress, io::PointDistribution* ranks) {
  if (ranks != nullptr && ranks->ranks() < 2) ranks = nullptr;
  check_search(input);
  const OptimizeSettings& s = *input.optimize;
  const auto start = std::chrono::steady_clock::now();
  Stages stages;
  const std::vector<double> x = search_space(s, stages.space);
  // Both algorithms are resolved first, so that a bad name is reported before any evaluation.
  if (s.global_algorithm != "none") stages.global.emplace(algorithm(s.global_algorithm, input, "global"), s.global_algorithm);
  if (s.local_algorithm != "none") stages.local.emplace(algorithm(s.local_algorithm, input, "local"), s.local_algorithm);
  const Goals goals = goals_of(s);
  const int budget = evaluation_budget(s, stages, goals);
  std::error_code absent;
  const bool folder_existed = std::filesystem::exists(out_dir, absent);
  OutputTransaction out(out_dir);  // creates the folder for the database too
  const std::filesystem::path database_path = out_dir / "optimize.sqlite";
  const bool resuming = std::filesystem::exists(database_path, absent);
  std::optional<io::StudyDatabase> database(std::in_place, database_path, fingerprint(input), database_definition(input, s));
  Problem problem(input, goals.metrics, progress, budget, ranks, *database);
  SearchOutcome outcome;
  try {
    outcome = search_to_end(stages, input, problem, goals, x);
  } catch (const InputError&) {
    // Bad input leaves nothing behind: a database this run made goes (its evaluations are of an
    // input that must change, which another database would hold).
    if (!resuming) {
      database.reset();
      std::filesystem::remove(database_path, absent);
      if (!folder_existed) std::filesystem::remove(out_dir, absent);  // only if empty
    }
    throw;
  }
  // The optimum: the best design for the main goal of every evaluation, the front's included.
  const Evaluation& optimum = *problem.best(goals.main);
  if (ranks != nullptr) ranks->finish();  // the workers are done: bare pounding runs here

  // The optimum's response against bare pounding and the free frames. They report as the last
  // evaluation did, so that a caller's progress (which may stop the run: RunStopped) is still
  // asked while they run.
  const RunInput best_point = with_settings(input, point_values(s, optimum.x));
  const auto evaluations_done = static_cast<int>(problem.evaluations().size());
  const auto still = [&](int, int) {
    if (progress) progress(evaluations_done, budget);
  };
  still(0, 0);
  OptimumAgainstBare against = against_bare(best_point, s, still);
  io::Table table = evaluation_table(problem, s, goals.metrics, goals.main);
  std::optional<io::Table> pareto_table;
  if (outcome.pareto) pareto_table = pareto_table_of(*outcome.pareto, s);
  const double run_time = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  OptimizationResult result{.source = input.source,
                            .title = input.title,
                            .settings = s,
                            .optimum = optimum.x,
                            .objective = optimum.metrics[0],
                            .feasible = problem.feasible(optimum, goals.main),
                            .constraints = constraint_outcomes(s, *optimum.figures),
                            .bare_constraints = constraint_outcomes(s, against.bare_figures),
                            .optimum_figures = *optimum.figures,
                            .bare_figures = std::move(against.bare_figures),
                            .metric = s.objective,
                            .meaning = figure_meaning(s.objective),
                            .stages = std::move(outcome.ran),
                            .evaluations = static_cast<long>(problem.evaluations().size()),
                            .reused = problem.reused(),
                            .computed = problem.computed(),
                            .run_time = run_time,
                            .evaluation_table = std::move(table),
                            .optimum_frf = std::move(against.optimum_frf),
                            .bare_frf = std::move(against.bare_frf),
                            .pareto = std::move(outcome.pareto),
                            .pareto_table = std::move(pareto_table)};
  write_optimization(out, result, input);
  return result;
}

std::string figure_meaning(std::string_view name) {
  // The figures an engineer designs against; a per-frame, per-floor or per-element column
  // (peak_drift_ratio_2, stroke_use_1_3) is the same figure of one frame, floor or element.
  static constexpr std::array<std::pair<std::string_view, std::string_view>, 13> meanings{{
      {"max_peak_V_W", "the larger of the frames' peak base shear V/W"},
      {"max_ratio_to_free", "the larger of the frames' peak V/W divided by the same frame's peak without gap elements"},
      {"max_peak_drift_ratio", "the worse frame's peak storey drift ratio |u_i − u_{i−1}|/h_i"},
      {"max_peak_drift_m", "the worse frame's peak storey drift |u_i − u_{i−1}| [m]"},
      {"max_peak_abs_acc_g", "the largest peak absolute floor acceleration [g]"},
      {"max_residual_drift_ratio", "the worse frame's storey drift ratio at the end of the run"},
      {"max_residual_drift_m", "the worse frame's storey drift at the end of the run [m]"},
      {"max_stroke_use", "the largest share of a gap element's stroke used, max s/ε (1: it reached its stop)"},
      {"max_gap_force_N", "the largest gap-element force [N]"},
      {"max_impact_impulse_Ns", "the largest impulse of one impact [N·s]"},
      {"hysteretic_energy_J", "the energy the yielding storeys dissipated [J]"},
      {"impacts", "the number of impacts"},
      {"max_ratio_to_bare", "the larger of the frames' peak V/W divided by bare pounding's"},
  }};
  for (const auto& [figure, meaning] : meanings) {
    if (figure == name) return std::string(meaning);
  }
  return {};
}

namespace {
/// The optimum as key → value.
json optimum_values(const OptimizeSettings& s, const std::vector<double>& x) {
  json optimum = json::object();
  for (std::size_t i = 0; i < s.variables.size(); ++i) optimum[s.variables[i].key] = x[i];
  return optimum;
}

json optional_number(const std::optional<double>& value) { return value ? json(*value) : json(nullptr); }

json constraints_json(const std::vector<ConstraintOutcome>& outcomes) {
  json out = json::array();
  for (const ConstraintOutcome& o : outcomes) {
    out.push_back({{"metric", o.constraint.metric},
                   {"min", optional_number(o.constraint.min)},
                   {"max", optional_number(o.constraint.max)},
                   {"value", optional_number(o.value)},
                   {"holds", o.holds}});
  }
  return out;
}
}  // namespace

json to_json(const OptimizationResult& result) {
  const OptimizeSettings& s = result.settings;
  // The optimum and bare pounding by the same measure, the one minimised.
  const json optimum_figures = io::to_json(result.optimum_figures);
  const json comparison{{"optimum", optimum_figures},
                        {"bare_pounding", io::to_json(result.bare_figures)},
                        {"objective", {{"metric", result.metric},
                                       {"meaning", result.meaning},
                                       {"optimum", result.objective},
                                       {"bare_pounding", optional_number(result.bare_objective())}}}};
  json stages = json::array();
  for (const OptimizationStage& g : result.stages) {
    stages.push_back({{"stage", g.stage}, {"algorithm", g.algorithm}, {"outcome", g.outcome},
                      {"evaluations", g.evaluations}});
  }
  json summary{{"poundsim_version", POUNDSIM_VERSION},
               {"input", result.source.string()},
               {"title", result.title},
               {"analysis", {{"kind", "optimize"}, {"each", to_string(s.each)}, {"objective", s.objective},
                             {"band", {s.band_min, s.band_max}}}},
               {"variables", json::array()},
               {"optimum", optimum_values(s, result.optimum)},
               {"objective", result.objective},
               {"optimum_metrics", optimum_figures},
               {"comparison", comparison},
               {"stages", stages},
               {"evaluations", result.evaluations},
               {"evaluations_from_database", result.reused},
               {"designs_computed", result.computed},
               {"run_time_s", result.run_time}};
  for (const OptimizeVariable& v : s.variables) summary["variables"].push_back({{"key", v.key}, {"min", v.min}, {"max", v.max}});
  if (!s.constraints.empty()) {
    summary["feasible"] = result.feasible;
    summary["constraints"] = constraints_json(result.constraints);
    summary["comparison"]["constraints"] = {{"optimum", constraints_json(result.constraints)},
                                            {"bare_pounding", constraints_json(result.bare_constraints)}};
  }
  if (result.pareto) {
    json points = json::array();
    for (const ParetoPoint& p : result.pareto->points) {
      points.push_back({{"limit", optional_number(p.limit)},
                        {"objective", p.objective},
                        {"metric", p.metric},
                        {"feasible", p.feasible},
                        {"dominated", p.dominated},
                        {"optimum", optimum_values(s, p.optimum)}});
    }
    summary["pareto"] = {{"objective", result.pareto->objective}, {"metric", result.pareto->metric}, {"points", points}};
  }
  return summary;
}

std::string report(const OptimizationResult& r, const std::filesystem::path& out_dir) {
  std::string text = fmt::format("poundsim {}: {} (optimisation, {} evaluations, {:.3f} s)\n", POUNDSIM_VERSION,
                                 r.source.string(), r.evaluations, r.run_time);
  if (r.reused > 0) {
    text += fmt::format("  {} evaluations read from optimize.sqlite (an earlier run of this input), {} designs computed\n",
                        r.reused, r.computed);
  }
  text += fmt::format("  objective {}: {} (lower is better)\n", r.metric, r.meaning.empty() ? "a figure of each evaluation" : r.meaning);
  text += fmt::format("  optimum {}: {} = {:.4f}{}\n", optimum_values(r.settings, r.optimum).dump(), r.metric, r.objective,
                      r.feasible ? "" : " (no evaluation met the constraints: this one breaks them least)");
  for (std::size_t c = 0; c < r.constraints.size(); ++c) {
    const ConstraintOutcome& o = r.constraints[c];
    const ConstraintOutcome& b = r.bare_constraints[c];
    const auto value = [](const ConstraintOutcome& x) {
      return x.value ? fmt::format("{:.4g} ({})", *x.value, x.holds ? "holds" : "broken") : std::string("none");
    };
    const std::string limit = o.constraint.min && o.constraint.max
                                  ? fmt::format("in [{}, {}]", *o.constraint.min, *o.constraint.max)
                                  : o.constraint.max ? fmt::format("≤ {}", *o.constraint.max)
                                                     : fmt::format("≥ {}", *o.constraint.min);
    text += fmt::format("  constraint {} {}: optimum {}, bare pounding {}\n", o.constraint.metric, limit, value(o), value(b));
  }
  const std::optional<double> bare = r.bare_objective();
  text += fmt::format("  bare pounding at the joint width and restitution: {} = {}\n", r.metric,
                      bare ? fmt::format("{:.4f}", *bare) : std::string("none (not a figure of bare pounding)"));
  if (r.pareto) {
    text += fmt::format("  Pareto front of {} against {}: {} points, {} not dominated\n", r.pareto->objective,
                        r.pareto->metric, r.pareto->points.size(),
                        std::count_if(r.pareto->points.begin(), r.pareto->points.end(),
                                      [](const ParetoPoint& p) { return !p.dominated; }));
  }
  text += fmt::format("  wrote {}/optimize.json, evaluations.csv, optimize.sqlite, input.toml{}{}\n", out_dir.string(),
                      r.settings.each == PointRun::frf ? ", optimum_frf.csv, bare_frf.csv" : "",
                      r.pareto ? ", pareto.csv" : "");
  return text;
}

}  // namespace poundsim::optimize
