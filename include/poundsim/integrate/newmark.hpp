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

#include <cstddef>
#include <span>
#include <vector>

#include <Eigen/Core>

#include "poundsim/dynamics/linear_phase.hpp"
#include "poundsim/dynamics/state.hpp"

namespace poundsim {

/// The pieces of a banded Newmark step (NewmarkIntegrator::step_banded, LinearPhase::Bands), one
/// DOF or row at a time. One simulator's step and the lockstep kernel (lockstep.hpp), which steps
/// several simulators at once, both step through them, so their operations — and bits — are the
/// same by construction. Half = τ/2 and quarter_sq = τ²/4 as the step computes them.

/// −w1 = −1·(u̇ + τ/2 ü) and −w2 = −1·(u + τ u̇ + τ²/4 ü): the sparse column loop's x_j = −1·w_j,
/// negated once instead of at each use (−(−w2) is w2 exactly).
struct NewmarkPredictors {
  double minus_w1, minus_w2;
};
[[gnu::always_inline]] inline NewmarkPredictors newmark_predictors(double u, double v, double a, double tau,
                                                                    double half, double quarter_sq) {
  return {.minus_w1 = -1.0 * (v + half * a), .minus_w2 = -1.0 * (u + tau * v + quarter_sq * a)};
}

/// The end of a DOF's step from its acceleration ü⁺: u⁺ = w2 + τ²/4 ü⁺, u̇⁺ = u̇ + τ/2 (ü + ü⁺).
struct DiagonalRowStep {
  double u, v, a;
};
[[gnu::always_inline]] inline DiagonalRowStep newmark_end(double minus_w2, double v, double a, double half,
                                                          double quarter_sq, double acceleration) {
  return {.u = -minus_w2 + quarter_sq * acceleration, .v = v + half * (a + acceleration), .a = acceleration};
}

/// One DOF's whole step when the effective matrix is diagonal (a band of width 0: no DOF coupled
/// to another): ü⁺ = (1/D)(b − m a_g − c w1 − k w2), C's term before K's as in the passes of the
/// wider bands.
[[gnu::always_inline]] inline DiagonalRowStep newmark_diagonal_row(double u, double v, double a, double tau, double half,
                                                                   double quarter_sq, double load, double ground_end,
                                                                   double mass, double damping, double stiffness,
                                                                   double inverse_d) {
  const NewmarkPredictors w = newmark_predictors(u, v, a, tau, half, quarter_sq);
  double sum = load - ground_end * mass;
  sum += damping * w.minus_w1;
  sum += stiffness * w.minus_w2;
  return newmark_end(w.minus_w2, v, a, half, quarter_sq, inverse_d * sum);
}

/// Row r of a band of width B, forward: load − a_g m, then C(r, j)(−w1_j) for j = r − B … r + B,
/// then K(r, j)(−w2_j) — the terms a sparse column loop adds to it, in its order — then the
/// forward solve with the unit lower L (columns r − B … r − 1 in order). Returns y_r, before D⁻¹.
/// Arrays are strided by S (1 for one simulator; a lockstep batch's lanes): c_row and k_row hold
/// the row's 2B + 1 entries, w1, w2 and y are indexed by DOF (padded: −B … n − 1 + B), `lower`
/// points at L's column 0 (column i holds rows i + 1 … i + B at i·C …, C ≥ B values a column).
template <int B, std::ptrdiff_t S, int C = B>
[[gnu::always_inline]] inline double banded_forward_row(double load, double ground_end, double mass,
                                                        const double* c_row, const double* k_row,
                                                        const double* minus_w1, const double* minus_w2,
                                                        const double* y, const double* lower, std::ptrdiff_t r) {
  constexpr int kRow = 2 * B + 1;
  double sum = load - ground_end * mass;
  // Unrolled (the band is known at compile time; -O2 unrolls no loop): 3 instructions a term.
#pragma GCC unroll 9
  for (int e = 0; e < kRow; ++e) sum += c_row[e * S] * minus_w1[(r - B + e) * S];
#pragma GCC unroll 9
  for (int e = 0; e < kRow; ++e) sum += k_row[e * S] * minus_w2[(r - B + e) * S];
#pragma GCC unroll 4
  for (int e = 0; e < B; ++e) {
    const std::ptrdiff_t i = r - B + e;
    sum -= y[i * S] * lower[(i * C + (B - 1 - e)) * S];
  }
  return sum;
}

/// Row i of the backward solve with Lᵀ (column i takes rows i + 1 … i + B in order): ü⁺_i, from
/// x = D⁻¹ y (padded with zeros past n − 1), strided and laid out as banded_forward_row's arrays.
template <int B, std::ptrdiff_t S, int C = B>
[[gnu::always_inline]] inline double banded_backward_row(const double* x, const double* lower, std::ptrdiff_t i) {
  double sum = x[i * S];
  const double* column = lower + i * C * S;
#pragma GCC unroll 4
  for (int e = 0; e < B; ++e) sum -= column[e * S] * x[(i + 1 + e) * S];
  return sum;
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
  /// The element to blame when not converged: the first whose force is not finite, else the one
  /// whose force changed most in the last iteration; −1 when the phase has no smooth link.
  int worst_element = -1;
  /// Whether `worst_element`'s force is not finite (NaN or ±∞) rather than merely changing.
  bool worst_not_finite = false;
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
  /// SimplicialLDLT's solve (hence the same bits), without their per-call machinery, which cost
  /// a step of two one-storey frames several times its arithmetic (docs/numerics.md, "Speed").
  void step_unreduced(const LinearPhase& phase, const LinearPhase::Solver& solver, const KinematicState& from,
                      double tau, double ground_end, KinematicState& to);
  /// step_unreduced() for a phase with bands of half-width B (LinearPhase::Bands), row by row,
  /// from (u, u̇, ü) to their ends in the phase's coordinates (the groups' for locked links): each
  /// entry of the right-hand side and of the solve receives the same terms in the same order as
  /// the column loops (or Eigen's expressions on the reduced matrices) give it, plus zeros from
  /// the band's unstored entries (the same bits: adding ±0 changes no sum, and none of these sums
  /// is −0; docs/numerics.md). The non-template one dispatches on the width.
  [[gnu::always_inline]] inline void step_banded(const LinearPhase& phase, const LinearPhase::Bands& bands,
                                                 const double* u, const double* v, const double* a, double tau,
                                                 double ground_end, double* u_new, double* v_new, double* a_new);
  template <int B>
  [[gnu::always_inline]] inline void step_banded(const LinearPhase& phase, const LinearPhase::Bands& bands,
                                                 const double* u, const double* v, const double* a, double tau,
                                                 double ground_end, double* u_new, double* v_new, double* a_new);
  /// step_banded() for a phase with locked links: over the groups' representative floors, then
  /// u = T q + o, u̇ and ü of every floor, as finish() writes them.
  void step_groups_banded(const LinearPhase& phase, const LinearPhase::Bands& bands, const KinematicState& from,
                          double tau, double ground_end, KinematicState& to);
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
