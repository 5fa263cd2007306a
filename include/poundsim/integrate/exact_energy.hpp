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
/// harmonic piece, the two halves of Im(h e^{iω̄(t₀+s)}); a singular phase adds s² u₂, the motion of
/// its undamped rigid-body modes under a ground ramp, which no dashpot resists (C u₂ = 0). The
/// powers the energy balance integrates (energy.hpp) are quadratic in q̇ (storey and gap dashpots,
/// q̇ᵀ C q̇) or bilinear in a_g and q̇ (ground input, −a_g m_rᵀ q̇, with a_g linear in s or a sine),
/// so each is a finite sum of s^d e^{μs} with d ≤ 2 (d = 3 for the input with u₂), and
///
///     ∫_a^b s^d e^{μs} ds = e^{μa} Σ_{l≤d} C(d,l) (−1)^l b^{d−l} l! h^{l+1} φ_{l+1}(μh),  h = b − a,
///     φ_k(z) = Σ_j z^j / (j+k)!   (φ₁(z) = (e^z − 1)/z, ...).
///
/// Why not quadrature: a Gauss rule must resolve the fastest product of two modes, so its cost
/// grew with the frequency spread of the phase (6.9 s for 1 s of a frame beside a wall 8·10⁴ times
/// stiffer). In closed form the cost per sample is O(T²), T = 2n + 4 terms,
/// whatever the frequencies. The modal products V_jᵀ C V_k are formed once per phase.
///
/// Only for the modal path (ExactPhase::modal()); the matrix-exponential path keeps quadrature.

#include <array>
#include <complex>
#include <utility>
#include <vector>

#include <Eigen/Core>

#include "poundsim/dynamics/energy.hpp"
#include "poundsim/integrate/exact_phase.hpp"

namespace poundsim {

/// ∫ s^d e^{μs} ds over [a, a + h] for d = 0 … 3, accurate also for μh → 0. Exposed for tests.
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

  /// s^degree e^{μs} with e^{μs} = f[first]·f[second] of the exponential factors of a step
  /// (modes 0…2n−1, then 1, e^{iω̄s}, e^{−iω̄s}; a step evaluates 2n + 1 complex exponentials in
  /// all), and its coefficient in each integral.
  struct Term {
    Complex mu;
    int degree;
    int first, second;
    Complex storey, gap, input;
  };
  /// Fills start_factor_ = e^{μa} and step_factor_ = e^{μh} for every factor.
  void factors(double a, double h) const;

  // The segment. Modes: c (q̇'s modal part is W e^{Λs} c), integrated as a block. Every other
  // product — the extras x_e s^{d_e} e^{μ_e s} of q̇ (u₀, s u₁ and the two halves of the harmonic
  // part) with the modes and with each other, and the input −a_g m_rᵀ q̇ — is one Term.
  Eigen::VectorXcd c_;
  std::vector<Term> terms_;
  bool gap_active_ = false;

  // ∫_a^{a+h} s^d e^{μs} ds = e^{μa} (polynomial in b of p_l = l! h^{l+1} φ_{l+1}(μh)), and the
  // p_l depend on h only: they are kept for the step length that repeats (the grid step) — for the
  // modal block as the weighted matrices (C_ij p₁), for the terms as p₁…p₃ — so that a grid step
  // costs two matrix–vector products and no φ. The terms' exponents are the same for every
  // segment of the phase with the same ω̄ and kind of piece (`signature_`).
  void weigh(double h) const;
  mutable double cached_step_ = -1.0, last_step_ = -1.0;
  mutable Eigen::MatrixXcd weighted_storey_, weighted_gap_;
  mutable std::vector<std::array<Complex, 4>> term_weights_;
  std::pair<double, std::size_t> signature_{-1.0, 0};

  mutable Eigen::VectorXcd start_factor_, step_factor_, advanced_, product_;
  // Work space of start(), kept so that a new segment of the same phase allocates nothing.
  Eigen::MatrixXcd extra_terms_, form_x_, cross_storey_, cross_gap_, among_storey_, among_gap_;
  Eigen::RowVectorXcd extra_mass_;
  Eigen::MatrixXcd complex_mass_transposed_;  // the mass form's transpose as complex numbers
  std::vector<Complex> extra_mu_;
  std::vector<int> extra_degree_, extra_factor_;
};

}  // namespace poundsim
