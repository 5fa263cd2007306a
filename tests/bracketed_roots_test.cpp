// The bracketed root searches of the exact integrator's events and of the peaks between samples:
// where they land and how many evaluations they take (each evaluation is a state of the exact
// trajectory, the costliest thing in an exact period).

#include "poundsim/integrate/bracketed_roots.hpp"

#include <cmath>
#include <limits>
#include <numbers>
#include <utility>

#include <gtest/gtest.h>

namespace poundsim::detail {
namespace {

constexpr double eps = std::numeric_limits<double>::epsilon();

/// A guard like an approach during contact: g = δ sin(ωs) e^{−ζωs} − δ/2 rising through zero.
struct ImpactPhaseGuard {
  double w = 8.9, zeta = 0.05, delta = 0.01;
  std::pair<double, double> operator()(double s) const {
    const double e = std::exp(-zeta * w * s);
    return {delta * std::sin(w * s) * e - 0.5 * delta, delta * w * e * (std::cos(w * s) - zeta * std::sin(w * s))};
  }
};

TEST(NewtonBracket, ConvexGuardConvergesFromOneSideInAFewSteps) {
  // g = s² − 2 on [1, 2]: Newton from s = 2 approaches √2 from above only, so the lower end of
  // the bracket stays at 1 until the last step — judged by the bracket's width (a plain safeguard),
  // every other step would bisect and this would take 33 evaluations.
  const double resolution = 16 * eps * 2;
  const RootBracket b = newton_bracket([](double s) { return std::pair{s * s - 2, 2 * s}; }, 1.0, 2.0, resolution);
  EXPECT_LE(b.hi - b.lo, resolution);
  EXPECT_LE(b.lo * b.lo - 2, 0.0);
  EXPECT_GT(b.hi * b.hi - 2, 0.0);
  EXPECT_LE(b.lo, std::numbers::sqrt2);
  EXPECT_GE(b.hi, std::numbers::sqrt2 - resolution);
  EXPECT_LE(b.evaluations, 8);
}

TEST(NewtonBracket, AGuardOfAnImpactPhaseToSixteenUlps) {
  // The impact-phase guard bracketed over a sampling step of a 16-per-period run at t ≈ 37 s
  // (the resolution is 16 ulps of the time, as the exact integrator asks).
  const ImpactPhaseGuard g;
  const double t0 = 37.0;
  const double resolution = 16 * eps * t0;
  const RootBracket b = newton_bracket(g, 0.0, 2 * std::numbers::pi / g.w / 16 * 2, resolution);
  EXPECT_LE(b.hi - b.lo, resolution);
  EXPECT_LE(g(b.lo).first, 0.0);
  EXPECT_GT(g(b.hi).first, 0.0);
  EXPECT_LE(b.evaluations, 8);
}

TEST(NewtonBracket, AStartNearTheRootSavesTheStepsFromTheEnd) {
  // The impact-phase guard, Newton started where the guard search's Hermite cubic puts the
  // root (within its error, here 1e-7 of the step) instead of at the upper end: the bracket
  // closes in three evaluations (two Newton steps and the probe past the converged point).
  const ImpactPhaseGuard g;
  const double t0 = 37.0;
  const double resolution = 16 * eps * t0, hi = 2 * std::numbers::pi / g.w / 16 * 2;
  const RootBracket from_end = newton_bracket(g, 0.0, hi, resolution);
  const double root = 0.5 * (from_end.lo + from_end.hi);
  const RootBracket b = newton_bracket(g, 0.0, hi, resolution, root + 1e-7 * hi);
  EXPECT_LE(b.hi - b.lo, resolution);
  EXPECT_LE(g(b.lo).first, 0.0);
  EXPECT_GT(g(b.hi).first, 0.0);
  EXPECT_LE(b.evaluations, 3);
  EXPECT_GT(from_end.evaluations, b.evaluations + 1);
}

TEST(NewtonBracket, AFlatCrossingStillClosesByBisection) {
  // g = (s − 0.3)³: the rate vanishes at the root, Newton crawls (linear convergence) and the
  // safeguard bisects; the bracket still closes, within the 60-odd halvings of its width.
  const double resolution = 16 * eps;
  const RootBracket b = newton_bracket(
      [](double s) { return std::pair{std::pow(s - 0.3, 3), 3 * std::pow(s - 0.3, 2)}; }, 0.0, 1.0, resolution);
  EXPECT_LE(b.hi - b.lo, resolution);
  EXPECT_LE(std::pow(b.lo - 0.3, 3), 0.0);
  EXPECT_GT(std::pow(b.hi - 0.3, 3), 0.0);
  EXPECT_LE(b.evaluations, 120);
}

TEST(IllinoisRoot, TheExtremumOfAFloorToTheToleranceInAFewEvaluations) {
  // u = sin(ωt + φ) peaks where u̇ = ω cos(ωt + φ) vanishes; a sampling interval of 1/16 of the
  // period around it, at t ≈ 12 s. Bisection to the same tolerance (1e-12 of the time) took 40.
  const double w = 8.9, phase = 0.3, t0 = 12.0;
  const double root = (std::numbers::pi / 2 - phase) / w;  // in time from 0
  const double a = root - 0.4 * (2 * std::numbers::pi / w / 16), b = root + 0.6 * (2 * std::numbers::pi / w / 16);
  const auto rate = [&](double s) { return w * std::cos(w * s + phase); };
  int evaluations = 0;
  const double tolerance = 1e-12 * t0;
  const double x = illinois_root(rate, a, b, rate(a), rate(b), tolerance, evaluations);
  EXPECT_NEAR(x, root, tolerance);
  EXPECT_GE(evaluations, 1);
  EXPECT_LE(evaluations, 6);
}

TEST(IllinoisRoot, AStronglyCurvedRateStillConverges) {
  // A rate that plain regula falsi creeps on (one end never moves): e^{10 s} − 2 on [0, 1]. The
  // Illinois halving moves both ends.
  const auto f = [](double s) { return std::exp(10 * s) - 2; };
  int evaluations = 0;
  const double x = illinois_root(f, 0.0, 1.0, f(0.0), f(1.0), 1e-12, evaluations);
  EXPECT_NEAR(x, std::log(2.0) / 10, 1e-12);
  EXPECT_LE(evaluations, 24);
}

TEST(IllinoisRoot, TwoCloseEstimatesFarFromTheRootDoNotStopIt) {
  // e^{50 s} − e^{25}, root 0.5: the first two estimates lie within 1e-10 of each other near 0
  // (a review found the search stopping there when two close estimates were taken as converged).
  const auto f = [](double s) { return std::exp(50 * s) - std::exp(25.0); };
  int evaluations = 0;
  const double x = illinois_root(f, 0.0, 1.0, f(0.0), f(1.0), 1e-10, evaluations);
  EXPECT_NEAR(x, 0.5, 1e-10);
  EXPECT_LE(evaluations, 10);
}

TEST(IllinoisRoot, AFlatRootIsBisectedToTheTolerance) {
  // (s − s₀)³: regula falsi crawls; the bisections when the bracket does not halve in three steps
  // still bring it to the tolerance, within four times a bisection's ~40 evaluations.
  const double root = 5e-5;
  const auto f = [&](double s) { return std::pow(s - root, 3); };
  int evaluations = 0;
  const double x = illinois_root(f, 0.0, 1.0, f(0.0), f(1.0), 1e-12, evaluations);
  EXPECT_NEAR(x, root, 1e-12);
  EXPECT_LE(evaluations, 160);
}

TEST(IllinoisRoot, ANarrowBracketIsNotEvaluated) {
  int evaluations = -1;
  const double x = illinois_root([](double s) { return s; }, -1e-14, 1e-14, -1e-14, 1e-14, 1e-12, evaluations);
  EXPECT_EQ(evaluations, 0);
  EXPECT_EQ(x, 0.0);
}

}  // namespace
}  // namespace poundsim::detail
