// Newmark's average acceleration between grid times, with events located on its sub-steps.

#include <algorithm>
#include <utility>

#include "steppers.hpp"

#include "hermite_cubic.hpp"

namespace poundsim::detail {

/// Evaluates guards on Newmark sub-steps from the start of the current step.
class NewmarkStepper::TrialEvaluator final : public GuardEvaluator {
 public:
  TrialEvaluator(NewmarkStepper& stepper, Simulator& sim) : stepper_(stepper), sim_(sim) {}
  void evaluate(double tau, GuardSample out) override {
    stepper_.trial_step(sim_, tau, false, stepper_.trial_);
    sim_.evaluate_guards(stepper_.trial_, out.value, out.rate);
    ++sim_.monitor_.counts().guard_evaluations;
  }
  void keep_trial_as_upper() override { std::swap(stepper_.trial_, stepper_.upper_); }

 private:
  NewmarkStepper& stepper_;
  Simulator& sim_;
};

NewmarkStepper::NewmarkStepper(int dofs) {
  trial_.resize(dofs);
  upper_.resize(dofs);
}

void NewmarkStepper::trial_step(Simulator& sim, double tau, bool nominal, KinematicState& out) const {
  const LinearPhase::Solver& solver = nominal ? sim.phase_->step_solver() : sim.phase_->substep_solver(tau);
  sim.newmark_.step(*sim.phase_, solver, sim.state_, tau, sim.system_.ground_acceleration(sim.state_.t + tau), out);
}

void NewmarkStepper::integrate_to(Simulator& sim, double t_end, bool nominal) {
  bool first = true;
  while (sim.state_.t < t_end) {
    const bool use_step_solver = nominal && first;
    const double tau = use_step_solver ? sim.options_.dt : t_end - sim.state_.t;
    first = false;
    trial_step(sim, tau, use_step_solver, upper_);
    upper_.t = t_end;  // exact grid time, whatever the rounding of t + τ
    sim.evaluate_guards(upper_, sim.g_hi_, sim.dg_hi_);
    if (!any_fired(sim.g_hi_) && !find_grazing(sim, tau)) {
      sim.accept(upper_);
      return;
    }
    TrialEvaluator evaluator(*this, sim);
    locate_first_event(0.0, upper_.t - sim.state_.t, {sim.g_lo_, sim.dg_lo_}, {sim.g_hi_, sim.dg_hi_},
                       {sim.g_work_, sim.dg_work_}, sim.options_.event_tolerance, evaluator);
    sim.system_.compute_stop_reactions(upper_, *sim.phase_, sim.contact_);  // trials below the event came last
    sim.accept(upper_);
    sim.apply_pending_events();
  }
}

bool NewmarkStepper::find_grazing(Simulator& sim, double tau) {
  // A guard that rises and falls inside the step without crossing at the ends: check the interior
  // maximum of its cubic Hermite model, then the Newmark sub-step there.
  const std::vector<double>&g_lo = sim.g_lo_, &g_hi = sim.g_hi_, &dg_lo = sim.dg_lo_, &dg_hi = sim.dg_hi_;
  double best_theta = 2.0;
  for (std::size_t j = 0; j < g_hi.size(); ++j) {
    // Inactive guards (−∞) have zero rates and are skipped with the others that do not rise.
    if (!(g_lo[j] <= 0 && g_hi[j] <= 0 && dg_lo[j] > 0 && dg_hi[j] < 0)) continue;
    const HermiteCubic cubic(g_lo[j], dg_lo[j], g_hi[j], dg_hi[j], tau);
    for (const double theta : cubic.critical_points()) {
      if (theta > 0 && cubic(theta) > 0 && cubic.slope(theta - 1e-9) > 0) {
        best_theta = std::min(best_theta, theta);
      }
    }
  }
  if (best_theta >= 1.0) return false;
  trial_step(sim, best_theta * tau, false, trial_);
  sim.evaluate_guards(trial_, sim.g_work_, sim.dg_work_);
  ++sim.monitor_.counts().guard_evaluations;
  if (!any_fired(sim.g_work_)) {
    sim.system_.compute_stop_reactions(upper_, *sim.phase_, sim.contact_);  // the step is accepted at upper_
    return false;
  }
  std::swap(trial_, upper_);
  sim.g_hi_ = sim.g_work_;
  sim.dg_hi_ = sim.dg_work_;
  return true;
}

}  // namespace poundsim::detail
