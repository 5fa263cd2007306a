#pragma once
/// @file
/// The energy integrals of the exact integrator in closed form.
///
/// On a segment of an exact trajectory (exact_phase.hpp) the reduced velocities are a sum of
/// exponentials and at most linear terms,
///
///     q̇(s) = u₀ + s u₁ + Σ_k g_k e^{μ_k s},
///
/// the g_k e^{μ_k s} being the modes (g_k = V_k c_k, μ_k = λ_k, the velocity rows of V) and, on a
/// harmonic piece, the two halves of Im(h e^{iω̄(t₀+s)}). The powers the energy balance integrates
/// (energy.hpp) are quadratic in q̇ (storey and gap dashpots, q̇ᵀ C q̇) or bilinear in a_g and q̇
/// (ground input, −a_g m_rᵀ q̇, with a_g linear in s or a sine), so each is a finite sum of
/// s^d e^{μs} with d ≤ 2, and
///
///     ∫_a^b s^d e^{μs} ds = e^{μa} Σ_{l≤d} C(d,l) (−1)^l b^{d−l} l! h^{l+1} φ_{l+1}(μh),  h = b − a,
///     φ_k(z) = Σ_j z^j / (j+k)!   (φ₁(z) = (e^z − 1)/z, ...).
///
/// Why not quadrature: a Gauss rule must resolve the fastest product of two modes, so its cost
/// grew with the frequency spread of the phase (6.9 s for 1 s of a frame beside a wall 8·10⁴ times
/// stiffer, issue 8 defect 9). In closed form the cost per sample is O(T²), T = 2n + 4 terms,
/// whatever the frequencies. The modal products V_jᵀ C V_k are formed once per phase.
///
/// Only for the modal path (ExactPhase::modal()); the matrix-exponential path keeps quadrature.

#include <complex>
#include <vector>

#include <Eigen/Core>

#include "poundsim/energy.hpp"
#include "poundsim/exact_phase.hpp"

namespace poundsim {

/// ∫ s^d e^{μs} ds over [a, a + h] for d = 0, 1, 2, accurate also for μh → 0. Exposed for tests.
[[nodiscard]] std::complex<double> exponential_moment(int degree, std::complex<double> mu, double a,
                                                      double h);

class ExactPowerIntegrals {
 public:
  /// Projects the forms on the modes of `phase`, which must be modal() and outlive this object.
  ExactPowerIntegrals(const ExactPhase& phase, PowerForms forms);

  /// Takes the coefficients of a new segment (after ExactTrajectory::start on the same phase).
  void start(const ExactTrajectory& trajectory);

  /// The integrals over s ∈ [a, b] of the segment started last. Allocation-free.
  [[nodiscard]] EnergyMeter::Powers integrate(double a, double b) const;

 private:
  using Complex = std::complex<double>;
  const ExactPhase* phase_;
  PowerForms forms_;
  Eigen::MatrixXcd modal_storey_, modal_gap_;  ///< W_jᵀ C W_k, W the velocity rows of V
  Eigen::RowVectorXcd modal_mass_;             ///< m_rᵀ W

  // The segment: terms y_i = g_i s^{d_i} e^{μ_i s} of q̇; pair coefficients of the two quadratic
  // forms (upper triangle, off-diagonal pairs doubled); the input's products of a_g and m_rᵀq̇.
  std::vector<Complex> mu_;
  std::vector<int> degree_;
  Eigen::MatrixXcd pair_storey_, pair_gap_;
  struct InputTerm {
    Complex coefficient;
    Complex mu;
    int degree;
  };
  std::vector<InputTerm> input_;
  mutable std::vector<Complex> start_factor_, step_factor_;
  // Work space of start(), kept so that a new segment of the same phase allocates nothing.
  Eigen::MatrixXcd extra_terms_, form_x_, cross_, extra_;
  Eigen::RowVectorXcd extra_mass_;
};

}  // namespace poundsim
