// Exact guard functions and the proven search for their first crossing.

#include "poundsim/integrate/guard_expansion.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

#include <gtest/gtest.h>

#include "../src/integrate/hermite_cubic.hpp"

#include "poundsim/integrate/simulator.hpp"
#include "test_models.hpp"

namespace poundsim {
namespace {

using testing::two_oscillators;

TimeHistoryOptions exact_options(double dt) {
  return TimeHistoryOptions{.dt = dt, .integrator = Integrator::exact};
}

TEST(GuardExpansion, FirstContactTimeToMachinePrecision) {
  // u₁ = (V/ω) sin ωt reaches δ at asin(δω/V)/ω, here 0.0347 s.
  const double k = 200.0, V = 0.3, delta = 0.01, w = std::sqrt(k);
  const double exact = std::asin(delta * w / V) / w;
  const Model model =
      two_oscillators(1.0, k, 0.0, 1.0, 50.0, 0.0, GapProperties{.gap = delta, .restitution = 0.5});
  InitialConditions ic;
  ic.velocity = {{V}, {0.0}};
  Simulator sim(model, NoExcitation{}, exact_options(0.1), ic);
  double first = -1;
  sim.set_event_handler([&](const Event& e) {
    if (first < 0) first = e.time;
  });
  sim.advance_to(0.1);
  // Near machine precision: the event is taken where the guard clears its own round-off.
  EXPECT_NEAR(first, exact, 1e-14);
  EXPECT_GE(first, exact);
}

TEST(GuardExpansion, TheHermiteModelsRateIsWithinItsBound) {
  // The guard search proves a single crossing by g' ≥ min p' − (2/81) h³ max|g⁗| (p the cubic
  // Hermite model; guard_expansion.cpp): g' − p' vanishes at both ends and once between, so
  // |g' − p'| ≤ max|g⁗| max|s(s − c)(s − h)|/6 ≤ (2/81) h³ max|g⁗|. Checked on decaying
  // oscillations of every rate against the step, and the least rate of the model against a dense
  // sampling of it.
  for (const double rate : {0.3, 1.0, 4.0, 12.0, 40.0}) {
    for (const double decay : {0.0, 0.05, 0.5}) {
      const double h = 0.25, a = 0.37;
      const auto g = [&](double s) { return std::exp(-decay * rate * s) * std::sin(rate * s); };
      const auto dg = [&](double s) {
        return std::exp(-decay * rate * s) * rate * (std::cos(rate * s) - decay * std::sin(rate * s));
      };
      // |d⁴/ds⁴ e^{λs}| = |λ|⁴ e^{Re λ s}, λ = rate(−decay ± i): bounds the imaginary part.
      const double fourth = std::pow(rate * std::hypot(1.0, decay), 4) * std::exp(-decay * rate * a);
      const detail::HermiteCubic p(g(a), dg(a), g(a + h), dg(a + h), h);
      double worst = 0, least = std::numeric_limits<double>::infinity(), largest = 0;
      for (int i = 0; i <= 2000; ++i) {
        const double theta = i / 2000.0;
        worst = std::max(worst, std::abs(dg(a + theta * h) - p.slope(theta) / h));
        least = std::min(least, p.slope(theta));
        largest = std::max(largest, std::abs(p.slope(theta)));
      }
      EXPECT_LE(worst, (2.0 / 81.0) * h * h * h * fourth) << rate << " " << decay;
      // The sampling misses the vertex by at most a quadratic's change over half a sample.
      EXPECT_LE(p.least_slope(), least) << rate << " " << decay;
      EXPECT_GE(p.least_slope(), least - 1e-5 * largest) << rate << " " << decay;
    }
  }
}

TEST(GuardExpansion, GrazingContactsAreProvenOrFound) {
  // Amplitude (1 ± 1e-7) δ: beyond δ for ~60 µs inside a 0.1 s sampling interval, or never.
  const double k = 200.0, w = std::sqrt(k), delta = 0.01;
  for (const double excess : {1e-7, -1e-7}) {
    const Model model = two_oscillators(1.0, k, 0.0, 1.0, 50.0, 0.0,
                                        GapProperties{.gap = delta, .restitution = 1.0});
    InitialConditions ic;
    ic.velocity = {{(1 + excess) * delta * w}, {0.0}};
    Simulator sim(model, NoExcitation{}, exact_options(0.1), ic);
    std::vector<Event> events;
    sim.set_event_handler([&](const Event& e) { events.push_back(e); });
    sim.advance_to(0.2);
    if (excess > 0) {
      ASSERT_EQ(events.size(), 1u);
      // The peak is at t = π/(2ω); the impact a hair before it, at closing velocity ≈ ω δ √(2e).
      EXPECT_NEAR(events[0].time, std::numbers::pi / (2 * w), 1e-3);
      EXPECT_NEAR(events[0].rate_before, w * delta * std::sqrt(2 * excess), 1e-3 * w * delta * std::sqrt(2 * excess));
    } else {
      EXPECT_TRUE(events.empty());
    }
  }
}

TEST(GuardExpansion, ExactAndFineNewmarkAgreeOnThreeStoreyFrames) {
  // Three gap elements, contacts at several floors: the exact run and a fine Newmark run see the
  // same events and end in the same state to Newmark's error.
  const Model model = make_model(testing::fig2('c'), {3, 3});
  Simulator exact(model, testing::harmonic(model, 0.2, 1.1), exact_options(1e-3));
  Simulator newmark(model, testing::harmonic(model, 0.2, 1.1), TimeHistoryOptions{.dt = 1e-4});
  exact.advance_to(5.0);
  newmark.advance_to(5.0);
  EXPECT_EQ(exact.statistics().events, newmark.statistics().events);
  EXPECT_NEAR((exact.state().u - newmark.state().u).norm(), 0.0, 1e-4 * exact.state().u.norm());
}

TEST(GuardExpansion, ExactRunsConserveEnergyThroughImpactsAndLocks) {
  // Elastic impacts: energy conserved to round-off.
  const Model elastic =
      two_oscillators(1.0, 200.0, 0.0, 1.5, 60.0, 0.0, GapProperties{.gap = 0.01, .restitution = 1.0});
  InitialConditions ic;
  ic.velocity = {{0.5}, {-0.2}};
  Simulator sim(elastic, NoExcitation{}, exact_options(1e-2), ic);
  sim.advance_to(10.0);
  const EnergyBalance& b = sim.energy();
  EXPECT_GT(sim.statistics().gaps[0].impacts, 20);
  EXPECT_NEAR(b.kinetic + b.storey_strain, b.initial, 1e-13 * b.initial);

  // Pressed frames lock and reach the static contact.
  const Model pressed =
      two_oscillators(1, 25, 1, 1, 400, 4, GapProperties{.gap = 0.02, .restitution = 0.5});
  Simulator lock(pressed, RecordExcitation{{0.0, 1000.0}, {-2.0, -2.0}, "constant"}, exact_options(1e-2));
  lock.advance_to(40.0);
  EXPECT_EQ(PaperGap::gap_mode(lock.configuration()[0]), GapMode::locked);
  const double u2 = (2 * 2.0 - 25 * 0.02) / 425;
  EXPECT_NEAR(lock.state().u(1), u2, 1e-9);
  EXPECT_NEAR(lock.gap_force(0), 400 * u2 - 2.0, 1e-7);
  EXPECT_LT(lock.energy_meter().max_relative_residual(), 1e-12);
}

TEST(GuardExpansion, PaperSystemsRunExactly) {
  for (const char panel : {'a', 'b'}) {
    const Model model = make_model(testing::fig4(panel), {1, 3});
    Simulator sim(model, testing::harmonic(model, 0.2, 0.7), exact_options(1e-3));
    sim.advance_to(20.0);
    EXPECT_GT(sim.statistics().events, 10);
    EXPECT_LT(sim.energy_meter().max_relative_residual(), 1e-12) << panel;
  }
  const Model model = make_model(testing::fig2('c'), {1, 1});
  Simulator sim(model, testing::harmonic(model, 0.2, 0.8),
                TimeHistoryOptions{.dt = 1e-3, .separation = SeparationCriterion::force,
                                   .integrator = Integrator::exact});
  sim.advance_to(20.0);
  EXPECT_LT(sim.energy_meter().max_relative_residual(), 1e-12);  // exact re-contact: no hair
}

}  // namespace
}  // namespace poundsim
