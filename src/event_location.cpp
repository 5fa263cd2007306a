#include "poundsim/event_location.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include <fmt/format.h>

#include "poundsim/error.hpp"

namespace poundsim {

namespace {
bool any_fired(std::span<const double> g) {
  return std::any_of(g.begin(), g.end(), [](double x) { return x > 0.0; });
}
}  // namespace

EventBracket locate_first_event(double lo, double hi, std::span<double> g_lo,
                                std::span<double> g_hi, std::span<double> work, double tolerance,
                                GuardEvaluator& evaluator, int max_iterations) {
  EventBracket b{lo, hi, 0};
  // Illinois weights of the two ends for the guard being followed; reset when it changes.
  int followed = -1;
  double weight_lo = 1.0, weight_hi = 1.0;
  int last_side = 0;  // +1: hi moved last time, −1: lo moved
  double width_two_ago = std::numeric_limits<double>::infinity();
  double width_one_ago = std::numeric_limits<double>::infinity();

  for (int iteration = 0; b.hi - b.lo > tolerance; ++iteration) {
    if (iteration >= max_iterations) {
      throw SimulationError(fmt::format(
          "event location did not converge: bracket [{}, {}] s after {} iterations", b.lo, b.hi,
          iteration));
    }
    const double width = b.hi - b.lo;

    // The fired guard whose linear root estimate is earliest.
    int chosen = -1;
    double earliest = std::numeric_limits<double>::infinity();
    for (std::size_t j = 0; j < g_hi.size(); ++j) {
      if (!(g_hi[j] > 0.0) || !std::isfinite(g_lo[j])) continue;
      const double estimate = -g_lo[j] / (g_hi[j] - g_lo[j]);
      if (estimate < earliest) {
        earliest = estimate;
        chosen = static_cast<int>(j);
      }
    }
    if (chosen != followed) {
      followed = chosen;
      weight_lo = weight_hi = 1.0;
    }

    double tau;
    if (chosen < 0 || width > 0.5 * width_two_ago) {
      tau = 0.5 * (b.lo + b.hi);  // no usable guard, or slow progress: bisect
      width_two_ago = std::numeric_limits<double>::infinity();
      width_one_ago = std::numeric_limits<double>::infinity();
    } else {
      const double glo = weight_lo * g_lo[chosen], ghi = weight_hi * g_hi[chosen];
      tau = b.lo + width * (-glo / (ghi - glo));
    }
    const double margin = 0.5 * tolerance;
    tau = std::clamp(tau, b.lo + margin, b.hi - margin);

    evaluator.evaluate(tau, work);
    ++b.evaluations;
    width_two_ago = width_one_ago;
    width_one_ago = width;
    if (any_fired(work)) {
      b.hi = tau;
      std::copy(work.begin(), work.end(), g_hi.begin());
      evaluator.keep_trial_as_upper();
      weight_hi = 1.0;
      if (last_side == +1) weight_lo *= 0.5;  // lo is stale: Illinois halves its value
      last_side = +1;
    } else {
      b.lo = tau;
      std::copy(work.begin(), work.end(), g_lo.begin());
      weight_lo = 1.0;
      if (last_side == -1) weight_hi *= 0.5;
      last_side = -1;
    }
  }
  return b;
}

}  // namespace poundsim
