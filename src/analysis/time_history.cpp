#include "poundsim/analysis/time_history.hpp"

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
    Simulator alone(free_frames(problem.model), problem.excitation, problem.options, problem.initial);
    alone.meter_energy(false);  // its peaks alone are reported
    alone.advance_to(sim.time());
    result.free = alone.statistics();
  }
  return result;
}

}  // namespace poundsim
