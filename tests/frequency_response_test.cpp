// Frequency responses: steady-state detection against known answers, coexisting branches,
// determinism whatever the thread count and the lanes stepped together.

#include "poundsim/analysis/frequency_response.hpp"

#include <atomic>
#include <cmath>
#include <numbers>
#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "test_models.hpp"

namespace poundsim {
namespace {

constexpr double kG = 9.81;

TEST(FreeResponse, SingleStoreyMatchesTheDynamicAmplification) {
  // V = K u with |u| = (A/ω²) / √((1 − r²)² + (2ζr)²), r = ω̄/ω.
  const double m = 2.0, k = 800.0, zeta = 0.05, w = std::sqrt(k / m);
  const Model model = make_model({make_uniform_frame(1, m, k, 2 * zeta * m * w)}, GapProperties{});
  for (const double r : {0.3, 1.0, 1.7}) {
    const FrameAmplitudes a = free_response(model, 2.0, r * w);
    const double u = (2.0 / (w * w)) / std::hypot(1 - r * r, 2 * zeta * r);
    EXPECT_NEAR(a.base_shear[0], k * u, 1e-12 * k * u);
    EXPECT_NEAR(a.top_displacement[0], u, 1e-12 * u);
    EXPECT_NEAR(a.storey_shear[0], std::hypot(k, r * w * 2 * zeta * m * w) * u, 1e-12 * k * u);
  }
}

TEST(FrequencyResponse, WithoutContactTheSteadyStateIsTheLinearOne) {
  // The Fig. 2 frames far apart: every point is periodic with period 1 and equals the closed form,
  // to Newmark's error with 128 steps per period and to round-off with the exact integrator.
  DimensionlessParameters p = testing::fig2('c');
  p.delta = 1e6;
  const Model model = make_model(p, {1, 1});
  for (const Integrator integrator : {Integrator::newmark, Integrator::exact}) {
    FrequencyResponseOptions o;
    o.amplitude = 0.2 * kG;
    o.ratios = {0.35, 0.5, 0.8, 1.0, 1.4};
    o.time_history.integrator = integrator;
    // The amplitudes are as accurate as the transient left when the sections repeat (the
    // detection tolerance) and as the integrator.
    if (integrator == Integrator::exact) {
      o.steady.steps_per_period = 16;
      o.steady.tolerance = 1e-12;
      o.steady.max_periods = 3000;
    }
    const double tolerance = integrator == Integrator::exact ? 1e-9 : 2e-3;
    for (const FrfPoint& point : frequency_response(model, o)) {
      EXPECT_EQ(point.periodicity, 1) << point.ratio;
      EXPECT_GT(point.transient_periods, 2);
      EXPECT_EQ(point.events, 0);
      for (int f = 0; f < 2; ++f) {
        EXPECT_NEAR(point.interacting.base_shear[f], point.free.base_shear[f], tolerance * point.free.base_shear[f])
            << "ratio " << point.ratio << " frame " << f + 1;
        EXPECT_NEAR(point.interacting.storey_shear[f], point.free.storey_shear[f], tolerance * point.free.storey_shear[f]);
        EXPECT_NEAR(point.interacting.top_displacement[f], point.free.top_displacement[f],
                    tolerance * point.free.top_displacement[f]);
      }
    }
  }
}

// At its default tolerance (1e-6) a frequency response's peaks are within 1e-6 of each frame's
// peak: the transient has shrunk to that, not only the sections' repetition. Fig. 2a with the
// exact integrator at the ratios where the repetition alone stopped short — a lightly damped
// transient of frame 2 sampled once a period past its resonance (1.48 … 1.6, no contact: the
// sections repeated to 1e-6 of frame 1's motion while frame 2's peak was 6e-6 off), and
// impacting orbits near resonance (0.88, 0.9) — against the same points to 1e-10.
TEST(FrequencyResponse, AtTheDefaultToleranceThePeaksAreWithinItOfEachFramesPeak) {
  const Model model = make_model(testing::fig2('a'), {1, 1});
  FrequencyResponseOptions o;
  o.amplitude = 0.2 * kG;
  o.ratios = {0.88, 0.9, 1.48, 1.5, 1.58, 1.6};
  o.time_history.integrator = Integrator::exact;
  o.steady.steps_per_period = 16;
  const std::vector<FrfPoint> defaults = frequency_response(model, o);
  o.steady.tolerance = 1e-10;
  o.steady.max_periods = 3000;
  const std::vector<FrfPoint> reference = frequency_response(model, o);
  for (std::size_t i = 0; i < o.ratios.size(); ++i) {
    SCOPED_TRACE(o.ratios[i]);
    ASSERT_EQ(defaults[i].periodicity, 1);
    ASSERT_EQ(reference[i].periodicity, 1);
    for (int f = 0; f < 2; ++f) {
      const FrameAmplitudes &a = defaults[i].interacting, &b = reference[i].interacting;
      EXPECT_NEAR(a.base_shear[f], b.base_shear[f], 1e-6 * b.base_shear[f]) << "frame " << f + 1;
      EXPECT_NEAR(a.storey_shear[f], b.storey_shear[f], 1e-6 * b.storey_shear[f]) << "frame " << f + 1;
    }
  }
}

TEST(FrequencyResponse, PeriodTwoResponseCoexistsWithTheLinearOne) {
  // Fig. 2a (elastic impacts) at ω̄/ω₁ = 1.3: from rest the frames settle on a pounding response
  // that repeats every two periods; sweeping down from 1.6, where they do not touch, they stay
  // apart and the response is the linear one, known in closed form.
  const Model model = make_model(testing::fig2('a'), {1, 1});
  const double ratio = 1.3;
  std::unique_ptr<Simulator> sim;
  const SteadyStateOptions steady;
  TimeHistoryOptions exact;
  exact.integrator = Integrator::exact;
  const FrfPoint pounding = steady_state_point(model, 0.2 * kG, ratio, steady, exact, sim);
  EXPECT_EQ(pounding.periodicity, 2);
  EXPECT_GT(pounding.impacts, 0);
  // Independent check of the period: the state returns after two periods, not after one.
  const double period = 2 * std::numbers::pi / pounding.omega;
  const Eigen::VectorXd y0 = sim->state().u;
  sim->advance_to(sim->time() + period);
  const Eigen::VectorXd y1 = sim->state().u;
  sim->advance_to(sim->time() + period);
  const Eigen::VectorXd y2 = sim->state().u;
  EXPECT_LT((y2 - y0).norm(), 1e-6 * y0.norm());
  EXPECT_GT((y1 - y0).norm(), 1e-2 * y0.norm());

  FrequencyResponseOptions down;
  down.amplitude = 0.2 * kG;
  down.ratios = {1.3, 1.4, 1.5, 1.6};
  down.sweep = SweepMode::down;
  down.time_history.integrator = Integrator::exact;
  down.steady.steps_per_period = 16;
  down.steady.tolerance = 1e-12;
  down.steady.max_periods = 3000;
  const std::vector<FrfPoint> branch = frequency_response(model, down);
  ASSERT_EQ(branch.size(), 4u);
  const FrfPoint& linear = branch.back();
  EXPECT_DOUBLE_EQ(linear.ratio, 1.3);
  EXPECT_EQ(linear.branch, SweepMode::down);
  EXPECT_EQ(linear.periodicity, 1);
  EXPECT_EQ(linear.impacts, 0);
  EXPECT_NEAR(linear.interacting.base_shear[0], linear.free.base_shear[0], 1e-9 * linear.free.base_shear[0]);
  // The two coexisting responses differ: a jump for a sweep.
  EXPECT_GT(pounding.interacting.base_shear[0], 1.05 * linear.interacting.base_shear[0]);
}

TEST(FrequencyResponse, APointsWindowIsThatOfARunRecordingEverything) {
  // steady_state_point runs the transient without peaks or energy and starts the window's peaks
  // at reset_statistics(): the window must be that of a run that recorded everything, to the bit
  // (a reset before recording is back on would drop the window's first sample).
  for (const Integrator integrator : {Integrator::newmark, Integrator::exact}) {
    const Model model = make_model(testing::fig2('a'), {1, 1});
    SteadyStateOptions steady;
    if (integrator == Integrator::exact) steady.steps_per_period = 16;
    TimeHistoryOptions options;
    options.integrator = integrator;
    std::unique_ptr<Simulator> sim;
    const FrfPoint point = steady_state_point(model, 0.2 * kG, 1.3, steady, options, sim);
    ASSERT_GT(point.impacts, 0);
    ASSERT_GT(point.periodicity, 0);
    const double period = 2 * std::numbers::pi / point.omega;
    TimeHistoryOptions o = options;
    o.dt = period / steady.steps_per_period;
    Simulator all(model, HarmonicExcitation{0.2 * kG, point.omega}, o);
    for (int m = 1; m <= point.transient_periods; ++m) all.advance_to(m * period);
    all.reset_statistics();
    all.advance_to((point.transient_periods + point.periodicity) * period);
    EXPECT_EQ(sim->state().u, all.state().u);
    testing::expect_same_peaks(all.statistics(), sim->statistics());
    const FrameAmplitudes amplitudes = run_amplitudes(all);
    EXPECT_EQ(amplitudes.base_shear, point.interacting.base_shear);
    EXPECT_EQ(amplitudes.storey_shear, point.interacting.storey_shear);
    EXPECT_EQ(amplitudes.top_displacement, point.interacting.top_displacement);
  }
}

/// The frequency response of `model` under 0.2 g at `ratios` with these threads, lanes and sweep.
std::vector<FrfPoint> response(const Model& model, const std::vector<double>& ratios, int threads, int lanes,
                               SweepMode sweep) {
  FrequencyResponseOptions o;
  o.amplitude = 0.2 * kG;
  o.ratios = ratios;
  o.threads = threads;
  o.lanes = lanes;
  o.sweep = sweep;
  return frequency_response(model, o);
}

TEST(FrequencyResponse, SameBitsWhateverTheThreadCount) {
  const Model model = make_model(testing::fig2('b'), {1, 1});
  std::vector<double> ratios;
  for (int i = 0; i < 9; ++i) ratios.push_back(0.4 + 0.1 * i);
  for (const SweepMode sweep : {SweepMode::from_rest, SweepMode::both}) {
    const auto one = response(model, ratios, 1, 8, sweep);
    for (const int threads : {2, 3}) {
      const auto other = response(model, ratios, threads, 8, sweep);
      ASSERT_EQ(one.size(), other.size());
      for (std::size_t i = 0; i < one.size(); ++i) testing::expect_same_frf_point(one[i], other[i]);
    }
  }
}

TEST(FrequencyResponse, SameBitsWhateverTheLanes) {
  // Fig. 2c over its range: points from rest one at a time (lanes = 1), or stepped together in
  // batches of 2, 3 and 8 (integrate/lockstep.hpp) on one and two threads.
  const Model model = make_model(testing::fig2('c'), {1, 1});
  std::vector<double> ratios;
  for (int i = 0; i < 15; ++i) ratios.push_back(0.2 + 0.1 * i);
  const std::vector<FrfPoint> one = response(model, ratios, 1, 1, SweepMode::from_rest);
  long impacts = 0;
  for (const FrfPoint& p : one) impacts += p.impacts;
  EXPECT_GT(impacts, 0);  // the range pounds
  for (const auto& [lanes, threads] : {std::pair{3, 1}, std::pair{8, 1}, std::pair{8, 2}, std::pair{2, 2}, std::pair{1, 2}}) {
    SCOPED_TRACE(::testing::Message() << lanes << " lanes, " << threads << " threads");
    const std::vector<FrfPoint> other = response(model, ratios, threads, lanes, SweepMode::from_rest);
    ASSERT_EQ(one.size(), other.size());
    for (std::size_t i = 0; i < one.size(); ++i) testing::expect_same_frf_point(one[i], other[i]);
  }
  FrequencyResponseOptions bad;
  bad.amplitude = 0.2 * kG;
  bad.ratios = ratios;
  for (const int lanes : {0, 9}) {
    bad.lanes = lanes;
    EXPECT_THROW(frequency_response(model, bad), std::invalid_argument);
  }
}

TEST(FrequencyResponse, AFailureOrAnInterruptEndsItAsOnePointAtATime) {
  // 1e306 g overflows the state of every point: the lowest point's error is the response's,
  // whatever the lanes and threads.
  const Model model = make_model(testing::fig2('c'), {1, 1});
  const std::vector<double> ratios{0.5, 0.8, 1.1, 1.4};
  const auto failure = [&](int lanes, int threads) -> std::string {
    FrequencyResponseOptions o;
    o.amplitude = 1e306 * kG;
    o.ratios = ratios;
    o.lanes = lanes;
    o.threads = threads;
    try {
      (void)frequency_response(model, o);
    } catch (const SimulationError& e) {
      return e.what();
    }
    return "no failure";
  };
  const std::string alone = failure(1, 1);
  EXPECT_NE(alone.find("is not finite"), std::string::npos) << alone;
  for (const auto& [lanes, threads] : {std::pair{8, 1}, std::pair{8, 2}, std::pair{3, 2}}) {
    EXPECT_EQ(failure(lanes, threads), alone) << lanes << " lanes, " << threads << " threads";
  }
  // An exception from the progress callback (Python's Ctrl-C) ends the response; only points
  // that succeeded are reported.
  struct Interrupt {};
  for (const auto& [lanes, threads] : {std::pair{1, 1}, std::pair{8, 1}, std::pair{8, 2}}) {
    FrequencyResponseOptions o;
    o.amplitude = 0.2 * kG;
    o.ratios = ratios;
    o.lanes = lanes;
    o.threads = threads;
    std::atomic<int> reports{0};
    o.progress = [&](int done, int total) {
      ++reports;
      EXPECT_EQ(total, 4);
      if (done >= 1) throw Interrupt{};
    };
    EXPECT_THROW((void)frequency_response(model, o), Interrupt);
    EXPECT_LE(reports.load(), threads);
  }
  // Threads ≤ 0 are all cores, as parallel_for takes them.
  const auto all = response(model, ratios, 0, 8, SweepMode::from_rest);
  const auto negative = response(model, ratios, -1, 8, SweepMode::from_rest);
  ASSERT_EQ(negative.size(), all.size());
  for (std::size_t i = 0; i < all.size(); ++i) testing::expect_same_frf_point(all[i], negative[i]);
}

TEST(FrequencyResponse, RejectsBadOptions) {
  const Model model = make_model(testing::fig2('a'), {1, 1});
  FrequencyResponseOptions o;
  o.amplitude = 1.0;
  EXPECT_THROW(frequency_response(model, o), std::invalid_argument);  // no ratios
  o.ratios = {-1.0};
  EXPECT_THROW(frequency_response(model, o), std::invalid_argument);
  o.ratios = {1.0};
  o.steady.steps_per_period = 4;
  EXPECT_THROW(frequency_response(model, o), std::invalid_argument);
}

}  // namespace
}  // namespace poundsim
