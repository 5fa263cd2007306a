#pragma once
/// @file
/// Location of the first event inside a step.
///
/// An event is announced by a guard function g(τ) of the time τ since the start of the step that
/// becomes strictly positive (a zero does not fire, so an event lying exactly on the start fires
/// once, never twice). Guards are evaluated on the integrator's own trajectory: g(τ) is the guard
/// at the end of a Newmark sub-step of length τ from the start of the step, so at the located time
/// the state is a true Newmark state.
///
/// locate_first_event() shrinks a bracket [lo, hi] with the invariant "no guard fired at lo, at
/// least one fired at hi" until hi − lo ≤ tolerance. Each iteration predicts the root of the fired
/// guard that crosses first — from the cubic Hermite model of its values and rates at both ends
/// where the rate is known, else by Illinois (modified regula falsi) — and proposes a point half a
/// tolerance past the prediction on the side that has not moved, so that an accurate prediction
/// closes the bracket in two evaluations. Proposals stay half a tolerance inside the bracket, and
/// bisection takes over when two proposals did not halve it, so the bracket always closes. All
/// guards that have fired at the final hi are simultaneous events.

#include <span>

namespace poundsim {

/// Guard values and their rates dg/dτ (NaN where unknown) at one point.
struct GuardSample {
  std::span<double> value;
  std::span<double> rate;
};

/// True when some guard has fired (is strictly positive).
[[nodiscard]] bool any_fired(std::span<const double> guards);

/// Evaluates the guards on the trajectory of the current step.
class GuardEvaluator {
 public:
  virtual ~GuardEvaluator() = default;
  /// Computes the guards and their rates at τ (0 < τ); the state there becomes the "trial".
  virtual void evaluate(double tau, GuardSample out) = 0;
  /// The last evaluated trial is the new upper end of the bracket: keep its state.
  virtual void keep_trial_as_upper() = 0;
};

struct EventBracket {
  double lo = 0.0;      ///< No guard has fired at lo.
  double hi = 0.0;      ///< At least one guard has fired at hi; its state is the last one kept.
  int evaluations = 0;  ///< Guard evaluations (Newmark sub-steps) spent.
};

/// Shrinks [lo, hi] to width ≤ tolerance. On entry every value at lo is ≤ 0 and some value at hi
/// is > 0; on return `at_lo` and `at_hi` hold the guards at the final ends. `work` is scratch of
/// the same size. Guards equal to −∞ are inactive. Throws SimulationError if the bracket fails to
/// close in `max_iterations`.
EventBracket locate_first_event(double lo, double hi, GuardSample at_lo, GuardSample at_hi,
                                GuardSample work, double tolerance, GuardEvaluator& evaluator,
                                int max_iterations = 300);

}  // namespace poundsim
