#pragma once
/// @file
/// Newmark's average-acceleration method (γ = 1/2, β = 1/4; the paper's choice, unconditionally
/// stable and second-order accurate) for one linear phase.
///
/// A step of length τ from (u, u̇, ü) at t solves, in the phase's reduced coordinates,
///
///     (M + τ/2 C + τ²/4 K) ü⁺ = −m a_g(t+τ) + b − C (u̇ + τ/2 ü) − K (u + τ u̇ + τ²/4 ü)
///     u̇⁺ = u̇ + τ/2 (ü + ü⁺),   u⁺ = u + τ u̇ + τ²/4 (ü + ü⁺)
///
/// This acceleration form is algebraically the usual displacement form, but it never divides by
/// τ²: event location takes sub-steps down to the event tolerance (1e-10 s) without cancellation.
/// The method enforces the equation of motion at t+τ, so ü⁺ is an equilibrium acceleration.
///
/// A step allocates nothing once the integrator is sized.
///
/// Smooth laws (Hertz-type contacts; LinearPhase::smooth_links) add forces F(d, ḋ) that the step
/// cannot solve linearly: step_newton solves the same equation at t+τ,
///
///     R(ü⁺) = −m a_g + b − M ü⁺ − C u̇⁺ − K u⁺ − Tᵀ f(u⁺, u̇⁺) = 0,
///
/// by Newton–Raphson on ü⁺ with the consistent tangent M + τ/2 (C + C_t) + τ²/4 (K + K_t): C_t holds
/// ∂F/∂ḋ, which OpenSees's Hertz-type materials leave out (they then converge linearly). It starts
/// from ü⁺ = ü and stops when the residual per unit mass — a bound on the correction still to
/// make, since J ⪰ M — is below `tolerance` of the accelerations' size.

#include <span>
#include <vector>

#include <Eigen/Core>

#include "poundsim/dynamics/linear_phase.hpp"
#include "poundsim/dynamics/state.hpp"

namespace poundsim {

/// One DOF's Newmark step when the effective matrix is diagonal (LinearPhase::Bands of width 0:
/// no DOF coupled to another), with half = τ/2 and quarter_sq = τ²/4 as the step computes them:
/// ü⁺ = (1/D)(b − m a_g − c (u̇ + τ/2 ü) − k (u + τ u̇ + τ²/4 ü)), then u⁺ and u̇⁺. The banded step
/// (NewmarkIntegrator::step_banded<0>) and the lockstep kernel (lockstep.hpp) both step through
/// it, so their operations, and bits, are the same by construction: the order is that of the
/// sparse step's passes (C's term before K's; −w as the column loop's −1·w).
struct DiagonalRowStep {
  double u, v, a;
};
[[gnu::always_inline]] inline DiagonalRowStep newmark_diagonal_row(double u, double v, double a, double tau, double half,
                                                                   double quarter_sq, double load, double ground_end,
                                                                   double mass, double damping, double stiffness,
                                                                   double inverse_d) {
  const double w1 = -1.0 * (v + half * a);
  const double w2 = -1.0 * (u + tau * v + quarter_sq * a);
  double sum = load - ground_end * mass;
  sum += damping * w1;
  sum += stiffness * w2;
  const double x = inverse_d * sum;
  return {.u = -w2 + quarter_sq * x, .v = v + half * (a + x), .a = x};
}

/// The smooth links' forces and tangents at a trial state, by gap element (what the Newton
/// iterations ask of the system).
class SmoothForces {
 public:
  virtual void evaluate(const KinematicState& x, std::span<ForceTangent> by_element) = 0;

 protected:
  ~SmoothForces() = default;
};

/// Newton's iterations in a step with smooth laws.
struct NewtonOptions {
  int max_iterations = 50;   ///< Beyond this the step fails (a SimulationError naming the element).
  double tolerance = 1e-10;  ///< Converged when max|R/m| ≤ tolerance × the accelerations' size.
};

/// How a Newton step went.
struct NewtonOutcome {
  int iterations = 0;  ///< Corrections made (each one tangent factorisation and solve).
  bool converged = true;
  /// The element whose force changed most in the last iteration (the one to blame), −1 if none.
  int worst_element = -1;
};

class NewmarkIntegrator {
 public:
  explicit NewmarkIntegrator(Eigen::Index dofs);

  /// Advances `from` by τ = `tau` with the factorisation `solver` of M + τ/2 C + τ²/4 K of
  /// `phase` (phase.step_solver() when τ is the phase's step); `ground_end` is a_g(t+τ).
  /// `from` and `to` must be different objects.
  void step(const LinearPhase& phase, const LinearPhase::Solver& solver,
            const KinematicState& from, double tau, double ground_end, KinematicState& to);

  /// The same step for a phase with smooth links, by Newton iterations; `forces` gives their
  /// forces and tangents at each iterate, in `by_element` (one per gap element). `to` holds the
  /// last iterate, also when it did not converge. Allocation-free once sized.
  NewtonOutcome step_newton(const LinearPhase& phase, const KinematicState& from, double tau, double ground_end,
                            SmoothForces& forces, std::span<ForceTangent> by_element, const NewtonOptions& options,
                            KinematicState& to);

 private:
  /// Gathers `from` into q, q̇, q̈ and sets w1 = q̇ + τ/2 q̈, w2 = q + τ q̇ + τ²/4 q̈ and the
  /// right-hand side −m a_g + b − C w1 − K w2.
  [[gnu::always_inline]] inline void prepare(const LinearPhase& phase, const KinematicState& from, double tau,
                                             double ground_end);
  /// step() for a phase without locked links, the common case, in plain loops over the sparse
  /// matrices' arrays: the same operations in the same order as Eigen's expressions and
  /// SimplicialLDLT's solve (hence the same bits), without their per-call machinery — a step of
  /// two one-storey frames took ≈ 980 instructions that way (docs/numerics.md).
  void step_unreduced(const LinearPhase& phase, const LinearPhase::Solver& solver, const KinematicState& from,
                      double tau, double ground_end, KinematicState& to);
  /// step_unreduced() for a phase with bands of half-width B (LinearPhase::Bands), row by row:
  /// each entry of the right-hand side and of the solve receives the same terms in the same order
  /// as the column loops give it, plus zeros from the band's unstored entries (the same bits:
  /// adding ±0 changes no sum, and none of these sums is −0; docs/numerics.md).
  template <int B>
  void step_banded(const LinearPhase& phase, const LinearPhase::Bands& bands, const KinematicState& from, double tau,
                   double ground_end, KinematicState& to);
  /// `to` from q̈⁺ (the reduced accelerations in qdd_new_) and w1, w2.
  [[gnu::always_inline]] inline void finish(const LinearPhase& phase, const KinematicState& from, double tau,
                                            double ground_end, KinematicState& to);

  Eigen::VectorXd q_, qd_, qdd_, w1_, w2_, rhs_, qdd_new_, residual_, correction_;
  /// step_banded's −w1, −w2, the solve's vector before and after D⁻¹, with Bands::kMaxWidth
  /// zeros before and after the DOFs, so that every row reads its whole band.
  std::vector<double> band_w1_, band_w2_, band_y_, band_x_;
  std::vector<double> previous_force_;
};

}  // namespace poundsim
