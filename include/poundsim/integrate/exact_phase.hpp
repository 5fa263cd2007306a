#pragma once
/// @file
/// The exact solution of one linear phase (the exact integrator, integrator = "exact").
///
/// Between events the equations of motion of a phase (linear_phase.hpp) are, in its reduced
/// coordinates with x = [q; q̇] (n groups, 2n states),
///
///     ẋ = A x + f + e a_g(t),   A = [[0, I], [−M⁻¹K, −M⁻¹C]],   f = [0; M⁻¹b],   e = [0; −1]
///
/// (M⁻¹m = 1: every floor feels the same ground acceleration). On a forcing piece (a_g linear in
/// t, or A sin ω̄t; excitation.hpp) the solution is known in closed form:
///
///     x(t₀ + s) = x_p(s) + Re(V e^{Λs} c),   c = V⁻¹(x(t₀) − x_p(0))
///
/// with the eigen-decomposition A = V Λ V⁻¹ — complex, since the gap dashpots and storey dashpots
/// that are not proportional make the modes complex — and the particular solution
///
///     x_p(s) = x_c + β s                         linear piece a_g = a₀ + a₁ s:
///                                                 β = −a₁ A⁻¹e,  x_c = −A⁻¹f + A⁻¹(β − a₀ e)
///     x_p(s) = x_c + Im(A_g h e^{iω̄(t₀+s)})      harmonic piece: (iω̄I − A) h = e, x_c = −A⁻¹f
///
/// When the modes are ill-conditioned (A nearly defective, e.g. a critically damped mode) the
/// homogeneous part uses the matrix exponential e^{As}(x(t₀) − x_p(0)) instead; it costs O(n³)
/// per evaluation rather than O(n²). A forcing at an undamped natural frequency has no bounded
/// particular solution and is rejected.
///
/// A is singular when the phase has a rigid-body mode: a floor or a frame held by no stiffness,
/// as a storey that yields with no post-yield stiffness (an elastic–perfectly-plastic storey).
/// A⁻¹ does not exist and the constant and linear forcing then drive a polynomial of degree up
/// to 3 (a constant force on a free mass moves it as s²/2; a linear one as s³/6): the particular
/// solution is x_p(s) = p₀ + p₁s + p₂s² + p₃s³ (+ the harmonic part), with
///
///     A p₀ − p₁ = −c₀,   A p₁ − 2p₂ = −c₁,   A p₂ − 3p₃ = 0,   A p₃ = 0
///
/// for the forcing c₀ + c₁s, solved once per phase by a complete orthogonal decomposition of that
/// block system.
///
/// A rigid-body mode N (K N = 0, mass-normalised NᵀMN = I) held by a dashpot (C N ≠ 0) is a simple
/// zero eigenvalue, and the modes stay a basis. One held by nothing (C N = 0 too: an undamped
/// storey that yields with no post-yield stiffness, or a floor without springs or dashpots) makes
/// zero a defective eigenvalue: A [0; N] = [N; 0], a Jordan block whose motion [N(α + α̇s); Nα̇]
/// is a polynomial, which no sum of exponentials represents. Those pairs are split off exactly:
/// J = span{[N; 0], [0; N]} and its complement {[q; v]: NᵀMq = NᵀMv = 0} are both invariant under
/// A (NᵀK = NᵀC = 0), so with P the projection on the complement along J
///
///     x(t₀ + s) = x_p(s) + Re(V e^{Λs} c),   (I − P)(x(t₀) − x_p(0)) = 0,
///
/// the particular polynomial carrying the whole motion in J (its homogeneous part, (I − P)r₀ +
/// s A(I − P)r₀, added to p₀ and p₁), and V, Λ the modes of PA — A on the complement, zero on J —
/// whose kernel, span{[N_K; 0], [0; N]} (N_K all of K's null space), is set to its exact basis
/// with λ = 0; the coefficients of the columns in J are zero. The guards, the energy integrals
/// and the propagator then take the phase as any modal one, with the polynomial part (degree ≤ 3
/// in q, ≤ 2 in q̇; the propagator gains s A(I − P)). A singular phase whose rigid modes cannot be
/// told apart (ExactPhaseTolerances), or whose remaining modes are ill-conditioned, uses the matrix
/// exponential with the same polynomial.

#include <array>
#include <cmath>
#include <complex>
#include <limits>
#include <memory>
#include <vector>

#include <Eigen/Core>
#include <Eigen/LU>
#include <Eigen/QR>

#include "poundsim/model/excitation.hpp"
#include "poundsim/dynamics/linear_phase.hpp"

namespace poundsim {

/// e^z − 1 without the cancellation of e^z − 1 for small |z|: Re = expm1(x) cos y − 2 sin²(y/2),
/// Im = e^x sin y.
[[nodiscard]] inline std::complex<double> complex_expm1(std::complex<double> z) {
  const double x = z.real(), y = z.imag(), half = std::sin(0.5 * y);
  return {std::expm1(x) * std::cos(y) - 2 * half * half, std::exp(x) * std::sin(y)};
}

/// e^z for finite z with z.real() ≤ 709, bit for bit what std::exp(std::complex<double>) returns
/// (glibc's cexp: e^x cos y + i e^x sin y through sincos), without its classification of every
/// special case — a third of the guard search's time went there. Other z go to std::exp.
/// Checked against std::exp on random arguments (exact_phase_test).
[[nodiscard]] inline std::complex<double> complex_exp(std::complex<double> z) {
  const double x = z.real(), y = z.imag();
  if (!(x <= 709.0) || !std::isfinite(y)) return std::exp(z);
  double sine = y, cosine = 1.0;
  if (std::abs(y) > std::numeric_limits<double>::min()) {
    sine = std::sin(y);
    cosine = std::cos(y);
  }
  const double magnitude = std::exp(x);
  return {magnitude * cosine, magnitude * sine};
}

/// The thresholds of ExactPhase's decomposition (see the file comment). K and C are taken
/// mass-normalised, M^{-1/2} K M^{-1/2} and M^{-1/2} C M^{-1/2}.
struct ExactPhaseTolerances {
  /// An eigenvalue ω² of K at most this times its largest is a rigid-body mode. A zero stiffness
  /// is computed as a few ε of the largest ω² (the sums of storey stiffnesses round), so the
  /// threshold sits well above round-off: ω ≤ 1e-6 ω_max.
  double rigid_stiffness = 1e-12;
  /// A rigid-body mode whose damping rate (an eigenvalue of C on those modes) is at most this
  /// times the phase's largest rate (ω_max or C's largest) is undamped: a Jordan pair.
  double rigid_damping = 1e-12;
  /// The kernel of PA is computed as eigenvalues within a few ε of its spectral radius; those up
  /// to this fraction of it are taken as that kernel, and must be as many as its exact basis.
  double kernel = 1e-8;
  /// A mode with |λ| h at most this (h the phase's step, LinearPhase::step) is slow: its
  /// coefficient |c| ~ |ċ|/|λ| dwarfs its motion over a step, ε|c| in absolute terms, so it is
  /// summed as c (e^{λs} − 1) with the constant c apart (see slow_modes()). Above it the loss,
  /// ε/(|λ| h) of a step's motion, is below 2e-13.
  double slow_mode = 1e-3;
};

class ExactPhase {
 public:
  /// Builds A and its eigen-decomposition; when that fails or its modes are ill-conditioned, the
  /// phase uses the matrix exponential instead (modal() is false).
  explicit ExactPhase(const LinearPhase& phase, const ExactPhaseTolerances& tolerances = {});

  [[nodiscard]] Eigen::Index groups() const { return n_; }
  [[nodiscard]] const Eigen::MatrixXd& matrix() const { return a_; }
  /// True when the eigen-decomposition is used (well-conditioned modes).
  [[nodiscard]] bool modal() const { return modal_; }
  [[nodiscard]] const Eigen::VectorXcd& eigenvalues() const { return lambda_; }
  /// e^{λ_k s} for every eigenvalue (modal path), into `out` (resized once). The eigen-solver
  /// returns complex eigenvalues as exactly conjugate neighbours, and e^{λ̄s} is the conjugate of
  /// e^{λs} bit for bit (glibc's cexp is odd in the imaginary part): one exponential serves
  /// both — half the transcendental work of the guard search and the trajectory, same bits.
  void exponentials(double s, Eigen::VectorXcd& out) const;
  [[nodiscard]] const Eigen::MatrixXcd& modes() const { return v_; }
  /// `out` = V⁻¹ r through the balanced modes V̂ = D⁻¹V (see the constructor): `scaled` = D⁻¹ r
  /// as complex numbers, then V̂⁻¹ `scaled`. Both keep their storage: a segment starts at every
  /// event and allocates nothing.
  void modal_coordinates(const Eigen::VectorXd& r, Eigen::VectorXcd& scaled, Eigen::VectorXcd& out) const;
  /// `out` = A⁻¹ r (not singular()), into `out`'s storage.
  void solve(const Eigen::VectorXd& r, Eigen::VectorXd& out) const { out = a_lu_.solve(r); }
  /// A has no inverse (a rigid-body mode): the particular solution is a polynomial.
  [[nodiscard]] bool singular() const { return singular_; }
  /// p₀ … p₃ of the polynomial particular solution of ẋ = A x + c₀ + c₁ s (see the file
  /// comment). Throws SimulationError when the block system has no solution.
  void polynomial_particular(const Eigen::VectorXd& c0, const Eigen::VectorXd& c1,
                             std::array<Eigen::VectorXd, 4>& p) const;
  /// The undamped rigid-body modes N (n × r, NᵀMN = I) split off as Jordan pairs on the modal
  /// path (see the file comment; no columns otherwise).
  [[nodiscard]] const Eigen::MatrixXd& rigid_modes() const { return rigid_; }
  /// For r = x(t₀) − x_p(0) of a segment: moves its part in the Jordan pairs, d = (I − P) r, to
  /// p₀ and d's rate A d = [N NᵀM d_v; 0] to p₁, so that the particular polynomial carries the
  /// rigid motion and the modes none of it. Nothing when rigid_modes() is empty.
  /// r loses d (r = P r after).
  void absorb_rigid_motion(Eigen::VectorXd& r, Eigen::VectorXd& p0, Eigen::VectorXd& p1) const;
  /// The modes whose coefficients are zero by construction (the columns of V in J).
  [[nodiscard]] const std::vector<Eigen::Index>& jordan_columns() const { return jordan_columns_; }
  /// slow_modes()[k]: mode k is slow (ExactPhaseTolerances::slow_mode; a floor on a storey of
  /// 1e-12 N/m: |λ| = 1e-6 rad/s). Its term V c e^{λs} would carry ε|V c| ~ ε|q̇|/|λ| of
  /// round-off, far more than its motion: it is taken as V c + V c (e^{λs} − 1), the constant
  /// with the segment's (ExactTrajectory::slow_constant) and the increment from expm1. Empty
  /// when no mode is slow (modal path only).
  [[nodiscard]] const std::vector<bool>& slow_modes() const { return slow_; }
  /// A⁻¹ e.
  [[nodiscard]] const Eigen::VectorXd& ground_response() const { return a_inv_e_; }
  /// Φ(s) = e^{As} = ∂x(t₀+s)/∂x(t₀): the forcing enters only the particular solution, so the
  /// state's sensitivity to where the phase starts is the homogeneous flow. Modal path: V e^{Λs} V⁻¹
  /// (real to round-off, its real part returned); otherwise the matrix exponential. For the
  /// monodromy matrix of periodic orbits (phase propagators composed with the events'
  /// saltation matrices).
  [[nodiscard]] Eigen::MatrixXd propagator(double s) const;
  /// One mode of each conjugate pair (the first) and every real mode, ascending; `paired(i)`: the
  /// i-th kept mode's conjugate is the next mode. Real sums over all modes of terms that are
  /// conjugate for a pair take the kept ones alone (guard_expansion.cpp, project_modes).
  [[nodiscard]] const std::vector<Eigen::Index>& kept_modes() const {
    keep_modes();
    return kept_modes_;
  }
  [[nodiscard]] bool paired(std::size_t i) const { return kept_weight_(static_cast<Eigen::Index>(i)) == 2.0; }
  /// Φ(s) r for many s and one real r (the tangent flow's columns), modal path: `projected` =
  /// V⁻¹ r once, then each Φ(s) r = Re(V e^{Λs} V⁻¹ r) from it. A conjugate pair's two terms are
  /// conjugates when r is real: one of each pair is kept, doubled — half the work of forming
  /// Φ(s) (a complex product of three n × n matrices) and then Φ(s) r. Equal to propagator(s) r to
  /// round-off (exact_phase_test).
  struct Projection {
    Eigen::MatrixXd real, imag;  ///< V⁻¹ r of the kept modes, in parts (r is real: two real products)
    Eigen::MatrixXd rigid_rate;  ///< A(I − P) r, the Jordan pairs' s-term (empty without them)
  };
  void project_modes(const Eigen::MatrixXd& r, Projection& projected) const;
  void propagate_projected(double s, const Projection& projected, Eigen::MatrixXd& out) const;
  /// h with (iωI − A) h = e. Throws SimulationError at an undamped natural frequency.
  ///
  /// Every segment of a harmonic excitation starts with the same ω, so the last h is kept and
  /// returned again for the same ω (valid until the next call with another ω). Because of that
  /// cache, one ExactPhase must not be used by several threads at once.
  [[nodiscard]] const Eigen::VectorXcd& harmonic_response(double omega) const;
  /// dh/dω = −i (iωI − A)⁻¹ h, for the sensitivity of a run to its forcing frequency
  /// (tangent_flow.hpp): one more solve with harmonic_response's factorisation, kept likewise.
  [[nodiscard]] const Eigen::VectorXcd& harmonic_response_rate(double omega) const;
  /// max |λ| [1/s]: the fastest rate of the phase (‖Â‖₂, an upper bound, when not modal()).
  [[nodiscard]] double spectral_radius() const { return spectral_radius_; }
  /// ‖Â‖₂ and the logarithmic norm μ₂(Â) of the balanced Â = D⁻¹ A D: bounds for the
  /// matrix-exponential path, computed only for it (NaN when modal()).
  [[nodiscard]] double norm() const { return norm_; }
  [[nodiscard]] double log_norm() const { return log_norm_; }
  /// D = diag(1, ω_i) of the balancing: e^{As} = D e^{Âs} D⁻¹.
  [[nodiscard]] const Eigen::VectorXd& scale() const { return scale_; }

 private:
  Eigen::Index n_ = 0;
  Eigen::MatrixXd a_;
  Eigen::PartialPivLU<Eigen::MatrixXd> a_lu_;
  Eigen::VectorXd a_inv_e_;
  bool singular_ = false;
  Eigen::MatrixXd rigid_;          ///< N, the undamped rigid-body modes (modal path)
  Eigen::MatrixXd rigid_weights_;  ///< NᵀM: (I − P) x = [N NᵀM q; N NᵀM q̇]
  std::vector<Eigen::Index> jordan_columns_;
  std::vector<bool> slow_;
  mutable Eigen::VectorXd rigid_work_, rigid_part_;  // absorb_rigid_motion's, sized once
  /// A(I − P) r for the columns r.
  [[nodiscard]] Eigen::MatrixXd rigid_rate(const Eigen::MatrixXd& r) const;
  /// Of the block system of polynomial_particular, made on first use.
  mutable std::unique_ptr<Eigen::CompleteOrthogonalDecomposition<Eigen::MatrixXd>> polynomial_;
  bool modal_ = false;
  Eigen::VectorXcd lambda_;
  /// conjugate_of_previous_[k]: λ_k is exactly conj(λ_{k−1}).
  std::vector<bool> conjugate_of_previous_;
  Eigen::VectorXd scale_;  ///< D of the balanced decomposition: 1 for q, ω_i for q̇_i.
  Eigen::MatrixXcd v_;     ///< V = D V̂
  Eigen::PartialPivLU<Eigen::MatrixXcd> v_lu_;  ///< of V̂
  double spectral_radius_ = 0.0;
  double norm_ = std::numeric_limits<double>::quiet_NaN();
  double log_norm_ = std::numeric_limits<double>::quiet_NaN();
  mutable double harmonic_omega_ = std::numeric_limits<double>::quiet_NaN();
  mutable Eigen::VectorXcd harmonic_response_;
  mutable Eigen::PartialPivLU<Eigen::MatrixXcd> harmonic_lu_;  ///< of D⁻¹(iωI − A)D at harmonic_omega_
  mutable double harmonic_rate_omega_ = std::numeric_limits<double>::quiet_NaN();
  mutable Eigen::VectorXcd harmonic_response_rate_;
  mutable Eigen::MatrixXcd inverse_modes_;  ///< V⁻¹, made on first use (inverse_modes())
  [[nodiscard]] const Eigen::MatrixXcd& inverse_modes() const;
  // project_modes' kept modes (one of each conjugate pair, weight 2; real modes, weight 1), their
  // rows of V⁻¹ and their columns of V in real and imaginary parts; made on first use.
  mutable std::vector<Eigen::Index> kept_modes_;
  mutable Eigen::VectorXd kept_weight_;
  mutable Eigen::MatrixXd kept_inverse_real_, kept_inverse_imag_;
  mutable Eigen::MatrixXd kept_real_, kept_imag_;
  mutable Eigen::MatrixXd projected_real_, projected_imag_;  // propagate_projected's work
  void keep_modes() const;
};

/// The exact trajectory of a phase from (t₀, x₀) while one forcing piece holds.
class ExactTrajectory {
 public:
  /// `constant_load` is the phase's b (reduced); `x0` = [q; q̇] at t0.
  void start(const ExactPhase& phase, const Eigen::VectorXd& mass, const Eigen::VectorXd& constant_load,
             double t0, const Eigen::VectorXd& x0, const ForcingPiece& piece);

  [[nodiscard]] double start_time() const { return t0_; }
  [[nodiscard]] const ForcingPiece& piece() const { return piece_; }
  [[nodiscard]] const ExactPhase& phase() const { return *phase_; }

  /// x(t₀+s) and ẋ(t₀+s).
  void evaluate(double s, Eigen::VectorXd& x, Eigen::VectorXd& x_rate) const;
  /// x(t₀+s) alone, the same bits as the overload above (half its work on the modal path).
  void evaluate(double s, Eigen::VectorXd& x) const;
  /// e^{λ_k s} (modal path; ExactPhase::exponentials), kept for the last s: the guard search asks
  /// every guard at the same ends of a step, and the state is then taken at one of them.
  [[nodiscard]] const Eigen::VectorXcd& exponentials(double s) const;

  // The parts of x(s) = x_c + β s + p₂s² + p₃s³ + Im(p e^{iω̄(t₀+s)}) + homogeneous(s), for guard
  // expansions (p₂ = p₃ = 0 unless the phase is singular()).
  [[nodiscard]] const Eigen::VectorXd& constant_part() const { return xc_; }
  [[nodiscard]] const Eigen::VectorXd& linear_part() const { return beta_; }
  [[nodiscard]] const Eigen::VectorXd& quadratic_part() const { return quadratic_; }
  [[nodiscard]] const Eigen::VectorXd& cubic_part() const { return cubic_; }
  [[nodiscard]] const Eigen::VectorXcd& harmonic_part() const { return harmonic_; }
  [[nodiscard]] double omega() const { return piece_.kind == ForcingPiece::Kind::harmonic ? piece_.omega : 0.0; }
  /// Modal coordinates c (modal path).
  [[nodiscard]] const Eigen::VectorXcd& modal_coefficients() const { return c_; }
  /// The slow modes' part of x(t₀) − x_p(0), Σ_slow V_k c_k, as r₀ less the other modes' (so
  /// without the slow ones' round-off): a constant of x(s) (ExactPhase::slow_modes). Empty when
  /// the phase has no slow modes.
  [[nodiscard]] const Eigen::VectorXd& slow_constant() const { return slow_constant_; }
  /// e^{λ_k s} − 1 of the slow modes (0 for the others), accurate for small |λs|; kept for the
  /// last s like exponentials().
  [[nodiscard]] const Eigen::VectorXcd& increments(double s) const;
  /// x(t₀) − x_p(0) (both paths).
  [[nodiscard]] const Eigen::VectorXd& homogeneous_start() const { return r0_; }

 private:
  const ExactPhase* phase_ = nullptr;
  double t0_ = 0.0;
  ForcingPiece piece_;
  Eigen::VectorXd xc_, beta_, quadratic_, cubic_, r0_, slow_constant_;
  Eigen::VectorXd load_, particular_start_, solved_;  // start()'s work vectors
  Eigen::VectorXcd scaled_start_;                     // D⁻¹ r₀, for the modal coordinates
  std::array<Eigen::VectorXd, 4> polynomial_work_;
  Eigen::VectorXcd harmonic_, c_;
  void evaluate(double s, Eigen::VectorXd& x, Eigen::VectorXd* x_rate) const;

  mutable Eigen::VectorXcd work_, product_, exponentials_, increments_;
  mutable double exponentials_at_ = std::numeric_limits<double>::quiet_NaN();
  mutable double increments_at_ = std::numeric_limits<double>::quiet_NaN();
  /// The modal part of x(s) (and of its rate) with the slow modes apart.
  void add_slow_modal(double s, Eigen::VectorXd& x, Eigen::VectorXd* x_rate) const;
};

}  // namespace poundsim
