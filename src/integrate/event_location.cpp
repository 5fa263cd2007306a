#include "poundsim/integrate/event_location.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include <fmt/format.h>

#include "hermite_cubic.hpp"
#include "poundsim/error.hpp"

namespace poundsim {

bool any_fired(std::span<const double> guards) {
  return std::any_of(guards.begin(), guards.end(), [](double g) { return g > 0.0; });
}

namespace {
void copy(const GuardSample& from, GuardSample& to) {
  std::copy(from.value.begin(), from.value.end(), to.value.begin());
  std::copy(from.rate.begin(), from.rate.end(), to.rate.begin());
}
}  // namespace

EventBracket locate_first_event(double lo, double hi, GuardSample at_lo, GuardSample at_hi,
                                GuardSample work, double tolerance, GuardEvaluator& evaluator,
                                int max_iterations) {
  constexpr double inf = std::numeric_limits<double>::infinity();
  EventBracket b{lo, hi, 0};
  // Illinois weights of the two ends for a guard followed without rates; reset when it changes.
  int followed = -1;
  double weight_lo = 1.0, weight_hi = 1.0;
  int last_side = 0;  // +1: hi moved last time, −1: lo moved
  double width_two_ago = inf, width_one_ago = inf;

  for (int iteration = 0; b.hi - b.lo > tolerance; ++iteration) {
    if (iteration >= max_iterations) {
      throw SimulationError(fmt::format(
          "event location did not converge: bracket [{}, {}] s after {} iterations", b.lo, b.hi,
          iteration), StopReason::event_location);
    }
    const double width = b.hi - b.lo;

    // The fired guard predicted to cross first, and where.
    int chosen = -1;
    double earliest = inf;
    for (std::size_t j = 0; j < at_hi.value.size(); ++j) {
      const double g0 = at_lo.value[j], g1 = at_hi.value[j];
      if (!(g1 > 0.0) || !std::isfinite(g0)) continue;
      double theta = std::numeric_limits<double>::quiet_NaN();
      const double d0 = at_lo.rate[j], d1 = at_hi.rate[j];
      if (std::isfinite(d0) && std::isfinite(d1)) {
        theta = detail::HermiteCubic(g0, d0, g1, d1, width).first_upward_root();
      }
      if (std::isnan(theta)) {
        const double w0 = static_cast<int>(j) == followed ? weight_lo : 1.0;
        const double w1 = static_cast<int>(j) == followed ? weight_hi : 1.0;
        theta = -w0 * g0 / (w1 * g1 - w0 * g0);
      }
      if (theta < earliest) {
        earliest = theta;
        chosen = static_cast<int>(j);
      }
    }
    if (chosen != followed) {
      followed = chosen;
      weight_lo = weight_hi = 1.0;
    }

    const double margin = 0.5 * tolerance;
    double tau;
    if (chosen < 0 || width > 0.5 * width_two_ago) {
      tau = 0.5 * (b.lo + b.hi);  // no usable prediction, or slow progress: bisect
      width_two_ago = width_one_ago = inf;
    } else {
      // Step just past the prediction towards the end that has not moved, so that an accurate
      // prediction lands on the other side of the root and closes the bracket.
      tau = b.lo + earliest * width - 0.98 * margin * last_side;
    }
    tau = std::clamp(tau, b.lo + margin, b.hi - margin);

    evaluator.evaluate(tau, work);
    ++b.evaluations;
    width_two_ago = width_one_ago;
    width_one_ago = width;
    if (any_fired(work.value)) {
      b.hi = tau;
      copy(work, at_hi);
      evaluator.keep_trial_as_upper();
      weight_hi = 1.0;
      if (last_side == +1) weight_lo *= 0.5;  // lo is stale: Illinois halves its value
      last_side = +1;
    } else {
      b.lo = tau;
      copy(work, at_lo);
      weight_lo = 1.0;
      if (last_side == -1) weight_hi *= 0.5;
      last_side = -1;
    }
  }
  return b;
}

}  // namespace poundsim
