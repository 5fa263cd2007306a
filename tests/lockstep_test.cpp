// Simulators stepped in lockstep (integrate/lockstep.hpp): every lane to the bit of its simulator
// stepped alone, whatever the lanes beside it; a lane that fails fails as it would alone.

#include "poundsim/integrate/lockstep.hpp"

#include <array>
#include <bit>
#include <cmath>
#include <cstdint>
#include <memory>
#include <numbers>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "poundsim/analysis/frequency_response.hpp"  // reference_frequency
#include "poundsim/integrate/simulator.hpp"
#include "test_models.hpp"

namespace poundsim {
namespace {

constexpr double kG = 9.81;

/// What a lane is: a Fig. 2 system under a harmonic forcing at ratio × ω₁, dt = T/128, its
/// transient settings (no peaks, no balance) unless `record`.
struct LaneSpec {
  char panel = 'c';
  std::array<int, 2> storeys{1, 1};
  double ratio = 0.8;
  double amplitude_g = 0.2;
  double delta = 0.25;  ///< δ̄, the gap over the static drift
  bool record = false;
  Integrator integrator = Integrator::newmark;
};

std::unique_ptr<Simulator> make_lane(const LaneSpec& spec) {
  DimensionlessParameters p = testing::fig2(spec.panel);
  p.delta = spec.delta;
  const Model model = make_model(p, spec.storeys);
  const double omega = spec.ratio * reference_frequency(model);
  TimeHistoryOptions o;
  o.dt = 2 * std::numbers::pi / omega / 128;
  o.integrator = spec.integrator;
  auto sim = std::make_unique<Simulator>(model, HarmonicExcitation{spec.amplitude_g * kG, omega}, o);
  sim->record_responses(spec.record);
  sim->meter_energy(spec.record);
  return sim;
}

std::uint64_t bits(double x) { return std::bit_cast<std::uint64_t>(x); }

/// Every number the lane's simulator keeps, to the bit (−0 told from +0).
void expect_same_simulator(const Simulator& lane, const Simulator& alone, std::size_t which) {
  SCOPED_TRACE(::testing::Message() << "lane " << which);
  EXPECT_EQ(bits(lane.time()), bits(alone.time()));
  EXPECT_EQ(bits(lane.state().ground), bits(alone.state().ground));
  for (Eigen::Index i = 0; i < alone.state().u.size(); ++i) {
    EXPECT_EQ(bits(lane.state().u(i)), bits(alone.state().u(i))) << "u of DOF " << i;
    EXPECT_EQ(bits(lane.state().v(i)), bits(alone.state().v(i))) << "v of DOF " << i;
    EXPECT_EQ(bits(lane.state().a(i)), bits(alone.state().a(i))) << "a of DOF " << i;
  }
  EXPECT_EQ(lane.configuration(), alone.configuration());
  EXPECT_EQ(lane.statistics().steps, alone.statistics().steps);
  EXPECT_EQ(lane.statistics().substeps, alone.statistics().substeps);
  EXPECT_EQ(lane.statistics().events, alone.statistics().events);
  EXPECT_EQ(lane.statistics().guard_evaluations, alone.statistics().guard_evaluations);
  EXPECT_EQ(lane.statistics().grazing_checks, alone.statistics().grazing_checks);
  if (alone.statistics().events > 0) {
    testing::expect_same_peaks(lane.statistics(), alone.statistics());  // the gap elements' too
  } else {
    testing::expect_same_frame_peaks(lane.statistics(), alone.statistics());
  }
}

/// Steps `specs` in lockstep, `calls` × `steps` grid steps, and each alone with step(); compares.
Lockstep::Counts run_and_compare(const std::vector<LaneSpec>& specs, int calls, int steps) {
  std::vector<std::unique_ptr<Simulator>> lanes, alone;
  std::vector<Simulator*> pointers;
  for (const LaneSpec& spec : specs) {
    lanes.push_back(make_lane(spec));
    alone.push_back(make_lane(spec));
    pointers.push_back(lanes.back().get());
  }
  std::vector<std::exception_ptr> errors(specs.size());
  Lockstep batch;
  for (int c = 0; c < calls; ++c) batch.step(pointers, steps, errors);
  for (std::size_t l = 0; l < specs.size(); ++l) {
    EXPECT_EQ(errors[l], nullptr);
    for (int s = 0; s < calls * steps; ++s) alone[l]->step();
    expect_same_simulator(*lanes[l], *alone[l], l);
    // And both go on to the same next step.
    lanes[l]->step();
    alone[l]->step();
    expect_same_simulator(*lanes[l], *alone[l], l);
  }
  return batch.counts();
}

TEST(Lockstep, EveryLaneIsItsSimulatorSteppedAloneToTheBit) {
  // Eight Fig. 2c systems at ratios across the range of Fig. 2: lanes that never touch, and
  // lanes that pound (their phases in contact stepped in lockstep; contacts, impacts, locks:
  // those steps refused and taken by step()).
  std::vector<LaneSpec> specs;
  for (const double ratio : {0.3, 0.55, 0.7, 0.8, 0.95, 1.05, 1.3, 1.6}) specs.push_back({.ratio = ratio});
  const Lockstep::Counts counts = run_and_compare(specs, 40, 128);
  EXPECT_GT(counts.lean, 20000);    // most steps in lockstep …
  EXPECT_GT(counts.refused, 20);    // … some refused at an event, stepped alone
  EXPECT_EQ(counts.lean + counts.general, 8 * 40 * 128);  // a refused step is one of step()'s
}

TEST(Lockstep, LanesThatCannotBeLeanStepAsAlone) {
  // Mixed lanes: recording ones, the exact integrator, Fig. 2a's elastic impacts, beside lean ones.
  const std::vector<LaneSpec> specs{
      {.ratio = 0.8, .record = true},
      {.ratio = 0.8},
      {.panel = 'a', .ratio = 1.3},
      {.ratio = 0.6, .integrator = Integrator::exact},
  };
  const Lockstep::Counts counts = run_and_compare(specs, 3, 100);
  EXPECT_GT(counts.lean, 300);
  EXPECT_GE(counts.general, 2 * 300);  // the recording and exact lanes
}

TEST(Lockstep, MultiStoreyLanesPoundingStepInBands) {
  // Three-storey frames at ratios that pound (a band of width 2 — a storey joins DOFs two apart,
  // an element in contact neighbours — open and in contact), and a lane of another size, which
  // steps alone. (The narrower lanes stepped at a wider band, with zeros, are Fig. 2c's open
  // phases beside phases in contact: the test above.)
  std::vector<LaneSpec> specs;
  for (const double ratio : {0.5, 0.8, 0.95, 1.1, 1.4}) specs.push_back({.storeys = {3, 3}, .ratio = ratio});
  specs.push_back({.storeys = {2, 2}, .ratio = 0.9});
  const Lockstep::Counts counts = run_and_compare(specs, 20, 128);
  EXPECT_GT(counts.lean, 5 * 20 * 100);
  EXPECT_GT(counts.refused, 50);
  EXPECT_GE(counts.general, 20 * 128);  // the two-storey lane
}

TEST(Lockstep, OneLaneAndThreeLanesAgree) {
  run_and_compare({{.ratio = 1.05}}, 4, 128);
  run_and_compare({{.ratio = 0.9}, {.ratio = 1.05}, {.ratio = 0.5}}, 4, 128);
}

TEST(Lockstep, LanesRefusedAtOnceAreEachWrittenBack) {
  // Two equal lanes are refused at the same steps (grazing checks, events) with no lane left in
  // lockstep: the first one's general step and return to the batch must not disturb the state
  // the second still holds there.
  // Apart (δ̄ = 100), so that a refused step (a grazing check) leaves each in lockstep again.
  const Lockstep::Counts counts = run_and_compare({{.ratio = 1.05, .delta = 100}, {.ratio = 1.05, .delta = 100}}, 10, 128);
  EXPECT_GE(counts.refused, 10);
  run_and_compare({{.ratio = 1.05}, {.ratio = 1.05}}, 10, 128);  // and pounding
}

TEST(Lockstep, AFailingLaneFailsAsAloneAndTheOthersGoOn) {
  // 1e306 g: the state overflows within a few steps. The lean step refuses the non-finite state
  // and the simulator's own step names it.
  const LaneSpec bad{.ratio = 0.8, .amplitude_g = 1e306};
  auto failing = make_lane(bad), alone = make_lane(bad), fine = make_lane({.ratio = 0.7});
  std::vector<Simulator*> pointers{failing.get(), fine.get()};
  std::vector<std::exception_ptr> errors(2);
  Lockstep batch;
  batch.step(pointers, 400, errors);
  ASSERT_NE(errors[0], nullptr);
  EXPECT_EQ(errors[1], nullptr);
  std::string lane_message, alone_message;
  try {
    std::rethrow_exception(errors[0]);
  } catch (const SimulationError& e) {
    EXPECT_EQ(e.reason(), StopReason::non_finite);
    lane_message = e.what();
  }
  try {
    for (int s = 0; s < 400; ++s) alone->step();
  } catch (const SimulationError& e) {
    alone_message = e.what();
  }
  EXPECT_FALSE(alone_message.empty());
  EXPECT_EQ(lane_message, alone_message);
  EXPECT_EQ(fine->statistics().steps, 400);
  auto fine_alone = make_lane({.ratio = 0.7});
  for (int s = 0; s < 400; ++s) fine_alone->step();
  expect_same_simulator(*fine, *fine_alone, 1);
  // A failed lane is skipped by the next call (its error kept), and throws again alone.
  batch.step(pointers, 10, errors);
  EXPECT_EQ(fine->statistics().steps, 410);
  EXPECT_THROW(failing->step(), SimulationError);
  std::vector<Simulator*> too_many(9, nullptr);
  std::vector<std::exception_ptr> their_errors(9);
  EXPECT_THROW(batch.step(too_many, 1, their_errors), std::invalid_argument);
}

}  // namespace
}  // namespace poundsim
