// The response monitor on a prescribed motion whose peaks are known in closed form: two single-
// storey frames whose floors move as u₁ = A sin ωt and u₂ = B sin(ωt + φ). Sampled every 0.1 s
// (ωh = 0.5), the samples alone miss every peak; the cubic Hermite model of Newmark steps finds
// them to O((ωh)⁴), and bisection on a known trajectory to round-off.

#include "poundsim/integrate/response_monitor.hpp"

#include <array>
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

// A floor's peak is the largest |q| at its first instant, in the order the candidates came:
// samples, and the peaks between them that the steps find. Any batching of the updates must keep
// both (these ties are what a batch that merged samples late would get wrong).

/// A state of two frames of two storeys (DOFs 0, 1: the lower floors; 2, 3: the upper ones).
KinematicState state(double t, std::array<double, 4> u, std::array<double, 4> v, std::array<double, 4> a,
                     double ground = 0.0) {
  KinematicState x;
  x.resize(4);
  x.t = t;
  x.ground = ground;
  for (int i = 0; i < 4; ++i) {
    x.u(i) = u[static_cast<std::size_t>(i)];
    x.v(i) = v[static_cast<std::size_t>(i)];
    x.a(i) = a[static_cast<std::size_t>(i)];
  }
  return x;
}

Model two_storey_frames() {
  return make_model({make_uniform_frame(2, 1e5, 4e7, 3e5, "1"), make_uniform_frame(2, 1e5, 1e7, 0.0, "2")},
                    GapProperties{.gap = 0.01});
}

TEST(ResponseMonitorPeaks, APeakBetweenSamplesTyingAnEarlierSampleKeepsTheSamplesInstant) {
  const Model model = two_storey_frames();
  const DofLayout layout(model);
  const int lower = layout.dof(0, 0), upper = layout.dof(0, 1);
  // Floor `lower` rises from 0 at 1 m/s and returns to 0 at −1 m/s over a step of 1 s: its cubic
  // Hermite model peaks at θ = 1/2 with u = h·(1/8 + 1/8) = 0.25 m, exactly.
  const auto with_lower = [&](double t, double u, double v) {
    std::array<double, 4> us{}, vs{};
    us[static_cast<std::size_t>(lower)] = u;
    vs[static_cast<std::size_t>(lower)] = v;
    us[static_cast<std::size_t>(upper)] = u;  // the drift of `upper` stays 0
    vs[static_cast<std::size_t>(upper)] = v;
    return state(t, us, vs, {});
  };
  {  // A sample of 0.25 m before the step between samples that finds 0.25 m: the sample came first.
    ResponseMonitor monitor(model, layout, {LinearForm{4e7, 3e5}, LinearForm{1e7, 0.0}});
    monitor.observe(with_lower(-1.0, 0.25, 0.0));
    const KinematicState a = with_lower(0.0, 0.0, 1.0), b = with_lower(1.0, 0.0, -1.0);
    monitor.observe(a);
    monitor.observe_step(a, b);
    monitor.observe(b);
    const Peak& peak = monitor.statistics().floors[static_cast<std::size_t>(lower)].displacement;
    EXPECT_EQ(peak.value, 0.25);
    EXPECT_EQ(peak.time, -1.0);
  }
  {  // The step's peak came first; a later sample of 0.25 m does not move it.
    ResponseMonitor monitor(model, layout, {LinearForm{4e7, 3e5}, LinearForm{1e7, 0.0}});
    const KinematicState a = with_lower(0.0, 0.0, 1.0), b = with_lower(1.0, 0.0, -1.0);
    monitor.observe(a);
    monitor.observe_step(a, b);
    monitor.observe(b);
    monitor.observe(with_lower(2.0, 0.25, 0.0));
    const Peak& peak = monitor.statistics().floors[static_cast<std::size_t>(lower)].displacement;
    EXPECT_EQ(peak.value, 0.25);
    EXPECT_EQ(peak.time, 0.5);
  }
}

TEST(ResponseMonitorPeaks, TiesKeepTheFirstSample) {
  const Model model = two_storey_frames();
  const DofLayout layout(model);
  ResponseMonitor monitor(model, layout, {LinearForm{4e7, 3e5}, LinearForm{1e7, 0.0}});
  // 20 samples: |u₀| peaks at 3 first at sample 5 and again at 6 and 17; u̇₀ at −2 first at
  // sample 12; the absolute acceleration of DOF 1 ties at 9 and 10.
  for (int k = 0; k < 20; ++k) {
    const double u0 = (k == 5 || k == 6 || k == 17) ? (k == 6 ? -3.0 : 3.0) : 1.0;
    const double v0 = (k == 12 || k == 19) ? -2.0 : 0.5;
    const double a1 = (k == 9 || k == 10) ? 4.0 : 0.0;
    monitor.observe(state(0.1 * k, {u0, 0.0, 0.0, 0.0}, {v0, 0.0, 0.0, 0.0}, {0.0, a1, 0.0, 0.0}, 1.0));
  }
  const ResponseStatistics& s = monitor.statistics();
  EXPECT_EQ(s.floors[0].displacement.value, 3.0);
  EXPECT_EQ(s.floors[0].displacement.time, 0.1 * 5);
  EXPECT_EQ(s.floors[0].velocity.value, 2.0);
  EXPECT_EQ(s.floors[0].velocity.time, 0.1 * 12);
  EXPECT_EQ(s.floors[1].absolute_acceleration.value, 5.0);
  EXPECT_EQ(s.floors[1].absolute_acceleration.time, 0.1 * 9);
  EXPECT_EQ(s.floors[1].acceleration.value, 4.0);
  EXPECT_EQ(s.floors[1].acceleration.time, 0.1 * 9);
  // The upper floor of frame 1 (DOF 2) stands still while the lower one moves: its drift is |u₀|.
  EXPECT_EQ(s.floors[2].drift.value, 3.0);
  EXPECT_EQ(s.floors[2].drift.time, 0.1 * 5);
  // reset() forgets every peak.
  monitor.observe(state(2.0, {9.0, 0.0, 0.0, 0.0}, {}, {}));
  monitor.reset();
  EXPECT_EQ(monitor.statistics().floors[0].displacement.value, 0.0);
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
