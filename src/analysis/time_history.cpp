#include "poundsim/analysis/time_history.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include <fmt/format.h>

#include "poundsim/analysis/response_metrics.hpp"

namespace poundsim {

namespace {
std::vector<double> element_dissipation_of(const EnergyMeter& meter) {
  const auto per_element = meter.element_dissipation();
  return per_element ? std::vector<double>(per_element->begin(), per_element->end()) : std::vector<double>{};
}

/// No gap element ever closed: it transmitted nothing (an open element's force is 0 by its law),
/// so the frames moved as they would without it.
bool no_gap_element_closed(const ResponseStatistics& run) {
  return std::all_of(run.gaps.begin(), run.gaps.end(), [](const GapResponse& g) {
    return g.contacts == 0 && g.separations == 0 && g.impacts == 0 && g.locks == 0 && g.contact_time == 0.0;
  });
}

/// The free frames' statistics taken from a run whose gap elements never closed. Its steps are
/// the ones the free run takes (the same grid, the same storey events), and stepping with the
/// open elements' stored zeros in C, K and the factor gives the same bits (docs/numerics.md,
/// "The free frames of a run without contact"), so every peak is the free run's to the bit. Its
/// counts are the run's: the guards of the gap elements were evaluated too.
ResponseStatistics frames_alone(const ResponseStatistics& run) {
  ResponseStatistics free = run;
  free.gaps.clear();
  return free;
}
}  // namespace

double output_instants(double duration, double output_dt) { return std::floor(duration / output_dt + 1e-9); }

TimeHistoryAnalysis analyse_time_history(const TimeHistoryProblem& problem, const TimeHistoryObserver& observer) {
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
    if (stepped_on_grid && no_gap_element_closed(result.statistics)) {
      result.free = frames_alone(result.statistics);
      result.free_from_this_run = true;
    } else {
      Simulator alone(free_frames(problem.model), problem.excitation, problem.options, problem.initial);
      alone.meter_energy(false);  // its peaks alone are reported
      alone.advance_to(sim.time());
      result.free = alone.statistics();
    }
  }
  return result;
}

}  // namespace poundsim
