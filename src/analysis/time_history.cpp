#include "poundsim/analysis/time_history.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <stdexcept>
#include <type_traits>

#include <fmt/format.h>

#include "poundsim/analysis/response_metrics.hpp"

namespace poundsim {

namespace {
std::vector<double> element_dissipation_of(const EnergyMeter& meter) {
  const auto per_element = meter.element_dissipation();
  return per_element ? std::vector<double>(per_element->begin(), per_element->end()) : std::vector<double>{};
}

/// The run moved as the frames do alone: no gap element closed (an open one transmits nothing,
/// and adds nothing to the phase's matrices), and no guard fired or cut a step. A guard that fires
/// without an event still changes the run — a rigid stop reached with no closing speed cuts the
/// step and settles the accelerations again, the exact integrator accepts a state at a touch
/// within round-off — so a run with any located crossing (a yielding storey's too) or a step that
/// is not a whole grid step makes its free run.
bool ran_as_the_frames_alone(const ResponseStatistics& run) {
  const bool none_closed = std::all_of(run.gaps.begin(), run.gaps.end(), [](const GapResponse& g) {
    return g.contacts == 0 && g.separations == 0 && g.impacts == 0 && g.locks == 0 && g.contact_time == 0.0;
  });
  return none_closed && run.events == 0 && run.guard_evaluations == run.grazing_checks && run.substeps == run.steps;
}

/// The free frames' statistics taken from a run that ran as the frames alone: its steps are the
/// free run's (the same grid), its phase the same matrices, so every peak is the free run's to
/// the bit (docs/numerics.md, "The free frames' run"). Its counts are the run's: the guards of the gap
/// elements were evaluated too.
ResponseStatistics frames_alone(const ResponseStatistics& run) {
  ResponseStatistics free = run;
  free.gaps.clear();
  return free;
}

/// FNV-1a over the bits of the key's numbers: equal keys agree, and so do only numbers equal bit
/// for bit (== takes −0 for +0).
class Fingerprint {
 public:
  template <class T>
    requires std::is_arithmetic_v<T> || std::is_enum_v<T>
  void add(T x) {
    std::uint64_t bits = 0;
    if constexpr (std::is_same_v<T, double>) {
      bits = std::bit_cast<std::uint64_t>(x);
    } else {
      bits = static_cast<std::uint64_t>(x);
    }
    for (int byte = 0; byte < 8; ++byte) {
      value_ = (value_ ^ ((bits >> (8 * byte)) & 0xffu)) * 0x100000001b3u;
    }
  }
  void add(const std::vector<double>& values) {
    add(values.size());
    for (const double x : values) add(x);
  }
  [[nodiscard]] std::uint64_t value() const { return value_; }

 private:
  std::uint64_t value_ = 0xcbf29ce484222325u;
};

std::uint64_t fingerprint(const FreeRunKey& key) {
  Fingerprint f;
  f.add(key.end_time);
  for (const Frame& frame : key.frames) {
    for (const auto* values : {&frame.mass, &frame.stiffness, &frame.damping, &frame.storey_height,
                               &frame.ground_damping, &frame.modal_damping_ratios}) {
      f.add(*values);
    }
  }
  f.add(key.excitation.index());
  std::visit(
      [&](const auto& e) {
        using E = std::decay_t<decltype(e)>;
        if constexpr (std::is_same_v<E, HarmonicExcitation>) {
          f.add(e.amplitude);
          f.add(e.omega);
        } else if constexpr (std::is_same_v<E, RecordExcitation>) {
          f.add(e.time);
          f.add(e.acceleration);
        }
      },
      key.excitation);
  const TimeHistoryOptions& o = key.options;
  for (const double x : {o.dt, o.event_tolerance, o.lock_time, o.rest_velocity_ratio, o.newton_tolerance}) f.add(x);
  f.add(o.integrator);
  f.add(o.separation);
  for (const auto* rows : {&key.initial.displacement, &key.initial.velocity}) {
    f.add(rows->size());
    for (const std::vector<double>& row : *rows) f.add(row);
  }
  return f.value();
}

/// The arrays a memo entry holds [bytes], roughly: the record, the frames, the initial conditions
/// and the statistics.
std::size_t footprint(const FreeRunKey& key, const ResponseStatistics& free) {
  std::size_t doubles = 0;
  if (const auto* record = std::get_if<RecordExcitation>(&key.excitation)) {
    doubles += record->time.size() + record->acceleration.size();
  }
  for (const Frame& f : key.frames) doubles += 8 * f.mass.size() + f.modal_damping_ratios.size();
  for (const auto* rows : {&key.initial.displacement, &key.initial.velocity}) {
    for (const std::vector<double>& row : *rows) doubles += row.size();
  }
  return sizeof(FreeRunKey) + sizeof(ResponseStatistics) + sizeof(double) * doubles + sizeof(FloorResponse) * free.floors.size() +
         sizeof(NeighbourResponse) * free.neighbours.size() + 2 * sizeof(Peak) * free.base_shear.size();
}
}  // namespace

FreeRunKey free_run_key(const TimeHistoryProblem& problem, double end_time) {
  return FreeRunKey{.frames = problem.model.frames,
                    .facing = problem.model.facing,
                    .excitation = problem.excitation,
                    .options = problem.options,
                    .initial = problem.initial,
                    .end_time = end_time};
}

std::deque<FreeRunMemo::Entry>::iterator FreeRunMemo::locate(std::uint64_t print, const FreeRunKey& key) {
  return std::find_if(entries_.begin(), entries_.end(),
                      [&](const Entry& e) { return e.fingerprint == print && e.key == key; });
}

std::optional<ResponseStatistics> FreeRunMemo::find(const FreeRunKey& key) {
  const std::uint64_t print = fingerprint(key);
  const std::lock_guard lock(mutex_);
  const auto e = locate(print, key);
  if (e == entries_.end()) {
    ++misses_;
    return std::nullopt;
  }
  ++hits_;
  // The most recently used last: the least recently used goes first when the memo is full.
  std::rotate(e, e + 1, entries_.end());
  return entries_.back().free;
}

void FreeRunMemo::clear() {
  const std::lock_guard lock(mutex_);
  entries_.clear();
  bytes_ = 0;
}

std::size_t FreeRunMemo::bytes() const {
  const std::lock_guard lock(mutex_);
  return bytes_;
}

void FreeRunMemo::add(const FreeRunKey& key, const ResponseStatistics& free) {
  const std::uint64_t print = fingerprint(key);
  const std::size_t bytes = footprint(key, free);
  if (capacity_ == 0 || bytes > byte_budget_) return;
  const std::lock_guard lock(mutex_);
  if (locate(print, key) != entries_.end()) return;  // another thread made it meanwhile
  while (!entries_.empty() && (entries_.size() == capacity_ || bytes_ + bytes > byte_budget_)) {
    bytes_ -= entries_.front().bytes;
    entries_.pop_front();
  }
  entries_.push_back(Entry{.fingerprint = print, .bytes = bytes, .key = key, .free = free});
  bytes_ += bytes;
}

std::int64_t FreeRunMemo::hits() const {
  const std::lock_guard lock(mutex_);
  return hits_;
}
std::int64_t FreeRunMemo::misses() const {
  const std::lock_guard lock(mutex_);
  return misses_;
}
std::size_t FreeRunMemo::size() const {
  const std::lock_guard lock(mutex_);
  return entries_.size();
}

double output_instants(double duration, double output_dt) { return std::floor(duration / output_dt + 1e-9); }

TimeHistoryAnalysis analyse_time_history(const TimeHistoryProblem& problem, const TimeHistoryObserver& observer,
                                         FreeRunMemo* memo) {
  Simulator sim(problem.model, problem.excitation, problem.options, problem.initial);
  if (observer.on_event) sim.set_event_handler(observer.on_event);
  const double duration = problem.duration, output_dt = problem.output_dt;
  const double count = output_instants(duration, output_dt);
  if (!(count >= 0 && count < 9.2e18)) {
    throw std::invalid_argument(fmt::format("output_dt = {} s over a duration of {} s gives {} output instants",
                                            output_dt, duration, count));
  }
  const auto rows = static_cast<std::int64_t>(count);
  const auto output = [&] {
    if (observer.on_output) observer.on_output(sim);
  };
  output();
  for (std::int64_t k = 1; k <= rows; ++k) {
    sim.advance_to(static_cast<double>(k) * output_dt);
    output();
  }
  // Whether every step so far ended on the grid k·dt, as the free run's single advance_to takes them.
  const bool stepped_on_grid = sim.grid_origin() == 0.0;
  if (sim.time() < duration - 1e-9 * output_dt) {
    sim.advance_to(duration);
    output();
  }
  TimeHistoryAnalysis result{.model = sim.model(),
                             .layout = sim.layout(),
                             .options = sim.options(),
                             .statistics = sim.statistics(),
                             .free = std::nullopt,
                             .energy = sim.energy(),
                             .element_dissipation = element_dissipation_of(sim.energy_meter()),
                             .final_drift = {},
                             .storey_hysteretic = std::vector<double>(sim.energy_meter().storey_hysteretic().begin(),
                                                                      sim.energy_meter().storey_hysteretic().end()),
                             .relative_residual = sim.energy_meter().relative_residual(),
                             .max_relative_residual = sim.energy_meter().max_relative_residual(),
                             .end_time = sim.time()};
  for (int dof = 0; dof < sim.layout().size(); ++dof) result.final_drift.push_back(sim.storey_drift(dof));
  // The same frames without gap elements, for amplifications and separation distances.
  if (problem.model.gap_count() > 0) {
    if (stepped_on_grid && ran_as_the_frames_alone(result.statistics)) {
      result.free = frames_alone(result.statistics);
      result.free_from_this_run = true;
    } else {
      std::optional<FreeRunKey> key;
      if (memo != nullptr) {
        key = free_run_key(problem, sim.time());
        result.free = memo->find(*key);
      }
      if (!result.free) {
        Simulator alone(free_frames(problem.model), problem.excitation, problem.options, problem.initial);
        alone.meter_energy(false);  // its peaks alone are reported
        alone.advance_to(sim.time());
        result.free = alone.statistics();
        if (key) memo->add(*key, *result.free);  // free runs only: what a point takes is one
      }
    }
  }
  return result;
}

std::optional<std::string> energy_balance_warning(double max_relative_residual, Integrator integrator,
                                                  bool smooth_laws, const EnergyBalanceCheck& check) {
  if (!(max_relative_residual > check.warn_above)) return std::nullopt;
  const std::string advice =
      integrator == Integrator::newmark && smooth_laws
          ? "a smooth law's balance closes as dt²: halve analysis.dt until the peaks stop moving"
          : "this model's balance should close to round-off: a smaller analysis.dt or analysis.event_tolerance may "
            "help; if not, the run is worth reporting";
  return fmt::format("the energy balance's relative residual reached {:.2e}, above {:.0e}: the response may not be "
                     "accurate; {}",
                     max_relative_residual, check.warn_above, advice);
}

}  // namespace poundsim
