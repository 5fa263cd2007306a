// Newmark's average acceleration between grid times, with events located on its sub-steps.

#include <algorithm>
#include <utility>

#include "steppers.hpp"

#include "hermite_cubic.hpp"

#include <fmt/format.h>

#include "poundsim/error.hpp"

namespace poundsim::detail {

/// Evaluates guards on Newmark sub-steps from the start of the current step.
class NewmarkStepper::TrialEvaluator final : public GuardEvaluator {
 public:
  TrialEvaluator(NewmarkStepper& stepper, Loop& loop) : stepper_(stepper), loop_(loop) {}
  void evaluate(double tau, GuardSample out) override {
    stepper_.trial_step(loop_, tau, false, stepper_.trial_);
    loop_.evaluate_guards(stepper_.trial_, out.value, out.rate);
    ++loop_.monitor().counts().guard_evaluations;
  }
  void keep_trial_as_upper() override { swap(stepper_.trial_, stepper_.upper_); }

 private:
  NewmarkStepper& stepper_;
  Loop& loop_;
};

NewmarkStepper::NewmarkStepper(int dofs, int tracked_links)
    : newmark_(dofs), smooth_(static_cast<std::size_t>(tracked_links)) {
  trial_.resize(dofs);
  upper_.resize(dofs);
}

namespace {
/// The system's smooth forces at Newton's iterates, with the loop's contact state.
class SystemSmoothForces final : public SmoothForces {
 public:
  explicit SystemSmoothForces(const Loop& loop) : loop_(loop) {}
  void evaluate(const KinematicState& x, std::span<ForceTangent> by_element) override {
    loop_.system().smooth_forces(x, loop_.contact(), by_element);
  }

 private:
  const Loop& loop_;
};

/// What a step's guards say at a glance, in one pass: whether one fired at the end (any_fired),
/// and whether one may rise and fall inside the step without crossing at the ends (the guards
/// find_grazing examines). Most steps have neither.
struct GuardScan {
  bool fired = false;
  bool may_graze = false;
};
GuardScan scan_guards(const Loop::Guards& g) {
  bool fired = false, may_graze = false;
  const std::size_t count = g.hi.size();
  const double *lo = g.lo.data(), *hi = g.hi.data(), *rate_lo = g.rate_lo.data(), *rate_hi = g.rate_hi.data();
  for (std::size_t j = 0; j < count; ++j) {
    fired |= hi[j] > 0.0;
    may_graze |= detail::may_graze(lo[j], hi[j], rate_lo[j], rate_hi[j]);
  }
  return {fired, may_graze};
}

/// Why a Newton step failed, naming the element to blame when there is one.
std::string newton_failure_message(const Loop& loop, double tau, const NewtonOutcome& outcome) {
  const auto& links = loop.system().tracked_links();
  const auto worst = static_cast<std::size_t>(outcome.worst_element);
  std::string blame = "no smooth link was found to blame";
  if (outcome.worst_element >= 0 && worst < links.size()) {
    const std::string name = describe(links[worst], loop.system().layout());
    blame = outcome.worst_not_finite ? fmt::format("the force of {} is not finite (NaN or infinite): its law's "
                                                   "parameters or the state it reached are outside its range",
                                                   name)
                                     : fmt::format("the force of {} changed most in the last one", name);
  }
  return fmt::format("Newton's iterations did not converge within {} iterations in the step from t = {} s to {} s; "
                     "{}. A smaller dt, or a larger newton_max_iterations or newton_tolerance, may help",
                     outcome.iterations, loop.state().t, loop.state().t + tau, blame);
}
}  // namespace

void NewmarkStepper::trial_step(Loop& loop, double tau, bool nominal, KinematicState& out) {
  const LinearPhase& phase = loop.phase();
  const double ground_end = loop.system().ground_acceleration(loop.state().t + tau);
  if (!phase.has_smooth_links()) {
    const LinearPhase::Solver& solver = nominal ? phase.step_solver() : phase.substep_solver(tau);
    newmark_.step(phase, solver, loop.state(), tau, ground_end, out);
    return;
  }
  SystemSmoothForces forces(loop);
  const NewtonOutcome outcome =
      newmark_.step_newton(phase, loop.state(), tau, ground_end, forces, smooth_, loop.options().newton(), out);
  ResponseStatistics& counts = loop.monitor().counts();
  ++counts.newton_steps;
  counts.newton_iterations += outcome.iterations;
  if (!outcome.converged) {
    throw SimulationError(newton_failure_message(loop, tau, outcome), StopReason::no_convergence);
  }
}

void NewmarkStepper::integrate_to(Loop& loop, double t_end, bool nominal) {
  Loop::Guards& g = loop.guards();
  bool first = true;
  while (loop.state().t < t_end) {
    const bool use_step_solver = nominal && first;
    const double tau = use_step_solver ? loop.options().dt : t_end - loop.state().t;
    first = false;
    trial_step(loop, tau, use_step_solver, upper_);
    upper_.t = t_end;  // exact grid time, whatever the rounding of t + τ
    loop.evaluate_guards(upper_, g.hi, g.rate_hi);
    const GuardScan scan = scan_guards(g);
    if (!scan.fired && !(scan.may_graze && find_grazing(loop, tau))) {
      loop.accept(upper_);
      return;
    }
    TrialEvaluator evaluator(*this, loop);
    locate_first_event(0.0, upper_.t - loop.state().t, {g.lo, g.rate_lo}, {g.hi, g.rate_hi},
                       {g.work, g.rate_work}, loop.options().event_tolerance, evaluator);
    loop.compute_stop_reactions(upper_);  // trials below the event came last
    loop.accept(upper_);
    loop.apply_pending_events();
  }
}

bool NewmarkStepper::find_grazing(Loop& loop, double tau) {
  // A guard that rises and falls inside the step without crossing at the ends: check the interior
  // maximum of its cubic Hermite model, then the Newmark sub-step there.
  Loop::Guards& g = loop.guards();
  double best_theta = 2.0;
  for (std::size_t j = 0; j < g.hi.size(); ++j) {
    // Inactive guards (−∞) have zero rates and are skipped with the others that do not rise.
    if (!may_graze(g.lo[j], g.hi[j], g.rate_lo[j], g.rate_hi[j])) continue;
    const HermiteCubic cubic(g.lo[j], g.rate_lo[j], g.hi[j], g.rate_hi[j], tau);
    for (const double theta : cubic.critical_points()) {
      if (theta > 0 && cubic(theta) > 0 && cubic.slope(theta - 1e-9) > 0) {
        best_theta = std::min(best_theta, theta);
      }
    }
  }
  if (best_theta >= 1.0) return false;
  trial_step(loop, best_theta * tau, false, trial_);
  loop.evaluate_guards(trial_, g.work, g.rate_work);
  ++loop.monitor().counts().guard_evaluations;
  ++loop.monitor().counts().grazing_checks;
  if (!any_fired(g.work)) {
    loop.compute_stop_reactions(upper_);  // the step is accepted at upper_, not at this trial
    return false;
  }
  swap(trial_, upper_);
  g.hi = g.work;
  g.rate_hi = g.rate_work;
  return true;
}

}  // namespace poundsim::detail
