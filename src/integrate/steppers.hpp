#pragma once
// The two integrators between grid times behind one interface (integrate/integrator.hpp says
// which laws each supports). The system (dynamics/system.hpp) answers for the guards and the
// events; the loop (detail::Loop, simulator.hpp) keeps the state, the phase of each contact
// configuration and the monitors, and asks its stepper to advance to the next grid time. A
// stepper sees the loop's interface only: the states it reaches go to Loop::accept, the guards
// that fired to Loop::apply_pending_events.

#include <map>
#include <memory>
#include <vector>

#include <Eigen/Core>

#include "poundsim/integrate/exact_energy.hpp"
#include "poundsim/integrate/exact_phase.hpp"
#include "poundsim/integrate/guard_expansion.hpp"
#include "poundsim/integrate/newmark.hpp"
#include "poundsim/integrate/simulator.hpp"

namespace poundsim::detail {

/// A guard that may rise and fall inside a Newmark step without crossing at its ends: not above
/// zero at either end, rising at the start and falling at the end. Only such guards need
/// NewmarkStepper's grazing check (its cubic model's interior maximum); the lockstep kernel
/// refuses a lane's step for the same reason. Bitwise &: no branch, so a pass over guards or lanes
/// vectorises.
[[gnu::always_inline]] inline bool may_graze(double lo, double hi, double rate_lo, double rate_hi) {
  return (lo <= 0) & (hi <= 0) & (rate_lo > 0) & (rate_hi < 0);
}

class Stepper {
 public:
  virtual ~Stepper() = default;
  /// Advances `loop` from its state to t_end, applying the events on the way. `nominal`: a whole
  /// grid step of dt (Newmark's factorised step solver applies).
  virtual void integrate_to(Loop& loop, double t_end, bool nominal) = 0;
  /// The current phase changed (an event, or a restart): what was built on the old one is void.
  virtual void phase_changed() {}
  /// The simulator dropped its phases (a new step, or a full cache): forget what refers to them.
  virtual void phases_cleared() {}
  /// The loop's tangent flow was (re)started at its current state: a segment under way carries it
  /// from here, the state's bits untouched.
  virtual void tangent_restarted(Loop& /*loop*/) {}
};

/// Newmark's average acceleration: a trial step to t_end; when a guard fired (or grazes inside
/// the step), the first event is located on Newmark sub-steps to event_tolerance.
class NewmarkStepper final : public Stepper {
 public:
  NewmarkStepper(int dofs, int tracked_links);
  void integrate_to(Loop& loop, double t_end, bool nominal) override;

 private:
  class TrialEvaluator;
  void trial_step(Loop& loop, double tau, bool nominal, KinematicState& out);
  /// A guard that rises and falls inside the step without crossing at the ends fires inside:
  /// makes `upper_` that trial (and returns true), so the event is located below it.
  bool find_grazing(Loop& loop, double tau);

  NewmarkIntegrator newmark_;
  KinematicState trial_, upper_;
  std::vector<ForceTangent> smooth_;  ///< The smooth laws' forces at Newton's iterates, by element.
};

/// The closed-form solution of each phase (exact_phase.hpp) from segment to segment; events are
/// proven first roots of the guards' exact expansions (guard_expansion.hpp).
class ExactStepper final : public Stepper {
 public:
  ExactStepper(int dofs, int tracked_links);
  void integrate_to(Loop& loop, double t_end, bool nominal) override;
  void phase_changed() override { segment_valid_ = false; }
  void tangent_restarted(Loop& loop) override;
  void phases_cleared() override {
    phases_.clear();
    segment_powers_ = nullptr;
    segment_guard_rows_ = nullptr;
  }

 private:
  struct PhaseData {
    std::unique_ptr<ExactPhase> phase;
    GuardRows guard_rows;  ///< R: guards as affine functions of the phase state
    std::unique_ptr<ExactPowerIntegrals> powers;  ///< closed-form energy integrals (modal phases)
  };
  /// The trajectory of the current segment as dense output for the response monitor.
  class Output final : public DenseOutput {
   public:
    Output(ExactStepper& stepper, Loop& loop) : stepper_(stepper), loop_(loop) {}
    void state_at(double s, KinematicState& out) override { stepper_.state_at(loop_, s, out); }
    void motion_at(double s, KinematicState& out) override { stepper_.motion_at(loop_, s, out); }

   private:
    ExactStepper& stepper_;
    Loop& loop_;
  };

  void start_segment(Loop& loop);
  void state_at(const Loop& loop, double s, KinematicState& out);
  void motion_at(const Loop& loop, double s, KinematicState& out);
  void accept(Loop& loop, KinematicState& next);
  /// ∫ of the powers over [a, b] of the segment by quadrature (phases without modes).
  EnergyMeter::Powers quadrature_powers(const Loop& loop, double a, double b);
  [[nodiscard]] Eigen::MatrixXd guard_rows(const Loop& loop, const ExactPhase& exact) const;
  /// Applies the events fired at the loop's state, taking the sensitivities (when tracked) across
  /// them: the saltation of guard `guard`, the one whose crossing was located.
  void apply_events(Loop& loop, int guard);

  std::map<ContactConfiguration, PhaseData> phases_;
  ExactPowerIntegrals* segment_powers_ = nullptr;  ///< of the current segment's phase, or null
  const Eigen::MatrixXd* segment_guard_rows_ = nullptr;  ///< of the current segment's phase
  ExactTrajectory trajectory_;
  GuardExpansion expansion_;
  bool segment_valid_ = false;
  bool powers_started_ = false;  ///< segment_powers_ started on this segment (recording runs only)
  Eigen::VectorXd x_work_, x_rate_work_;
  std::vector<double> memory_amplitude_, memory_rate_;
  KinematicState node_, upper_;
  Eigen::RowVectorXd gradient_;
};

}  // namespace poundsim::detail
