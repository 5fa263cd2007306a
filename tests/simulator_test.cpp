// The event-driven simulator: impacts, contact times, locking, convergence, the paper's systems.

#include "poundsim/integrate/simulator.hpp"

#include <cmath>
#include <numbers>
#include <tuple>

#include <gtest/gtest.h>

#include "poundsim/error.hpp"
#include "test_models.hpp"

namespace poundsim {
namespace {

using testing::two_oscillators;

TEST(SimulatorImpacts, ElasticImpactsConserveEnergyAndMomentum) {
  // Undamped frames, no ground motion, e = 1: the mechanical energy is an invariant of the
  // continuous problem, of Newmark's average-acceleration scheme and of the impact law.
  const Model model =
      two_oscillators(1.0, 200.0, 0.0, 1.5, 60.0, 0.0, GapProperties{.gap = 0.01, .restitution = 1.0});
  InitialConditions ic;
  ic.velocity = {{0.5}, {-0.2}};
  Simulator sim(model, NoExcitation{}, TimeHistoryOptions{.dt = 1e-3}, ic);
  const double e0 = sim.energy().initial;
  int impacts = 0;
  double worst_momentum = 0;
  sim.set_event_handler([&](const Event& e) {
    if (e.kind != EventKind::impact) return;
    ++impacts;
    const double before = 1.0 * e.left_velocity_before + 1.5 * e.right_velocity_before;
    const double after = 1.0 * e.left_velocity_after + 1.5 * e.right_velocity_after;
    worst_momentum = std::max(worst_momentum, std::abs(after - before));
    EXPECT_NEAR(e.rate_after, -e.rate_before, 1e-14);
  });
  double worst_energy = 0;
  for (int k = 1; k <= 1000; ++k) {
    sim.advance_to(0.01 * k);
    const EnergyBalance& b = sim.energy();
    worst_energy = std::max(worst_energy, std::abs(b.kinetic + b.storey_strain - e0) / e0);
  }
  EXPECT_GT(impacts, 20);
  EXPECT_LT(worst_energy, 1e-9);
  EXPECT_LT(worst_momentum, 1e-14);
  EXPECT_NEAR(sim.energy().impact_loss, 0.0, 1e-14 * e0);  // round-off of ΔT over the impacts
}

TEST(SimulatorImpacts, FirstContactTimeMatchesTheClosedForm) {
  // Frame 1 leaves u = 0 with velocity V towards frame 2 at rest: u₁ = (V/ω) sin ωt reaches the
  // gap δ at t = asin(δω/V)/ω. With h = 2e-6 s Newmark's phase error is ~1e-12 s.
  const double k = 200.0, V = 0.3, delta = 0.01, w = std::sqrt(k);
  const double exact = std::asin(delta * w / V) / w;
  const Model model = two_oscillators(1.0, k, 0.0, 1.0, 50.0, 0.0,
                                      GapProperties{.gap = delta, .restitution = 0.5});
  InitialConditions ic;
  ic.velocity = {{V}, {0.0}};
  for (const double tolerance : {1e-6, 1e-8, 1e-10}) {
    TimeHistoryOptions options{.dt = 2e-6, .event_tolerance = tolerance, .lock_time = 1e-4};
    Simulator sim(model, NoExcitation{}, options, ic);
    double first = -1;
    sim.set_event_handler([&](const Event& e) {
      if (first < 0) first = e.time;
    });
    sim.advance_to(0.05);
    ASSERT_GT(first, 0) << "no contact";
    EXPECT_LE(std::abs(first - exact), tolerance + 1e-11) << "tolerance " << tolerance;
    EXPECT_GE(first, exact - 1e-11);  // the event is reported at the upper end of its bracket
  }
}

TEST(SimulatorImpacts, SymmetricSimultaneousImpactsOnAMiddleFrame) {
  // Frames 1 and 3 hit frame 2 at the same instant from both sides (e = 1, equal masses): the
  // outer frames bounce back with their velocity reversed and the middle one stays at rest.
  const Frame f = make_uniform_frame(1, 1.0, 100.0, 0.0);
  const Model model = make_model({f, f, f}, GapProperties{.gap = 0.01, .restitution = 1.0});
  InitialConditions ic;
  ic.velocity = {{0.4}, {0.0}, {-0.4}};
  Simulator sim(model, NoExcitation{}, TimeHistoryOptions{.dt = 1e-3}, ic);
  std::vector<Event> events;
  sim.set_event_handler([&](const Event& e) { events.push_back(e); });
  double t_impact = -1;
  while (events.empty()) sim.step();
  t_impact = events.front().time;
  ASSERT_EQ(events.size(), 2u);
  EXPECT_EQ(events[0].time, events[1].time);
  EXPECT_NEAR(events[0].left_velocity_after, -events[0].left_velocity_before, 1e-12);
  EXPECT_NEAR(events[1].right_velocity_after, -events[1].right_velocity_before, 1e-12);
  EXPECT_NEAR(events[0].right_velocity_after, 0.0, 1e-12);
  EXPECT_GT(t_impact, 0.0);
  EXPECT_NEAR(testing::momentum(sim), 0.0, 1e-12);
}

TEST(SimulatorImpacts, ImpactThroughAChainIsNewtonsCradle) {
  // Frame 1 strikes frames 2 and 3, which touch (δ = 0): with e = 1 and equal masses the
  // velocity passes through frame 2 to frame 3.
  const Frame f = make_uniform_frame(1, 1.0, 1.0, 0.0);  // soft storeys: a short free flight
  Model model = make_model({f, f, f}, GapProperties{.gap = 0.0, .restitution = 1.0});
  parameters_of<PaperGap>(model.gaps[0]).gap = 0.001;
  InitialConditions ic;
  ic.velocity = {{0.5}, {0.0}, {0.0}};
  Simulator sim(model, NoExcitation{}, TimeHistoryOptions{.dt = 1e-4}, ic);
  sim.advance_to(0.01);
  EXPECT_NEAR(sim.state().v(0), 0.0, 1e-3);
  EXPECT_NEAR(sim.state().v(1), 0.0, 1e-3);
  EXPECT_NEAR(sim.state().v(2), 0.5, 1e-3);
  EXPECT_EQ(sim.statistics().gaps[0].impacts, 1);
  EXPECT_EQ(sim.statistics().gaps[1].impacts, 1);
}

/// Frame 1 (soft) is pressed against frame 2 (stiff) by a constant ground acceleration.
struct PressedFrames {
  double m1 = 1, k1 = 25, c1 = 1, m2 = 1, k2 = 400, c2 = 4, push = 2.0;  // push [m/s²]
  Excitation ground() const { return RecordExcitation{{0.0, 1000.0}, {-push, -push}, "constant"}; }
  /// Static solution with the stop closed at δ + ε: u₂ and the total gap force.
  std::pair<double, double> statics(const GapProperties& g) const {
    const double closure = g.gap + g.shortening;
    const double u2 = ((m1 + m2) * push - k1 * closure) / (k1 + k2);
    return {u2, k2 * u2 - m2 * push};
  }
};

class SimulatorLocking : public ::testing::TestWithParam<std::tuple<double, bool>> {};

TEST_P(SimulatorLocking, PressedFramesStopChatteringAndReachTheStaticContact) {
  const auto [restitution, device] = GetParam();
  const PressedFrames pf;
  GapProperties g{.gap = 0.02, .restitution = restitution};
  if (device) {
    g.stiffness = 20.0;  // too soft to carry the push alone: the stop closes
    g.damping = 0.5;
    g.shortening = 0.004;
  }
  const Model model = two_oscillators(pf.m1, pf.k1, pf.c1, pf.m2, pf.k2, pf.c2, g);
  Simulator sim(model, pf.ground(), TimeHistoryOptions{.dt = 1e-3});
  sim.advance_to(40.0);
  const auto [u2, force] = pf.statics(g);
  EXPECT_EQ(PaperGap::gap_mode(sim.configuration()[0]), GapMode::locked);
  EXPECT_NEAR(sim.state().u(1), u2, 1e-7);
  // The link keeps the floors where they locked: on the stop to |ṡ| × event tolerance.
  EXPECT_NEAR(sim.state().u(0) - sim.state().u(1), g.gap + g.shortening, 1e-9);
  EXPECT_NEAR(sim.gap_force(0), force, 1e-5);
  EXPECT_GT(force - g.stiffness * g.shortening, 0.0);  // the stop carries part of the push
  // Chattering is cut short: a bounded number of impacts, not an accumulation.
  EXPECT_GE(sim.statistics().gaps[0].locks, 1);
  EXPECT_LT(sim.statistics().events, 400);
  EXPECT_LT(sim.energy_meter().max_relative_residual(), 1e-9);
}

INSTANTIATE_TEST_SUITE_P(RestitutionAndDevice, SimulatorLocking,
                         ::testing::Combine(::testing::Values(0.0, 0.5, 0.9),
                                            ::testing::Values(false, true)));

TEST(SimulatorLocking, LockedPairReleasesWhenTheStopReactionTurnsTensile) {
  // The push reverses at t = 5 s: the locked pair must let go and frame 1 swing away.
  const PressedFrames pf;
  const Model model = two_oscillators(pf.m1, pf.k1, pf.c1, pf.m2, pf.k2, pf.c2,
                                      GapProperties{.gap = 0.02, .restitution = 0.5});
  const Excitation ground =
      RecordExcitation{{0.0, 5.0, 5.001, 100.0}, {-pf.push, -pf.push, pf.push, pf.push}, "reversal"};
  Simulator sim(model, ground, TimeHistoryOptions{.dt = 1e-3});
  // An event handler that asks for the element's force sees the element as the event left it:
  // a rigid stop that unlocked is open and carries nothing (no stop reaction any more).
  std::vector<double> force_at_unlock;
  sim.set_event_handler([&](const Event& e) {
    if (e.kind == EventKind::unlock) force_at_unlock.push_back(sim.gap_force(e.gap));
  });
  sim.advance_to(5.0);
  EXPECT_EQ(PaperGap::gap_mode(sim.configuration()[0]), GapMode::locked);
  sim.advance_to(6.0);
  EXPECT_EQ(PaperGap::gap_mode(sim.configuration()[0]), GapMode::open);
  EXPECT_GE(sim.statistics().gaps[0].unlocks, 1);
  ASSERT_FALSE(force_at_unlock.empty());
  for (const double f : force_at_unlock) EXPECT_EQ(f, 0.0);
  EXPECT_LT(sim.state().u(0) - sim.state().u(1), 0.02);
}

TEST(SimulatorConvergence, SecondOrderWithEventsLocated) {
  // Fig. 2c system, 3 s of 0.2 g harmonic forcing at ω̄/ω₁ = 0.8: contacts, an impact and
  // separations, all located inside the steps. The state at 3 s converges at order 2.
  const Model model = make_model(testing::fig2('c'), {1, 1});
  const auto run = [&](double dt) {
    Simulator sim(model, testing::harmonic(model, 0.2, 0.8), TimeHistoryOptions{.dt = dt});
    sim.advance_to(3.0);
    Eigen::VectorXd x(4);
    x << sim.state().u, sim.state().v;
    return std::make_pair(x, sim.statistics().events);
  };
  const auto [x1, n1] = run(2e-3);
  const auto [x2, n2] = run(1e-3);
  const auto [x3, n3] = run(5e-4);
  const auto [x4, n4] = run(2.5e-4);
  EXPECT_EQ(n1, n4);  // the same sequence of events at every step size
  EXPECT_GE(n4, 8);
  const double d1 = (x1 - x2).norm(), d2 = (x2 - x3).norm(), d3 = (x3 - x4).norm();
  EXPECT_GE(std::log2(d1 / d2), 1.8);
  EXPECT_GE(std::log2(d2 / d3), 1.8);
}

TEST(SimulatorPaperSystems, Fig4WithZeroGapRunsToCompletion) {
  // δ̄ = 0: the frames touch at rest and are pushed together half of every cycle.
  for (const char panel : {'a', 'b'}) {
    const Model model = make_model(testing::fig4(panel), {1, 3});
    for (const double ratio : {0.4, 0.7, 1.0, 1.6}) {
      Simulator sim(model, testing::harmonic(model, 0.2, ratio), TimeHistoryOptions{.dt = 1e-3});
      sim.advance_to(20.0);
      EXPECT_DOUBLE_EQ(sim.time(), 20.0);
      EXPECT_GT(sim.statistics().events, 10) << panel << " " << ratio;
      EXPECT_LT(sim.statistics().events, 20000) << panel << " " << ratio;
      EXPECT_LT(sim.energy_meter().max_relative_residual(), 1e-9) << panel << " " << ratio;
    }
  }
}

TEST(SimulatorEnergy, BalanceClosesToRoundOffOnThePaperSystems) {
  for (const char panel : {'a', 'b', 'c'}) {
    const Model model = make_model(testing::fig2(panel), {1, 1});
    Simulator sim(model, testing::harmonic(model, 0.2, 0.8), TimeHistoryOptions{.dt = 1e-3});
    sim.advance_to(20.0);
    const EnergyBalance& b = sim.energy();
    EXPECT_GT(b.input, 0.0);
    EXPECT_LT(sim.energy_meter().max_relative_residual(), 1e-11) << panel;
    if (panel == 'a') {
      EXPECT_NEAR(b.impact_loss, 0.0, 1e-14 * b.input);
    } else {
      EXPECT_GT(b.impact_loss, 0.0);
    }
    if (panel == 'c') {
      EXPECT_GT(b.gap_damping, 1e-3 * b.input);
    }
  }
}

TEST(SimulatorEvents, GrazingContactInsideOneStepIsFound) {
  // Amplitude 1 % above the gap: frame 1 is beyond δ for 0.02 s around t = 0.111 s, inside one
  // step of 0.05 s whose ends are both short of the gap.
  const double k = 200.0, w = std::sqrt(k), delta = 0.01, amplitude = 1.01 * delta;
  const Model model =
      two_oscillators(1.0, k, 0.0, 1.0, 50.0, 0.0, GapProperties{.gap = delta, .restitution = 1.0});
  InitialConditions ic;
  ic.velocity = {{amplitude * w}, {0.0}};
  Simulator sim(model, NoExcitation{}, TimeHistoryOptions{.dt = 0.05}, ic);
  double first = -1;
  sim.set_event_handler([&](const Event& e) {
    if (first < 0) first = e.time;
  });
  sim.advance_to(0.1);
  EXPECT_LT(sim.state().u(0), delta);  // the grid point itself misses the contact
  EXPECT_EQ(sim.statistics().grazing_checks, 0);  // the guard rises through both ends so far
  sim.advance_to(0.2);
  EXPECT_GT(first, 0.1);
  EXPECT_LT(first, 0.12);
  // The step found by its interior maximum: one grazing check, counted among the trial sub-steps
  // (guard_evaluations) and apart from those that locate the event.
  EXPECT_EQ(sim.statistics().grazing_checks, 1);
  EXPECT_GT(sim.statistics().guard_evaluations, sim.statistics().grazing_checks);
}

TEST(SimulatorEvents, ForceCriterionNeverPullsTheFloorsTogether) {
  const Model model = make_model(testing::fig2('c'), {1, 1});
  const auto min_force = [&](SeparationCriterion criterion) {
    Simulator sim(model, testing::harmonic(model, 0.2, 0.8),
                  TimeHistoryOptions{.dt = 1e-3, .separation = criterion});
    double lowest = 0, highest = 0;
    for (int k = 1; k <= 20000; ++k) {
      sim.step();
      lowest = std::min(lowest, sim.gap_force(0));
      highest = std::max(highest, sim.gap_force(0));
    }
    // Re-contact of a relaxing element happens a hair (≤ |ṡ|·tolerance) past its free end, which
    // adds energy of first order in the event tolerance: 1e-10 s gives ~1e-11 here.
    EXPECT_LT(sim.energy_meter().max_relative_residual(), 1e-9);
    return lowest / highest;
  };
  // The paper's displacement criterion lets the dashpot pull before separation ...
  EXPECT_LT(min_force(SeparationCriterion::displacement), -0.01);
  // ... the force criterion does not (up to the event tolerance).
  EXPECT_GT(min_force(SeparationCriterion::force), -1e-6);
}

// Without the energy balance (the free frames beside a time history) the peaks, the neighbours'
// approach and the state are the same bits, with either integrator, pounding or not; the balance
// stays at its start.
TEST(SimulatorEnergy, PeaksWithoutTheBalanceAreTheSameBits) {
  for (const Integrator integrator : {Integrator::newmark, Integrator::exact}) {
    const Model model = make_model(testing::fig2('c'), {1, 1});
    const auto run = [&](bool meter) {
      Simulator sim(model, testing::harmonic(model, 0.2, 0.8), TimeHistoryOptions{.dt = 1e-3, .integrator = integrator});
      sim.meter_energy(meter);
      sim.advance_to(5.0);
      return std::tuple(sim.statistics(), Eigen::VectorXd(sim.state().u), sim.energy());
    };
    const auto [with, u_with, balance_with] = run(true);
    const auto [without, u_without, balance_without] = run(false);
    EXPECT_GT(balance_with.input, 0.0);
    EXPECT_EQ(balance_without.input, 0.0);
    EXPECT_EQ(u_with, u_without);
    testing::expect_same_peaks(with, without);
  }
}

TEST(SimulatorRecording, ATransientNotRecordedLeavesTheWindowsPeaksTheSameBits) {
  // What a brute-force frequency response does: no energy and no peaks through the transient,
  // then reset_statistics() with recording on. The state, the events and the window's peaks must
  // be those of a run that recorded everything, for both integrators; the transient's peaks are
  // not taken at all (they would describe nothing the caller keeps).
  for (const Integrator integrator : {Integrator::newmark, Integrator::exact}) {
    const Model model = make_model(testing::fig2('c'), {2, 2});
    const auto run = [&](bool record_transient) {
      Simulator sim(model, testing::harmonic(model, 0.2, 0.8), TimeHistoryOptions{.dt = 1e-3, .integrator = integrator});
      sim.meter_energy(record_transient);
      sim.record_responses(record_transient);
      sim.advance_to(3.0);
      const ResponseStatistics transient = sim.statistics();
      sim.record_responses(true);
      sim.reset_statistics();
      // The window starts with the state it starts from (recording on before the reset).
      EXPECT_EQ(sim.statistics().floors[0].displacement.value, std::abs(sim.state().u(0)));
      EXPECT_EQ(sim.statistics().floors[0].displacement.time, sim.time());
      sim.advance_to(4.5);
      return std::tuple(transient, sim.statistics(), Eigen::VectorXd(sim.state().u), Eigen::VectorXd(sim.state().v));
    };
    const auto [transient_with, with, u_with, v_with] = run(true);
    const auto [transient_without, without, u_without, v_without] = run(false);
    EXPECT_EQ(u_with, u_without);
    EXPECT_EQ(v_with, v_without);
    EXPECT_GT(transient_with.floors[0].displacement.value, 0.0);
    EXPECT_EQ(transient_without.floors[0].displacement.value, 0.0);  // not taken
    EXPECT_GT(transient_without.events, 0);                          // counted all the same
    EXPECT_EQ(transient_with.events, transient_without.events);
    testing::expect_same_peaks(with, without);
  }
}

TEST(SimulatorDeterminism, SameInputSameBits) {
  const Model model = make_model(testing::fig2('b'), {3, 3});
  const auto run = [&] {
    Simulator sim(model, testing::harmonic(model, 0.2, 1.1), TimeHistoryOptions{.dt = 1e-3});
    sim.advance_to(10.0);
    return Eigen::VectorXd(sim.state().u);
  };
  const Eigen::VectorXd a = run(), b = run();
  EXPECT_EQ(std::memcmp(a.data(), b.data(), sizeof(double) * a.size()), 0);
}

TEST(SimulatorOptions, RejectsInconsistentOptions) {
  const Model model = make_model(testing::fig2('a'), {1, 1});
  EXPECT_THROW(Simulator(model, NoExcitation{}, TimeHistoryOptions{.dt = 0.0}), std::invalid_argument);
  EXPECT_THROW(Simulator(model, NoExcitation{}, TimeHistoryOptions{.dt = 1e-3, .lock_time = 1e-10}),
               std::invalid_argument);
  InitialConditions ic;
  ic.displacement = {{0.5}, {0.0}};  // through the other frame
  EXPECT_THROW(Simulator(model, NoExcitation{}, TimeHistoryOptions{.dt = 1e-3}, ic),
               std::invalid_argument);
}


// Magnitudes beyond double range used to run to the end with NaN energies (the balance check
// dropped them) and exit 0. Each must stop with the time and the quantity that went non-finite.
TEST(SimulatorFailures, NonFiniteStatesStopTheRunNamingTimeAndQuantity) {
  const GapProperties gap{.gap = 0.01, .restitution = 0.75};
  const Model paper = two_oscillators(1.0, 200.0, 1.4, 1.0, 50.0, 0.7, gap);
  const auto message_of = [](auto&& run) -> std::string {
    try {
      run();
    } catch (const SimulationError& e) {
      return e.what();
    }
    return "no error";
  };
  // A huge ground acceleration: finite states, overflowing energies.
  const std::string huge_ground = message_of([&] {
    Simulator sim(paper, HarmonicExcitation{1e300 * 9.81, 10.0}, TimeHistoryOptions{.dt = 1e-3});
    sim.advance_to(1.0);
  });
  EXPECT_NE(huge_ground.find("is not finite"), std::string::npos) << huge_ground;
  EXPECT_NE(huge_ground.find("energy"), std::string::npos) << huge_ground;
  EXPECT_NE(huge_ground.find("at t = "), std::string::npos) << huge_ground;
  // Huge initial velocities: the kinetic energy overflows at once.
  const std::string huge_velocity = message_of([&] {
    InitialConditions ic;
    ic.velocity = {{1e300}, {-1e300}};
    Simulator sim(paper, NoExcitation{}, TimeHistoryOptions{.dt = 1e-3}, ic);
    sim.advance_to(1.0);
  });
  EXPECT_NE(huge_velocity.find("at t = 0 s the kinetic energy"), std::string::npos) << huge_velocity;
  // A stiffness near the largest double: its force overflows.
  const std::string stiff = message_of([&] {
    const Model m = two_oscillators(1.0, 1e308, 0.0, 1.0, 50.0, 0.0, gap);
    InitialConditions ic;
    ic.displacement = {{-10.0}, {0.0}};
    Simulator sim(m, NoExcitation{}, TimeHistoryOptions{.dt = 1e-3}, ic);
    sim.advance_to(1.0);
  });
  EXPECT_NE(stiff.find("at t = 0 s the acceleration of frame 1 floor 1 (inf) is not finite"), std::string::npos)
      << stiff;
}


// The loop's status: why a run stopped, at what time, with the same message the error carries.
TEST(SimulatorStatus, RunToSaysWhyItStopped) {
  const Model paper = two_oscillators(1.0, 200.0, 1.4, 1.0, 50.0, 0.7, {.gap = 0.01, .restitution = 0.75});
  Simulator fine(paper, HarmonicExcitation{0.2 * 9.81, 10.0}, TimeHistoryOptions{.dt = 1e-3});
  const SimulationStatus reached = fine.run_to(0.5);
  EXPECT_TRUE(reached.ok());
  EXPECT_EQ(reached.time, 0.5);
  EXPECT_TRUE(reached.message.empty());

  Simulator huge(paper, HarmonicExcitation{1e300 * 9.81, 10.0}, TimeHistoryOptions{.dt = 1e-3});
  const SimulationStatus overflow = huge.run_to(1.0);
  EXPECT_EQ(overflow.reason, StopReason::non_finite);
  EXPECT_EQ(overflow.time, huge.time());
  EXPECT_LT(overflow.time, 1.0);
  EXPECT_NE(overflow.message.find("is not finite"), std::string::npos) << overflow.message;
  // A failed simulation stays failed: its state is the failure's, not a solution.
  EXPECT_EQ(huge.run_to(2.0).message, overflow.message);
  try {
    huge.advance_to(2.0);
    ADD_FAILURE() << "advance_to continued after a failure";
  } catch (const SimulationError& e) {
    EXPECT_EQ(e.reason(), StopReason::non_finite);
  }
  // Nor can a frequency sweep continue from it under a new excitation.
  try {
    huge.restart(HarmonicExcitation{9.81, 5.0}, 1e-3);
    ADD_FAILURE() << "restart continued after a failure";
  } catch (const SimulationError& e) {
    EXPECT_EQ(e.reason(), StopReason::non_finite);
    EXPECT_EQ(std::string(e.what()), overflow.message);  // the failure itself, not a new one
  }

  // A stiff spring (contact π/√(k/m̄) = 2.2 ms) closes at 0.5 ms and reopens at 2.7 ms, within
  // the first step of 10 ms: two events, which the exact integrator locates in that step.
  const Model stiff = two_oscillators(1.0, 1.0, 0.0, 1.0, 1.0, 0.0,
                                      {.stiffness = 1e6, .gap = 0.001, .shortening = 0.1, .restitution = 1.0});
  InitialConditions closing;
  closing.velocity = {{1.0}, {-1.0}};
  Simulator one_event(stiff, NoExcitation{},
                      TimeHistoryOptions{.dt = 0.01, .integrator = Integrator::exact, .max_events_per_step = 1},
                      closing);
  const SimulationStatus limit = one_event.run_to(0.1);
  EXPECT_EQ(limit.reason, StopReason::event_limit);
  EXPECT_GT(limit.time, 0.0);
  EXPECT_LT(limit.time, 0.01);
  EXPECT_NE(limit.message.find("more than 1 events within one step"), std::string::npos) << limit.message;
  Simulator two_events(stiff, NoExcitation{},
                       TimeHistoryOptions{.dt = 0.01, .integrator = Integrator::exact, .max_events_per_step = 2},
                       closing);
  EXPECT_TRUE(two_events.run_to(0.1).ok());
  EXPECT_EQ(two_events.statistics().gaps[0].contacts, 1);
  EXPECT_EQ(two_events.statistics().gaps[0].separations, 1);
}

}  // namespace
}  // namespace poundsim
