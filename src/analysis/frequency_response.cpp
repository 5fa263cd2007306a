#include "poundsim/analysis/frequency_response.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <complex>
#include <deque>
#include <exception>
#include <limits>
#include <mutex>
#include <numbers>
#include <optional>
#include <stdexcept>
#include <thread>

#include <Eigen/Dense>
#include <fmt/format.h>

#include "poundsim/analysis/parallel.hpp"
#include "poundsim/analysis/periodic_orbits.hpp"
#include "poundsim/integrate/lockstep.hpp"

namespace poundsim {

std::string_view to_string(SweepMode mode) { return name_in(sweep_mode_names, mode); }

void SteadyStateOptions::validate() const {
  if (const auto violation = first_violation(*this)) throw std::invalid_argument(*violation);
  if (max_periods < 2 * max_periodicity + 2) {
    throw std::invalid_argument("max_periods must be at least 2 × max_periodicity + 2");
  }
}

FrameAmplitudes run_amplitudes(const Simulator& sim) {
  FrameAmplitudes out;
  const ResponseStatistics& st = sim.statistics();
  const Model& model = sim.model();
  for (int f = 0; f < model.frame_count(); ++f) {
    out.base_shear.push_back(st.base_shear[static_cast<std::size_t>(f)].value);
    out.storey_shear.push_back(st.storey_shear[static_cast<std::size_t>(f)].value);
    const int top = sim.layout().dof(f, model.frames[static_cast<std::size_t>(f)].storeys() - 1);
    out.top_displacement.push_back(st.floors[static_cast<std::size_t>(top)].displacement.value);
  }
  return out;
}

double reference_frequency(const Model& model) { return fundamental_frequency(model.frames.front()); }

FrameAmplitudes free_response(const Model& model, double amplitude, double omega) {
  using Complex = std::complex<double>;
  FrameAmplitudes out;
  for (const Frame& f : model.frames) {
    const Eigen::VectorXcd u = harmonic_amplitudes(f, amplitude, omega);
    out.base_shear.push_back(f.stiffness[0] * std::abs(u(0)));
    out.storey_shear.push_back(std::abs(Complex(f.stiffness[0], omega * f.damping[0]) * u(0)));
    out.top_displacement.push_back(std::abs(u(f.storeys() - 1)));
  }
  return out;
}

namespace {

/// The Poincaré samples of one run and the search for a repetition.
class PoincareSection {
 public:
  PoincareSection(int max_periodicity, double tolerance)
      : max_k_(max_periodicity), tolerance_(tolerance) {}

  void add(const Simulator& sim, double omega) {
    const KinematicState& x = sim.state();
    const Eigen::Index n = x.u.size();
    if (frame_of_.empty()) {
      for (Eigen::Index i = 0; i < 2 * n; ++i) frame_of_.push_back(sim.layout().frame_of(static_cast<int>(i % n)));
      frame_scale_.assign(static_cast<std::size_t>(sim.layout().frame_count()), 0.0);
    }
    Eigen::VectorXd y(2 * n);
    y << x.u, x.v / omega;
    for (Eigen::Index i = 0; i < y.size(); ++i) {
      double& scale = frame_scale_[static_cast<std::size_t>(frame_of_[static_cast<std::size_t>(i)])];
      scale = std::max(scale, std::abs(y(i)));
    }
    samples_.push_back({std::move(y), sim.configuration()});
    if (static_cast<int>(samples_.size()) > kept(max_k_)) samples_.pop_front();
    // Each frame's differences relative to its own largest |y| (at least 1e-3 of the largest
    // frame's), so that a frame moving far less than its neighbour has its peaks to the tolerance too.
    const double largest = *std::max_element(frame_scale_.begin(), frame_scale_.end());
    weight_.resize(frame_of_.size());
    for (std::size_t i = 0; i < frame_of_.size(); ++i) {
      const double scale = std::max(frame_scale_[static_cast<std::size_t>(frame_of_[i])], kSmallestFrameScale * largest);
      weight_[i] = scale > 0 ? 1.0 / scale : 0.0;
    }
  }

  /// The smallest k whose last k samples each lie within the tolerance of the period-k orbit,
  /// provided the orbit is clearly not of a shorter period j < k; 0 if none, or not yet decided.
  ///
  /// The distance to the orbit is estimated from the transient's contraction. Over a window of
  /// w = max(k, 8) sections, let d be the largest difference of a section from the one k periods
  /// earlier, and d' the same over the w sections before: the transient shrinks by d/d' every
  /// w periods, by q = (d/d')^{k/w} every k, and the sections are within about d q/(1 − q) of the
  /// orbit — more than d when q > 1/2, a lightly damped transient, which the repetition
  /// d ≤ tolerance alone would stop short of (the peaks taken next would carry what remains of
  /// it). The window spans several sections because a decaying free vibration sampled once a
  /// period oscillates: a single difference can pass near one of its zeros. The test is
  /// max(d, d q/(1 − q)) ≤ tolerance, the
  /// differences of each frame relative to its own largest |y| (a d far below the tolerance, at
  /// round-off, passes whatever ρ; one that passes d ≤ tolerance but not the estimate leaves the
  /// point undecided, and the transient goes on).
  ///
  /// The second condition rejects a decaying transient whose natural period is commensurate with
  /// the forcing (e.g. a free mode at ω̄/3 makes the sections nearly repeat every 3 periods long
  /// before they repeat every period): a genuine period-k orbit keeps its k sections apart by far
  /// more than the tolerance.
  ///
  /// `last`: the budget of periods is spent; the repetition alone decides (a slowly contracting
  /// transient near a bifurcation is periodic all the same, its peaks as close as it came).
  [[nodiscard]] int periodicity(bool last) const {
    const double limit = tolerance_;
    for (int k = 1; k <= max_k_; ++k) {
      const int w = window(k);
      const double d = difference(k, 0, w);
      if (d > limit) continue;
      if (!last && d > std::max(kRoundOff * limit, kNoise)) {
        // Not yet within the tolerance of the period-k orbit (or too few sections to tell):
        // undecided, not a longer period (a period-k orbit repeats every 2k periods too).
        const double rho = d / difference(k, w, w);
        const double q = std::pow(rho, static_cast<double>(k) / w);  // the contraction every k periods
        if (!(q > 0 && q < 1) || d * q / (1 - q) > limit) return 0;
      }
      for (int j = 1; j < k; ++j) {
        if (difference(j, 0, j) <= kDistinct * limit) return 0;  // undecided yet
      }
      return k;
    }
    return 0;
  }

  /// The sections a PoincareSection keeps: enough for the two windows of the longest period.
  [[nodiscard]] static int kept(int max_k) { return 2 * window(max_k) + max_k; }

 private:
  static constexpr double kDistinct = 100.0;
  /// A repetition this far below the tolerance is converged, whatever the contraction's estimate
  /// (near round-off the differences no longer shrink geometrically).
  static constexpr double kRoundOff = 1e-3;
  /// … and so is one at the sections' round-off, where a tolerance near it puts the test.
  static constexpr double kNoise = 1e-12;
  /// A frame's scale is at least this share of the largest frame's (a frame nearly at rest is
  /// not held to the tolerance of its own tiny motion).
  static constexpr double kSmallestFrameScale = 1e-3;
  /// The fewest sections of a window of the contraction's estimate.
  static constexpr int kWindow = 8;

  [[nodiscard]] static int window(int k) { return std::max(k, kWindow); }

  /// max over `count` samples, ending `back` samples before the last, of |y − y k samples
  /// earlier|, each component relative to its frame's scale (∞ if too few samples or a
  /// different contact configuration).
  [[nodiscard]] double difference(int k, int back, int count) const {
    const int n = static_cast<int>(samples_.size()) - back;
    if (count + k > n) return std::numeric_limits<double>::infinity();
    double worst = 0;
    for (int j = 0; j < count; ++j) {
      const Sample& now = samples_[static_cast<std::size_t>(n - 1 - j)];
      const Sample& before = samples_[static_cast<std::size_t>(n - 1 - j - k)];
      if (now.config != before.config) return std::numeric_limits<double>::infinity();
      for (Eigen::Index i = 0; i < now.y.size(); ++i) {
        worst = std::max(worst, std::abs(now.y(i) - before.y(i)) * weight_[static_cast<std::size_t>(i)]);
      }
    }
    return worst;
  }

  struct Sample {
    Eigen::VectorXd y;
    ContactConfiguration config;
  };
  int max_k_;
  double tolerance_;
  std::vector<int> frame_of_;         ///< Of each component of y.
  std::vector<double> frame_scale_;   ///< Each frame's largest |y| seen.
  std::vector<double> weight_;        ///< 1 / the scale each component's differences are relative to.
  std::deque<Sample> samples_;
};

/// A point of a frequency response from its start to its window: the steady state reached from
/// its simulator's state. steady_state_point_at() runs one alone; frequency_response() runs
/// points from rest with Newmark in lockstep batches (integrate/lockstep.hpp), period by period
/// through the same calls.
class PointRun {
 public:
  /// Sets `sim` to the point's forcing and step: created when null (from rest), else restarted
  /// from its state (a sweep's next point). The transient then records neither the energy balance
  /// (never reported here) nor peaks (reset before the window): the state, the configuration and
  /// the events are all it needs.
  PointRun(const Model& model, double omega1, double amplitude, double ratio, const SteadyStateOptions& steady,
           const TimeHistoryOptions& options, std::unique_ptr<Simulator>& sim)
      : steady_(steady), section_(steady.max_periodicity, steady.tolerance) {
    const double omega = ratio * omega1;
    period_ = 2 * std::numbers::pi / omega;
    const double dt = period_ / steady.steps_per_period;
    const HarmonicExcitation forcing{amplitude, omega};
    if (sim) {
      sim->restart(forcing, dt);
    } else {
      TimeHistoryOptions o = options;
      o.dt = dt;
      sim = std::make_unique<Simulator>(model, forcing, o);
    }
    point_.ratio = ratio;
    point_.omega = omega;
    point_.free = free_response(model, amplitude, omega);
    sim->meter_energy(false);
    sim->record_responses(false);
    section_.add(*sim, omega);
  }

  /// The time at the end of the transient's next period [s].
  [[nodiscard]] double next_section() const { return (periods_ + 1) * period_; }

  /// After `sim` has run the transient's next period (to next_section()): its Poincaré section.
  /// True when the transient is over — a repetition found or max_periods run.
  bool end_period(const Simulator& sim) {
    ++periods_;
    section_.add(sim, point_.omega);
    point_.periodicity = section_.periodicity(periods_ >= steady_.max_periods);
    point_.transient_periods = periods_;
    return point_.periodicity > 0 || periods_ >= steady_.max_periods;
  }

  /// The window after the transient (k periods of a period-k orbit, else window_periods) with
  /// peaks, and the point.
  FrfPoint finish(Simulator& sim) {
    const int window = point_.periodicity > 0 ? point_.periodicity : steady_.window_periods;
    sim.record_responses(true);
    sim.reset_statistics();
    sim.advance_to((point_.transient_periods + window) * period_);
    const ResponseStatistics& st = sim.statistics();
    point_.interacting = run_amplitudes(sim);
    point_.events = st.events;
    for (const GapResponse& g : st.gaps) point_.impacts += g.impacts;
    return point_;
  }

 private:
  const SteadyStateOptions& steady_;
  PoincareSection section_;
  FrfPoint point_;
  double period_ = 0.0;
  int periods_ = 0;
};

/// steady_state_point() with ω₁ = reference_frequency(model) given, so that a sweep finds it once.
FrfPoint steady_state_point_at(const Model& model, double omega1, double amplitude, double ratio,
                               const SteadyStateOptions& steady, const TimeHistoryOptions& options,
                               std::unique_ptr<Simulator>& sim) {
  PointRun run(model, omega1, amplitude, ratio, steady, options, sim);
  do {
    sim->advance_to(run.next_section());
  } while (!run.end_period(*sim));
  return run.finish(*sim);
}

/// The points of `ratios` from rest, each thread stepping up to `lanes` of them in lockstep
/// (integrate/lockstep.hpp) a period at a time, a lane taking the next point as soon as its own
/// is done. Each point's simulator takes the steps steady_state_point_at's would, to the bit:
/// the results depend neither on the lanes nor on the threads. As parallel_for does with one task
/// a point: the failure of the lowest point that fails is rethrown, the points above a failure
/// are not started, and a failed point is not reported to the progress callback.
std::vector<FrfPoint> points_from_rest_in_lockstep(const Model& model, double omega1,
                                                   const FrequencyResponseOptions& options) {
  const int count = static_cast<int>(options.ratios.size());
  std::vector<FrfPoint> results(static_cast<std::size_t>(count));
  std::vector<std::exception_ptr> failures(static_cast<std::size_t>(count));
  std::atomic<int> next{0}, done{0};
  std::atomic<bool> stop{false};  // the progress callback threw (an interrupt): every worker stops
  std::atomic<int> lowest_failure{count};  // points above it are not started
  const auto lanes = static_cast<std::size_t>(options.lanes);
  const int workers = std::min(count, options.threads > 0 ? options.threads : hardware_threads());
  parallel_for(workers, options.threads, [&](int /*worker*/) {
    struct Lane {
      int index = -1;
      std::unique_ptr<Simulator> sim;
      std::optional<PointRun> run;
    };
    std::vector<Lane> lane(lanes);
    std::vector<Simulator*> sims(lanes, nullptr);
    std::vector<std::exception_ptr> errors(lanes);
    Lockstep batch;
    // A point ends with its result or its failure; the progress callback may throw (an
    // interrupt), which ends the whole response as it would from parallel_for's task.
    const auto release = [](Lane& l) {
      const int index = l.index;
      l.run.reset();
      l.sim.reset();
      l.index = -1;
      return index;
    };
    const auto fail_point = [&](Lane& l, std::exception_ptr error) {
      const int index = release(l);
      failures[static_cast<std::size_t>(index)] = std::move(error);
      for (int lowest = lowest_failure; index < lowest && !lowest_failure.compare_exchange_weak(lowest, index);) {
      }
    };
    const auto finish_point = [&](Lane& l, FrfPoint&& point) {
      results[static_cast<std::size_t>(release(l))] = std::move(point);
      const int finished = ++done;
      if (!options.progress) return;
      try {
        options.progress(finished, count);
      } catch (...) {
        stop = true;
        throw;
      }
    };
    const auto start_next = [&](Lane& l) {
      while (l.index < 0) {
        const int i = next++;
        if (i >= count || i > lowest_failure) return;
        l.index = i;
        std::exception_ptr error;
        try {
          l.run.emplace(model, omega1, options.amplitude, options.ratios[static_cast<std::size_t>(i)], options.steady,
                        options.time_history, l.sim);
        } catch (...) {
          error = std::current_exception();
        }
        if (error) fail_point(l, error);
      }
    };
    while (!stop) {
      bool any = false;
      for (std::size_t k = 0; k < lanes; ++k) {
        start_next(lane[k]);
        sims[k] = lane[k].index >= 0 ? lane[k].sim.get() : nullptr;
        errors[k] = nullptr;
        any = any || lane[k].index >= 0;
      }
      if (!any) return;
      batch.step(sims, options.steady.steps_per_period, errors);
      for (std::size_t k = 0; k < lanes; ++k) {
        Lane& l = lane[k];
        if (l.index < 0) continue;
        std::optional<FrfPoint> point;
        std::exception_ptr error = errors[k];
        if (!error) {
          try {
            // The period's grid steps end at its section (dt = T / steps_per_period) within
            // advance_to's slack: this takes no step, and any the grid would leave it.
            l.sim->advance_to(l.run->next_section());
            if (l.run->end_period(*l.sim)) {
              point = l.run->finish(*l.sim);
              point->branch = SweepMode::from_rest;
            }
          } catch (...) {
            error = std::current_exception();
          }
        }
        if (error) {
          fail_point(l, error);
        } else if (point) {
          finish_point(l, std::move(*point));
        }
      }
    }
  });
  for (const std::exception_ptr& failure : failures) {
    if (failure) std::rethrow_exception(failure);
  }
  return results;
}

}  // namespace

FrfPoint steady_state_point(const Model& model, double amplitude, double ratio,
                            const SteadyStateOptions& steady, const TimeHistoryOptions& options,
                            std::unique_ptr<Simulator>& sim) {
  return steady_state_point_at(model, reference_frequency(model), amplitude, ratio, steady, options,
                               sim);
}

std::vector<FrfPoint> frequency_response(const Model& model, const FrequencyResponseOptions& options) {
  options.steady.validate();
  if (options.ratios.empty()) throw std::invalid_argument("no frequency ratios");
  for (const double r : options.ratios) {
    if (!(r > 0) || !std::isfinite(r)) throw std::invalid_argument(fmt::format("frequency ratio {} must be > 0", r));
  }
  validate(model);
  if (options.method == FrfMethod::continuation) return frequency_response_by_continuation(model, options);
  const double omega1 = reference_frequency(model);

  if (options.lanes < 1 || options.lanes > Lockstep::kLanes) {
    throw std::invalid_argument(fmt::format("lanes = {} must be in [1, {}]", options.lanes, Lockstep::kLanes));
  }
  if (options.sweep == SweepMode::from_rest && options.lanes > 1 &&
      options.time_history.integrator == Integrator::newmark) {
    return points_from_rest_in_lockstep(model, omega1, options);
  }

  std::vector<double> ascending = options.ratios;
  std::sort(ascending.begin(), ascending.end());

  // Tasks: one per point from rest (each with a simulator of its own), or one per sweep direction.
  struct Task {
    SweepMode branch;
    std::vector<double> ratios;
  };
  std::vector<Task> tasks;
  if (options.sweep == SweepMode::from_rest) {
    for (const double r : options.ratios) tasks.push_back({SweepMode::from_rest, {r}});
  } else {
    if (options.sweep == SweepMode::up || options.sweep == SweepMode::both) {
      tasks.push_back({SweepMode::up, ascending});
    }
    if (options.sweep == SweepMode::down || options.sweep == SweepMode::both) {
      tasks.push_back({SweepMode::down, std::vector<double>(ascending.rbegin(), ascending.rend())});
    }
  }
  int total = 0;
  for (const Task& task : tasks) total += static_cast<int>(task.ratios.size());
  std::vector<std::vector<FrfPoint>> results(tasks.size());
  std::atomic<int> done{0};
  parallel_for(static_cast<int>(tasks.size()), options.threads, [&](int t) {
    const Task& task = tasks[static_cast<std::size_t>(t)];
    std::unique_ptr<Simulator> sim;
    for (const double r : task.ratios) {
      FrfPoint p = steady_state_point_at(model, omega1, options.amplitude, r, options.steady,
                                         options.time_history, sim);
      p.branch = task.branch;
      results[static_cast<std::size_t>(t)].push_back(std::move(p));
      const int count = ++done;
      if (options.progress) options.progress(count, total);
    }
  });
  std::vector<FrfPoint> out;
  for (auto& r : results) {
    for (auto& p : r) out.push_back(std::move(p));
  }
  return out;
}

}  // namespace poundsim
