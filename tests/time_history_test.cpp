// The time history as an analysis without files (analysis/time_history.hpp): its observer sees
// the state at every output instant and every event, and the result holds the peaks and the
// free frames' response.

#include "poundsim/analysis/time_history.hpp"

#include <array>
#include <cmath>
#include <numbers>
#include <vector>

#include <gtest/gtest.h>

#include "poundsim/model/dimensionless.hpp"
#include "poundsim/units.hpp"
#include "test_models.hpp"

namespace poundsim {
namespace {

// One undamped storey released from u₀ in free vibration: with the exact integrator every output
// is u₀ cos ωt, at exactly the instants k·output_dt and at the duration (not a multiple).
TEST(TimeHistoryAnalysis, OutputsAtEveryInstantFollowTheClosedForm) {
  const double mass = 2.0, stiffness = 800.0, u0 = 0.01;
  const double omega = std::sqrt(stiffness / mass);
  TimeHistoryProblem problem{.model = make_model({make_uniform_frame(1, mass, stiffness, 0.0, "alone")}, GapProperties{}),
                             .excitation = NoExcitation{},
                             .options = {},
                             .initial = {},
                             .duration = 1.05,
                             .output_dt = 0.1};
  problem.options.dt = 0.01;
  problem.options.integrator = Integrator::exact;
  problem.initial.displacement = {{u0}};
  problem.initial.velocity = {{0.0}};
  std::vector<double> times;
  TimeHistoryObserver observer;
  observer.on_output = [&](const Simulator& sim) {
    times.push_back(sim.time());
    EXPECT_NEAR(sim.state().u(0), u0 * std::cos(omega * sim.time()), 1e-13) << "t = " << sim.time();
  };
  int events = 0;
  observer.on_event = [&](const Event&) { ++events; };
  const TimeHistoryAnalysis result = analyse_time_history(problem, observer);
  ASSERT_EQ(times.size(), 12u);  // t = 0, 0.1, …, 1.0, and the duration 1.05
  // The clock runs on the step grid (k·dt): an instant k·output_dt lands on it to round-off.
  for (std::size_t k = 0; k + 1 < times.size(); ++k) EXPECT_NEAR(times[k], static_cast<double>(k) * 0.1, 1e-15);
  EXPECT_EQ(times.back(), 1.05);
  EXPECT_EQ(result.end_time, 1.05);
  EXPECT_EQ(events, 0);
  EXPECT_FALSE(result.free.has_value());  // no gap elements: nothing to compare with
  EXPECT_NEAR(result.statistics.floors[0].displacement.value, u0, 1e-15);
  // No damping and no input: the energy stays ½ k u₀².
  EXPECT_NEAR(result.energy.kinetic + result.energy.storey_strain, 0.5 * stiffness * u0 * u0, 1e-15);
}

/// The Fig. 2c frames with the given storeys under A = 0.2 g at ω̄/ω₁ = 0.8, Newmark with step dt.
TimeHistoryProblem fig2c_problem(std::array<int, 2> storeys, double duration, double output_dt, double dt) {
  const DimensionlessParameters p = testing::fig2('c');
  TimeHistoryProblem problem{.model = make_model(p, storeys),
                             .excitation = HarmonicExcitation{0.2 * standard_gravity, 0.8 * std::sqrt(p.lambda2)},
                             .options = {},
                             .initial = {},
                             .duration = duration,
                             .output_dt = output_dt};
  problem.options.dt = dt;
  return problem;
}

// Two frames that pound: the observer sees the events the result counts, and the free frames'
// response (no gap elements) comes with the result.
TEST(TimeHistoryAnalysis, EventsReachTheObserverAndTheFreeFramesComeAlong) {
  const TimeHistoryProblem problem = fig2c_problem({1, 1}, 5.0, 0.5, 0.001);
  int events = 0;
  const TimeHistoryAnalysis result =
      analyse_time_history(problem, {.on_output = {}, .on_event = [&](const Event&) { ++events; }});
  EXPECT_GT(events, 0);
  EXPECT_EQ(events, result.statistics.events);
  ASSERT_TRUE(result.free.has_value());
  EXPECT_EQ(result.free->events, 0);
  EXPECT_NE(result.free->base_shear[0].value, result.statistics.base_shear[0].value);
  EXPECT_LT(result.max_relative_residual, 1e-6);
}

// A first storey's drift is its floor's displacement: both peaks are refined between samples
// alike, with either integrator (the drift used to be taken at the samples only).
TEST(TimeHistoryAnalysis, FirstStoreyDriftPeakIsTheDisplacementPeak) {
  for (const Integrator integrator : {Integrator::newmark, Integrator::exact}) {
    TimeHistoryProblem problem = fig2c_problem({1, 3}, 3.0, 3.0, 0.01);
    problem.options.integrator = integrator;
    const TimeHistoryAnalysis result = analyse_time_history(problem);
    for (int f = 0; f < result.model.frame_count(); ++f) {
      const FloorResponse& first = result.statistics.floors[static_cast<std::size_t>(result.layout.dof(f, 0))];
      EXPECT_EQ(first.drift.value, first.displacement.value) << to_string(integrator) << " frame " << f + 1;
      EXPECT_EQ(first.drift.time, first.displacement.time) << to_string(integrator) << " frame " << f + 1;
    }
  }
}

}  // namespace
}  // namespace poundsim
