// The response monitor on a prescribed motion whose peaks are known in closed form: two single-
// storey frames whose floors move as u₁ = A sin ωt and u₂ = B sin(ωt + φ). Sampled every 0.1 s
// (ωh = 0.5), the samples alone miss every peak; the cubic Hermite model of Newmark steps finds
// them to O((ωh)⁴), and bisection on a known trajectory to round-off.

#include "poundsim/integrate/response_monitor.hpp"

#include <cmath>
#include <complex>
#include <numbers>

#include <gtest/gtest.h>

#include "test_models.hpp"

namespace poundsim {
namespace {

constexpr double kA = 0.03, kB = 0.02, kOmega = 5.0, kPhase = 2.0;  // m, m, rad/s, rad
constexpr double kK1 = 4e7, kC1 = 3e5;                               // first storey of frame 1

/// The prescribed motion, as an integrator's dense output (time from `origin`).
class Harmonic final : public DenseOutput {
 public:
  double origin = 0.0;
  void state_at(double s, KinematicState& x) override {
    const double t = origin + s;
    x.t = t;
    x.ground = 0.0;
    const double phases[2] = {kOmega * t, kOmega * t + kPhase};
    const double amplitudes[2] = {kA, kB};
    for (int i = 0; i < 2; ++i) {
      x.u(i) = amplitudes[i] * std::sin(phases[i]);
      x.v(i) = amplitudes[i] * kOmega * std::cos(phases[i]);
      x.a(i) = -kOmega * kOmega * x.u(i);
    }
  }
};

ResponseMonitor monitor_of(const Model& model) {
  return ResponseMonitor(model, DofLayout(model), {LinearForm{kK1, kC1}, LinearForm{1e7, 0.0}});
}

/// Observes one period in steps of h; `dense`: bisect on the trajectory, else the Hermite model.
ResponseStatistics observe_period(bool dense) {
  const Model model = testing::two_oscillators(1e5, kK1, kC1, 1e5, 1e7, 0.0, GapProperties{.gap = 0.01});
  ResponseMonitor monitor = monitor_of(model);
  Harmonic motion;
  KinematicState a, b;
  a.resize(2);
  b.resize(2);
  const double h = 0.1;
  motion.state_at(0.0, a);
  monitor.observe(a);
  for (int k = 1; k * h <= 2 * std::numbers::pi / kOmega + h; ++k) {
    motion.state_at(k * h, b);
    if (dense) {
      monitor.observe_step(a, b, motion.origin, motion);
    } else {
      monitor.observe_step(a, b);
    }
    monitor.observe(b);
    std::swap(a, b);
  }
  return monitor.statistics();
}

TEST(ResponseMonitor, FindsThePeaksBetweenSamples) {
  // |u₁ − u₂| peaks at |A − B e^{iφ}|; k u₁ + c u̇₁ at A √(k² + c²ω²).
  const double approach = std::abs(std::complex<double>(kA) - std::polar(kB, kPhase));
  const double storey_shear = kA * std::hypot(kK1, kC1 * kOmega);
  const ResponseStatistics hermite = observe_period(false);
  const ResponseStatistics exact = observe_period(true);

  // (ωh)⁴/384 ≈ 1.6e-4 of the amplitude bounds the error of the cubic model.
  EXPECT_NEAR(hermite.floors[0].displacement.value, kA, 1.6e-4 * kA);
  EXPECT_NEAR(hermite.floors[1].displacement.value, kB, 1.6e-4 * kB);
  EXPECT_NEAR(hermite.base_shear[0].value, kK1 * kA, 1.6e-4 * kK1 * kA);
  EXPECT_NEAR(hermite.neighbours[0].max_approach, approach, 1.6e-4 * approach);
  // Samples alone would be short of the peak by up to 1 − cos(ωh/2) ≈ 3 %: the model found it.
  EXPECT_GT(hermite.floors[0].displacement.value, kA * (1 - 1e-4));

  EXPECT_NEAR(exact.floors[0].displacement.value, kA, 1e-13);
  EXPECT_NEAR(exact.floors[0].displacement.time, 0.5 * std::numbers::pi / kOmega, 1e-9);
  EXPECT_NEAR(exact.floors[1].displacement.value, kB, 1e-13);
  EXPECT_NEAR(exact.base_shear[0].value, kK1 * kA, 1e-13 * kK1 * kA);
  EXPECT_NEAR(exact.storey_shear[0].value, storey_shear, 1e-12 * storey_shear);
  EXPECT_NEAR(exact.neighbours[0].max_approach, approach, 1e-13);
  EXPECT_NEAR(exact.floors[0].velocity.value, kA * kOmega, 1e-3 * kA * kOmega);  // at samples only
}

TEST(ResponseMonitor, CountsEventsAndForgets) {
  const Model model = testing::two_oscillators(1e5, kK1, kC1, 1e5, 1e7, 0.0, GapProperties{.gap = 0.01});
  ResponseMonitor monitor = monitor_of(model);
  monitor.observe_event(0, EventKind::contact, 0.3, 0.0, 1.0);
  monitor.observe_event(0, EventKind::impact, 0.5, 120.0, 1.5);
  monitor.observe_event(0, EventKind::impact, 0.2, 80.0, 2.0);
  monitor.observe_gap(0, 2.5e5, 0.004, 1.6);
  monitor.observe_gap(0, 1.0e5, -0.001, 1.7);  // open: no shortening peak
  monitor.observe_locked(0, 0.25);
  const GapResponse& g = monitor.statistics().gaps[0];
  EXPECT_EQ(monitor.statistics().events, 3);
  EXPECT_EQ(g.contacts, 1);
  EXPECT_EQ(g.impacts, 2);
  EXPECT_EQ(g.impact_velocity.value, 0.5);
  EXPECT_EQ(g.impulse.value, 120.0);
  EXPECT_EQ(g.impulse.time, 1.5);
  EXPECT_EQ(g.force.value, 2.5e5);
  EXPECT_EQ(g.shortening.value, 0.004);
  EXPECT_EQ(g.locked_time, 0.25);
  monitor.reset();
  EXPECT_EQ(monitor.statistics().events, 0);
  EXPECT_EQ(monitor.statistics().gaps[0].impacts, 0);
  EXPECT_EQ(monitor.statistics().gaps[0].force.value, 0.0);
  EXPECT_EQ(monitor.statistics().neighbours[0].left_frame, 0);
}

}  // namespace
}  // namespace poundsim
