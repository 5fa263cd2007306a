#pragma once
/// @file
/// Roots of a scalar function of time inside a bracket where it changes sign: where a guard of the
/// exact integrator crosses zero (guard_expansion.cpp) and where a response's rate vanishes
/// between two samples, its extremum (response_monitor.cpp). Bisection-like searches take ~34
/// and ~40 evaluations of the trajectory there; these safeguarded methods take ~8 and ~7 on the
/// same searches (Fig. 3a by continuation), each evaluation the costliest thing in an exact
/// period.
///
/// References: W. H. Press et al., Numerical Recipes, 3rd ed. (2007), §9.4 "rtsafe" (Newton with
/// bisection when a step leaves the bracket or does not halve); M. Dowell and P. Jarratt, "A
/// modified regula falsi method for computing the root of an equation", BIT 11 (1971) 168–174
/// (the Illinois method).

#include <algorithm>
#include <cmath>
#include <limits>

namespace poundsim::detail {

/// A bracket [lo, hi] of a root, and the evaluations it took.
struct RootBracket {
  double lo = 0.0, hi = 0.0;
  int evaluations = 0;
};

/// Shrinks [lo, hi], with g(lo) ≤ 0 < g(hi), to width ≤ resolution keeping g(lo) ≤ 0 < g(hi).
/// `value_and_rate(s)` returns {g(s), g′(s)}. Newton steps from hi, kept inside the bracket; a
/// bisection instead when a step would leave it or is longer than half the step before the last
/// (rtsafe). A Newton sequence closing in on the root from one side leaves that end of the
/// bracket where it was, so the bracket's width is no measure of progress: judged by it, every
/// other step bisected. A converged Newton point is followed by a step of half the resolution
/// past it, which lands on the other side of the root and closes the bracket. At most 200
/// evaluations (a bisection from 2⁶⁰ resolutions wide needs 60).
///
/// `start`, when inside (lo, hi), is the first point instead of hi: a model's root (the guard
/// search's Hermite cubic, within its h⁴ error of the root) saves Newton the steps from hi.
template <class ValueAndRate>
RootBracket newton_bracket(ValueAndRate&& value_and_rate, double lo, double hi, double resolution,
                           double start = std::numeric_limits<double>::quiet_NaN()) {
  RootBracket out{lo, hi, 0};
  double x = start > lo && start < hi ? start : hi;
  double last_step = hi - lo, step_before_last = hi - lo;
  while (out.evaluations < 200 && out.hi - out.lo > resolution) {
    const auto [g, d] = value_and_rate(x);
    ++out.evaluations;
    if (g > 0) {
      out.hi = x;
    } else {
      out.lo = x;
    }
    if (out.hi - out.lo <= resolution) break;
    const double mid = 0.5 * (out.lo + out.hi);
    double next = d != 0 ? x - g / d : mid;
    if (!(next > out.lo && next < out.hi) || std::abs(next - x) > 0.5 * std::abs(step_before_last)) next = mid;
    step_before_last = last_step;
    last_step = next - x;
    if (std::abs(next - x) < 0.5 * resolution) next = g > 0 ? x - 0.5 * resolution : x + 0.5 * resolution;
    x = std::clamp(next, out.lo + 0.25 * resolution, out.hi - 0.25 * resolution);
  }
  return out;
}

/// Where f vanishes in (a, b), given fa = f(a) and fb = f(b) of opposite signs, to `tolerance`:
/// regula falsi with the Illinois modification (an end that stays put twice running has its value
/// halved, so both ends close in; superlinear, order ≈ 1.44). Two safeguards:
/// - when an estimate is within half the tolerance of the one before, it is taken as converged and
///   the next point is half a tolerance past it, towards the end that stayed put: a converged
///   estimate then closes the bracket; one that was not (on a strongly curved f two estimates can
///   sit side by side far from the root: e^{50s} − e^{25} on [0, 1] had two within 1e-10 at
///   3e-11, the root at 0.5) only moves that end;
/// - a bisection when the bracket has not halved in three steps (a flat root, (s − s₀)³, makes
///   regula falsi crawl), so that no search takes more than four times a bisection's evaluations.
/// Stops when the bracket is at most `tolerance` wide, f is exactly zero, or after 200
/// evaluations. Returns the last point evaluated — within `tolerance` of the root unless the 200
/// ran out — or the midpoint when none was (a bracket already that narrow); `evaluations` counts
/// the calls of f.
template <class Value>
double illinois_root(Value&& f, double a, double b, double fa, double fb, double tolerance, int& evaluations) {
  constexpr double nan = std::numeric_limits<double>::quiet_NaN();
  evaluations = 0;
  double x = 0.5 * (a + b), last = nan;
  int kept = 0;  // which end stayed put at the last step: −1 a, +1 b
  double reference = b - a;  // the width the bracket must halve from
  int steps_since_halved = 0;
  while (evaluations < 200 && b - a > tolerance) {
    if (steps_since_halved >= 3) {
      x = 0.5 * (a + b);
      last = nan;
    } else {
      x = (a * fb - b * fa) / (fb - fa);
      if (!(x > a && x < b)) x = 0.5 * (a + b);
      if (std::abs(x - last) <= 0.5 * tolerance) {
        x = std::clamp(kept == 1 ? x + 0.5 * tolerance : x - 0.5 * tolerance, a + 0.25 * tolerance,
                       b - 0.25 * tolerance);
      }
    }
    const double fx = f(x);
    ++evaluations;
    if (fx == 0) break;
    last = x;
    if ((fx > 0) == (fa > 0)) {
      a = x;
      fa = fx;
      if (kept == 1) fb *= 0.5;
      kept = 1;
    } else {
      b = x;
      fb = fx;
      if (kept == -1) fa *= 0.5;
      kept = -1;
    }
    if (b - a <= 0.5 * reference) {
      reference = b - a;
      steps_since_halved = 0;
    } else {
      ++steps_since_halved;
    }
  }
  return x;
}

}  // namespace poundsim::detail
