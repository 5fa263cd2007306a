// The time history as an analysis without files (analysis/time_history.hpp): its observer sees
// the state at every output instant and every event, and the result holds the peaks and the
// free frames' response.

#include "poundsim/analysis/time_history.hpp"

#include <array>
#include <cstdint>
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

// Points of a study that differ in their gap elements share their free run (FreeRunMemo): the
// second point takes the first's, and it is the bits its own free run gives. Anything else that
// differs — a frame's mass, the end, an initial displacement of −0 instead of +0 — is a new run;
// the oldest run goes when the memo is full.
TEST(FreeRunMemo, PointsDifferingInTheirGapElementsShareTheFreeRunToTheBit) {
  FreeRunMemo memo;
  const TimeHistoryProblem first = fig2c_problem({1, 2}, 4.0, 4.0, 0.001);
  const TimeHistoryAnalysis a = analyse_time_history(first, {}, &memo);
  EXPECT_EQ(memo.hits(), 0);
  EXPECT_EQ(memo.misses(), 1);
  EXPECT_EQ(memo.size(), 1u);
  ASSERT_GT(a.statistics.events, 0);  // it pounds: the free run is a run of its own

  TimeHistoryProblem stiffer = first;
  for (GapElement& g : stiffer.model.gaps) parameters_of<PaperGap>(g).stiffness *= 3.0;
  const TimeHistoryAnalysis b = analyse_time_history(stiffer, {}, &memo);
  EXPECT_EQ(memo.hits(), 1);
  EXPECT_NE(b.statistics.base_shear[0].value, a.statistics.base_shear[0].value);  // another point
  const TimeHistoryAnalysis alone = analyse_time_history(stiffer);  // no memo: its own free run
  ASSERT_TRUE(b.free && alone.free);
  testing::expect_same_frame_peaks(*b.free, *alone.free);
  EXPECT_FALSE(b.free_from_this_run);

  const auto expect_new_run = [&](const TimeHistoryProblem& problem, const char* what) {
    const std::int64_t misses = memo.misses(), hits = memo.hits();
    const TimeHistoryAnalysis r = analyse_time_history(problem, {}, &memo);
    EXPECT_EQ(memo.misses(), misses + 1) << what;
    EXPECT_EQ(memo.hits(), hits) << what;
    testing::expect_same_frame_peaks(*r.free, *analyse_time_history(problem).free);
  };
  TimeHistoryProblem heavier = first;
  heavier.model.frames[1].mass[1] *= 1.5;
  expect_new_run(heavier, "a frame's mass");
  TimeHistoryProblem longer = first;
  longer.duration = longer.output_dt = 4.5;
  expect_new_run(longer, "the duration");
  TimeHistoryProblem at_rest = first;
  at_rest.initial.displacement = {{0.0}, {0.0, 0.0}};
  at_rest.initial.velocity = {{0.0}, {0.0, 0.0}};
  expect_new_run(at_rest, "initial conditions given");
  TimeHistoryProblem negative_zero = at_rest;
  negative_zero.initial.displacement[0][0] = -0.0;
  ASSERT_TRUE(free_run_key(negative_zero, 4.0) == free_run_key(at_rest, 4.0));  // == alone would take it
  expect_new_run(negative_zero, "−0 for +0");

  FreeRunMemo one(1);
  one.add(free_run_key(first, 4.0), *a.free);
  one.add(free_run_key(heavier, 4.0), *a.free);
  EXPECT_EQ(one.size(), 1u);
  EXPECT_FALSE(one.find(free_run_key(first, 4.0)).has_value());
  EXPECT_TRUE(one.find(free_run_key(heavier, 4.0)).has_value());

  // A byte budget: a record is its samples (10⁵ of them, 1.6 MB with their times).
  const auto with_record = [&](double scale) {
    TimeHistoryProblem p = first;
    RecordExcitation record{.time = {}, .acceleration = {}, .source = "long"};
    for (int i = 0; i < 100000; ++i) {
      record.time.push_back(0.01 * i);
      record.acceleration.push_back(scale * std::sin(0.01 * i));
    }
    p.excitation = record;
    return free_run_key(p, 4.0);
  };
  FreeRunMemo budget(64, 3'000'000);
  budget.add(with_record(1.0), *a.free);
  EXPECT_EQ(budget.size(), 1u);
  EXPECT_GT(budget.bytes(), 1'600'000u);
  budget.add(with_record(2.0), *a.free);  // both would exceed 3 MB: the first goes
  EXPECT_EQ(budget.size(), 1u);
  EXPECT_FALSE(budget.find(with_record(1.0)).has_value());
  EXPECT_TRUE(budget.find(with_record(2.0)).has_value());
  FreeRunMemo small(64, 1'000'000);
  small.add(with_record(1.0), *a.free);  // larger than the whole budget: not kept
  EXPECT_EQ(small.size(), 0u);
  EXPECT_EQ(small.bytes(), 0u);
  budget.clear();
  EXPECT_EQ(budget.size(), 0u);
  EXPECT_EQ(budget.bytes(), 0u);
}

}  // namespace
}  // namespace poundsim
