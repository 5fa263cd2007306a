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
/// least one fired at hi" until hi − lo ≤ tolerance. Each iteration proposes the Illinois (modified
/// regula falsi) point of the guard with the earliest estimated root, clamped half a tolerance
/// inside the bracket so that the bracket always closes, and falls back to bisection when two
/// proposals did not halve it. All guards that have fired at the final hi are simultaneous events.

#include <span>

namespace poundsim {

/// Evaluates the guards on the trajectory of the current step.
class GuardEvaluator {
 public:
  virtual ~GuardEvaluator() = default;
  /// Computes the guards at τ (0 < τ) into `g`; the state there becomes the "trial" state.
  virtual void evaluate(double tau, std::span<double> g) = 0;
  /// The last evaluated trial is the new upper end of the bracket: keep its state.
  virtual void keep_trial_as_upper() = 0;
};

struct EventBracket {
  double lo = 0.0;      ///< No guard has fired at lo.
  double hi = 0.0;      ///< At least one guard has fired at hi; its state is the last one kept.
  int evaluations = 0;  ///< Guard evaluations (Newmark sub-steps) spent.
};

/// Shrinks [lo, hi] to width ≤ tolerance. On entry g_lo ≤ 0 everywhere and some g_hi > 0; on
/// return they hold the guards at the final ends. `work` is scratch of the same size. Guards
/// equal to −∞ are inactive. Throws SimulationError if the bracket fails to close in
/// `max_iterations`.
EventBracket locate_first_event(double lo, double hi, std::span<double> g_lo,
                                std::span<double> g_hi, std::span<double> work, double tolerance,
                                GuardEvaluator& evaluator, int max_iterations = 300);

}  // namespace poundsim
