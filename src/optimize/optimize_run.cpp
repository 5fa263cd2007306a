#include "poundsim/optimize/optimize_run.hpp"

#include <chrono>
#include <cmath>
#include <limits>
#include <map>
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

/// The column of the figure that `objective` minimises, and what it measures.
std::pair<std::string, std::string> objective_metric(Objective objective) {
  if (objective == Objective::max_peak) {
    return {std::string(column_names::max_peak_V_W), "the larger of the frames' peak base shear V/W"};
  }
  return {std::string(column_names::max_ratio_to_free), "the larger of the frames' peak V/W divided by the same frame's peak without gap elements"};
}

/// The overrides that set the design variables to `x`.
PointValues point_values(const OptimizeSettings& settings, const std::vector<double>& x) {
  PointValues values;
  for (std::size_t i = 0; i < x.size(); ++i) values.push_back(make_setting(settings.variables[i].key, {x[i]}));
  return values;
}

struct Evaluation {
  std::vector<double> x;
  double objective = kRejected;
  std::string stage, status, error;
  PointFigures figures;
};

class Problem {
 public:
  Problem(const RunInput& input, const std::function<void(int, int)>& progress, int budget)
      : input_(input), settings_(*input.optimize), progress_(progress), budget_(budget) {}

  double operator()(const std::vector<double>& x, const std::string& stage) {
    if (auto it = memo_.find(x); it != memo_.end()) return it->second;
    Evaluation e{x, kRejected, stage, "done", "", {}};
    try {
      const RunInput point = with_settings(input_, point_values(settings_, x));
      e.figures = point_figures(point, settings_.threads, nullptr);
      e.objective = objective_of(e.figures, settings_.objective);
    } catch (const InputError& err) {
      e.status = "rejected";
      e.error = err.what();
    } catch (const SimulationError& err) {
      e.status = "failed";
      e.error = err.what();
    }
    memo_[x] = e.objective;
    evaluations_.push_back(e);
    if (progress_) progress_(static_cast<int>(evaluations_.size()), budget_);
    return e.objective;
  }

  [[nodiscard]] const std::vector<Evaluation>& evaluations() const { return evaluations_; }
  [[nodiscard]] const Evaluation* best() const {
    const Evaluation* b = nullptr;
    for (const Evaluation& e : evaluations_) {
      if (e.status == "done" && (b == nullptr || e.objective < b->objective)) b = &e;
    }
    return b;
  }

 private:
  const RunInput& input_;
  const OptimizeSettings& settings_;
  std::function<void(int, int)> progress_;
  int budget_;
  std::map<std::vector<double>, double> memo_;
  std::vector<Evaluation> evaluations_;
};

struct Stage {
  Problem* problem;
  std::string name;
  bool stopped = false;  ///< The caller asked the run to stop (RunStopped from its progress).
};

double objective(const std::vector<double>& x, std::vector<double>& /*gradient*/, void* data) {
  auto* stage = static_cast<Stage*>(data);
  try {
    return (*stage->problem)(x, stage->name);
  } catch (const RunStopped&) {
    // NLopt's C++ wrapper turns any other exception into a generic failure: forced_stop ends the
    // stage, and run_stage stops the run.
    stage->stopped = true;
    throw nlopt::forced_stop();
  }
}

/// Runs one NLopt stage from x; returns NLopt's outcome as text.
std::string run_stage(nlopt::opt& opt, Problem& problem, const std::string& name, std::vector<double>& x) {
  Stage stage{&problem, name};
  opt.set_min_objective(objective, &stage);
  double value = 0;
  try {
    const nlopt::result r = opt.optimize(x, value);
    return nlopt_result_to_string(static_cast<nlopt_result>(r));
  } catch (const nlopt::roundoff_limited&) {
    return "ROUNDOFF_LIMITED";
  } catch (const nlopt::forced_stop&) {
    if (stage.stopped) throw RunStopped();
    return "FORCED_STOP";
  } catch (const std::invalid_argument& e) {
    throw SimulationError(fmt::format("NLopt rejected the {} stage: {}", name, e.what()));
  }
}

}  // namespace

OptimizationResult run_optimization(const RunInput& input, const std::filesystem::path& out_dir,
                                    const std::function<void(int, int)>& progress) {
  if (!input.optimize) throw InputError(fmt::format("{}: no [optimize] table", input.source.string()));
  const OptimizeSettings& s = *input.optimize;
  if (s.variables.empty()) {
    throw InputError(fmt::format("{}: optimize: no [[optimize.variable]]", input.source.string()));
  }
  const bool global = s.global_algorithm != "none", local = s.local_algorithm != "none";
  if (!global && !local) throw InputError(fmt::format("{}: optimize: both stages are \"none\"", input.source.string()));
  const auto start = std::chrono::steady_clock::now();
  const auto n = static_cast<unsigned>(s.variables.size());
  std::vector<double> lower, upper, x;
  for (const OptimizeVariable& v : s.variables) {
    lower.push_back(v.min);
    upper.push_back(v.max);
    x.push_back(v.start.value_or(0.5 * (v.min + v.max)));
  }
  // Both algorithms are resolved first, so that a bad name is reported before any evaluation.
  const nlopt::algorithm global_algorithm = global ? algorithm(s.global_algorithm, input, "global") : nlopt::NUM_ALGORITHMS;
  const nlopt::algorithm local_algorithm = local ? algorithm(s.local_algorithm, input, "local") : nlopt::NUM_ALGORITHMS;
  // The starting point, then each stage's evaluations.
  const int budget = 1 + (global ? s.global_evaluations : 0) + (local ? s.local_evaluations : 0);
  Problem problem(input, progress, budget);
  // The starting point is evaluated first, so that a bad key is reported before any search.
  problem(x, "start");
  if (const Evaluation& first = problem.evaluations().back(); first.status == "rejected") {
    // Reported where the file defines the variable whose value was rejected, else at the file.
    std::string where = input.source.string(), values;
    for (std::size_t i = 0; i < n; ++i) {
      const OptimizeVariable& v = s.variables[i];
      values += fmt::format("{}{} = {}", i == 0 ? "" : ", ", v.key, toml_float(x[i]));
      if (!v.where.empty() && first.error.starts_with(fmt::format("{}: --set {}=", input.source.string(), v.key))) {
        where = v.where;
      }
    }
    throw InputError(fmt::format("{}: the starting point ({}) is rejected: {}", where, values, first.error));
  }
  nlopt::srand(s.seed);
  std::vector<OptimizationStage> stages;
  if (global) {
    nlopt::opt opt(global_algorithm, n);
    opt.set_lower_bounds(lower);
    opt.set_upper_bounds(upper);
    opt.set_maxeval(s.global_evaluations);
    const std::size_t before = problem.evaluations().size();
    std::vector<double> g = x;
    const std::string outcome = run_stage(opt, problem, "global", g);
    stages.push_back({"global", s.global_algorithm, outcome,
                      static_cast<long>(problem.evaluations().size() - before)});
  }
  if (local) {
    const Evaluation* best = problem.best();
    std::vector<double> l = best != nullptr ? best->x : x;
    nlopt::opt opt(local_algorithm, n);
    opt.set_lower_bounds(lower);
    opt.set_upper_bounds(upper);
    opt.set_maxeval(s.local_evaluations);
    opt.set_ftol_rel(s.relative_tolerance);
    std::vector<double> step;
    for (unsigned i = 0; i < n; ++i) step.push_back(0.1 * (upper[i] - lower[i]));
    opt.set_initial_step(step);
    const std::size_t before = problem.evaluations().size();
    const std::string outcome = run_stage(opt, problem, "local", l);
    stages.push_back({"local", s.local_algorithm, outcome,
                      static_cast<long>(problem.evaluations().size() - before)});
  }
  const Evaluation* best = problem.best();
  if (best == nullptr) throw SimulationError("optimize: no evaluation succeeded");

  // The optimum's response against bare pounding and the free frames.
  const RunInput best_point = with_settings(input, point_values(s, best->x));
  PointFigures bare_figures;
  std::optional<io::Table> optimum_frf, bare_frf;
  // The responses below report as the last evaluation did, so that a caller's progress (which
  // may stop the run: RunStopped) is still asked while they run.
  const auto evaluations_done = static_cast<int>(problem.evaluations().size());
  const auto still = [&](int, int) {
    if (progress) progress(evaluations_done, budget);
  };
  still(0, 0);
  if (s.each == PointRun::frf) {
    // Both responses are written out, so the bare one's metrics come from the same sweep.
    FrequencyResponseOptions o = frequency_response_options(best_point);
    o.threads = s.threads;
    o.progress = still;
    optimum_frf = io::frf_table(best_point.model, frequency_response(best_point.model, o));
    const Model bare = bare_pounding_model(best_point);
    const std::vector<FrfPoint> bare_response = frequency_response(bare, o);
    bare_frf = io::frf_table(bare, bare_response);
    bare_figures.response = frf_figures(bare, bare_response, s.band_min, s.band_max);
  } else {
    bare_figures = baseline_figures(best_point, s.threads);
  }
  io::Table table;
  {
    const std::vector<Evaluation>& all = problem.evaluations();
    auto& number = table.integers("evaluation");
    auto& stage = table.texts("stage");
    for (std::size_t k = 0; k < all.size(); ++k) {
      number.push_back(static_cast<std::int64_t>(k + 1));
      stage.push_back(all[k].stage);
    }
    for (std::size_t i = 0; i < s.variables.size(); ++i) {
      auto& values = table.numbers(s.variables[i].key, io::column_unit(s.variables[i].key));
      for (const Evaluation& e : all) values.push_back(e.x[i]);
    }
    auto& objective = table.numbers("objective", io::column_unit(objective_metric(s.objective).first));
    auto& status = table.texts("status");
    auto& error = table.texts("error");
    for (const Evaluation& e : all) {
      objective.push_back(e.status == "done" ? e.objective : std::nan(""));  // none: an empty field
      status.push_back(e.status);
      error.push_back(e.error);
    }
  }
  const double run_time = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  const auto [metric, meaning] = objective_metric(s.objective);
  OptimizationResult result{.source = input.source,
                            .title = input.title,
                            .settings = s,
                            .optimum = best->x,
                            .objective = best->objective,
                            .optimum_figures = best->figures,
                            .bare_figures = std::move(bare_figures),
                            .metric = metric,
                            .meaning = meaning,
                            .stages = std::move(stages),
                            .evaluations = static_cast<long>(problem.evaluations().size()),
                            .run_time = run_time,
                            .evaluation_table = std::move(table),
                            .optimum_frf = std::move(optimum_frf),
                            .bare_frf = std::move(bare_frf)};
  OutputTransaction out(out_dir);
  if (result.optimum_frf) write_csv(out.open("optimum_frf.csv"), *result.optimum_frf);
  if (result.bare_frf) write_csv(out.open("bare_frf.csv"), *result.bare_frf);
  write_csv(out.open("evaluations.csv"), result.evaluation_table);
  out.write_json("optimize.json", to_json(result));
  // Its variables name keys of the file's own form: the file as written (to_toml_as_written).
  out.open("input.toml").text(to_toml_as_written(input));
  out.commit();
  return result;
}

namespace {
/// The optimum as key → value.
json optimum_values(const OptimizationResult& result) {
  json optimum = json::object();
  for (std::size_t i = 0; i < result.settings.variables.size(); ++i) {
    optimum[result.settings.variables[i].key] = result.optimum[i];
  }
  return optimum;
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
                                       {"bare_pounding", result.bare_objective()}}}};
  json stages = json::array();
  for (const OptimizationStage& g : result.stages) {
    stages.push_back({{"stage", g.stage}, {"algorithm", g.algorithm}, {"outcome", g.outcome},
                      {"evaluations", g.evaluations}});
  }
  json summary{{"poundsim_version", POUNDSIM_VERSION},
               {"input", result.source.string()},
               {"title", result.title},
               {"analysis", {{"kind", "optimize"}, {"each", to_string(s.each)}, {"objective", to_string(s.objective)},
                             {"band", {s.band_min, s.band_max}}}},
               {"variables", json::array()},
               {"optimum", optimum_values(result)},
               {"objective", result.objective},
               {"optimum_metrics", optimum_figures},
               {"comparison", comparison},
               {"stages", stages},
               {"evaluations", result.evaluations},
               {"run_time_s", result.run_time}};
  for (const OptimizeVariable& v : s.variables) summary["variables"].push_back({{"key", v.key}, {"min", v.min}, {"max", v.max}});
  return summary;
}

std::string report(const OptimizationResult& r, const std::filesystem::path& out_dir) {
  std::string text = fmt::format("poundsim {}: {} (optimisation, {} evaluations, {:.3f} s)\n", POUNDSIM_VERSION,
                                 r.source.string(), r.evaluations, r.run_time);
  text += fmt::format("  objective {}: {} (lower is better)\n", r.metric, r.meaning);
  text += fmt::format("  optimum {}: {} = {:.4f}\n", optimum_values(r).dump(), r.metric, r.objective);
  text += fmt::format("  bare pounding at the joint width and restitution: {} = {:.4f}\n", r.metric,
                      r.bare_objective());
  text += fmt::format("  wrote {}/optimize.json, evaluations.csv, input.toml{}\n", out_dir.string(),
                      r.settings.each == PointRun::frf ? ", optimum_frf.csv, bare_frf.csv" : "");
  return text;
}

}  // namespace poundsim::optimize
