#include "poundsim/integrate/exact_phase.hpp"

#include <algorithm>
#include <cmath>

#include <Eigen/Eigenvalues>
#include <fmt/format.h>
#include <unsupported/Eigen/MatrixFunctions>

#include "poundsim/error.hpp"

namespace poundsim {

namespace {
/// Round-off in the modal path grows like ε / rcond(V): below this (a nearly defective A, such as
/// a critically damped mode) it would exceed 1e-11, so e^{As} is used instead.
constexpr double kMinModeConditioning = 1e-5;
/// Below this rcond(A) the phase is taken as singular (a rigid-body mode): its A⁻¹ would carry
/// round-off amplified beyond 1e-4.
constexpr double kMinInverseConditioning = 1e-12;

/// rcond(Â) ≤ kMinInverseConditioning, proven by a pivot or estimated. Eigen's estimate alone
/// is not enough: on an exactly singular Â (a floor held by neither a spring nor a dashpot, a
/// zero column) the zero pivot's infinities can leave it at 1, and A⁻¹ then made every state
/// NaN. With PÂ = LU and |L_ij| ≤ 1, ‖Â⁻¹‖₁ ≥ ‖U⁻¹‖₁/‖L‖₁ ≥ 1/(size · min|u_ii|), so
/// rcond₁(Â) ≤ size · min|u_ii| / ‖Â‖₁: a small pivot proves the phase singular.
bool is_singular(const Eigen::MatrixXd& balanced) {
  const Eigen::PartialPivLU<Eigen::MatrixXd> lu(balanced);
  const double size = static_cast<double>(balanced.rows());
  const double norm = balanced.cwiseAbs().colwise().sum().maxCoeff();
  const double least_pivot = lu.matrixLU().diagonal().cwiseAbs().minCoeff();
  if (!(size * least_pivot > kMinInverseConditioning * norm)) return true;
  return !(lu.rcond() > kMinInverseConditioning);
}

/// K's null space N_K, mass-normalised (NᵀMN = I), split into the modes C also annihilates
/// (undamped: the Jordan pairs) and the rest (damped). `found` is false when K or C is not
/// symmetric (the invariant splitting of exact_phase.hpp needs NᵀK = NᵀC = 0) or K has no null
/// space within the tolerances.
struct RigidModes {
  Eigen::MatrixXd undamped, damped;
  bool found = false;
};

bool symmetric(const Eigen::MatrixXd& m) {
  return (m - m.transpose()).cwiseAbs().maxCoeff() <= 16 * std::numeric_limits<double>::epsilon() * m.cwiseAbs().maxCoeff();
}

RigidModes find_rigid_modes(const LinearPhase& phase, const ExactPhaseTolerances& tolerances) {
  const Eigen::VectorXd root = phase.mass().cwiseSqrt().cwiseInverse();  // M^{-1/2}
  const Eigen::MatrixXd k = root.asDiagonal() * Eigen::MatrixXd(phase.stiffness()) * root.asDiagonal();
  const Eigen::MatrixXd c = root.asDiagonal() * Eigen::MatrixXd(phase.damping()) * root.asDiagonal();
  RigidModes out;
  if (!symmetric(k) || !symmetric(c)) return out;
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> stiffness(k);  // ascending
  const double largest = std::max(stiffness.eigenvalues().maxCoeff(), 0.0);
  Eigen::Index free = 0;
  while (free < k.rows() && stiffness.eigenvalues()(free) <= tolerances.rigid_stiffness * largest) ++free;
  if (free == 0) return out;
  const Eigen::MatrixXd null_space = stiffness.eigenvectors().leftCols(free);
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> damping(null_space.transpose() * c * null_space);
  // Rates of the phase: √ω²_max, and C's largest (its ∞-norm bounds it).
  const double rate = std::max(std::sqrt(largest), c.cwiseAbs().rowwise().sum().maxCoeff());
  Eigen::Index undamped = 0;
  while (undamped < free && damping.eigenvalues()(undamped) <= tolerances.rigid_damping * rate) ++undamped;
  const Eigen::MatrixXd modes = root.asDiagonal() * (null_space * damping.eigenvectors());
  out.undamped = modes.leftCols(undamped);
  out.damped = modes.rightCols(free - undamped);
  out.found = true;
  return out;
}

/// D⁻¹ P A D: the balanced A with the Jordan pairs of the undamped rigid modes N projected out,
/// P = I − diag(N NᵀM, N NᵀM) (exact_phase.hpp).
Eigen::MatrixXd projected_balanced(const Eigen::MatrixXd& a, const Eigen::MatrixXd& rigid, const Eigen::VectorXd& mass,
                                   const Eigen::VectorXd& scale) {
  const Eigen::Index n = rigid.rows();
  const Eigen::MatrixXd within = rigid * (rigid.transpose() * mass.asDiagonal());
  Eigen::MatrixXd projector = Eigen::MatrixXd::Identity(2 * n, 2 * n);
  projector.topLeftCorner(n, n) -= within;
  projector.bottomRightCorner(n, n) -= within;
  return scale.cwiseInverse().asDiagonal() * (projector * a) * scale.asDiagonal();
}

/// Sets the computed kernel of D⁻¹PAD to its exact basis, balanced and normalised: D⁻¹[N; 0],
/// D⁻¹[0; N] (the Jordan pairs, listed in `jordan`) and D⁻¹[N_d; 0] (the damped rigid modes),
/// with λ = 0. False when the eigenvalues within tolerance of zero are not as many as that basis.
bool set_exact_kernel(const RigidModes& rigid, const Eigen::VectorXd& scale, double tolerance, Eigen::VectorXcd& values,
                      Eigen::MatrixXcd& vectors, std::vector<Eigen::Index>& jordan) {
  const Eigen::Index n = rigid.undamped.rows(), r = rigid.undamped.cols(), d = rigid.damped.cols();
  Eigen::MatrixXd kernel = Eigen::MatrixXd::Zero(2 * n, 2 * r + d);
  kernel.block(0, 0, n, r) = rigid.undamped;
  kernel.block(n, r, n, r) = rigid.undamped;
  kernel.block(0, 2 * r, n, d) = rigid.damped;
  kernel = scale.cwiseInverse().asDiagonal() * kernel;
  kernel.colwise().normalize();
  const double radius = values.cwiseAbs().maxCoeff();
  std::vector<Eigen::Index> zero;
  for (Eigen::Index k = 0; k < values.size(); ++k) {
    if (std::abs(values(k)) <= tolerance * radius) zero.push_back(k);
  }
  if (static_cast<Eigen::Index>(zero.size()) != kernel.cols()) return false;
  for (std::size_t i = 0; i < zero.size(); ++i) {
    vectors.col(zero[i]) = kernel.col(static_cast<Eigen::Index>(i)).cast<std::complex<double>>();
    values(zero[i]) = 0.0;
  }
  jordan.assign(zero.begin(), zero.begin() + 2 * r);
  return true;
}

/// `slow`[k]: |λ_k| h ≤ limit (a conjugate pair shares |λ|, so both or neither); left empty when
/// no mode is.
void mark_slow_modes(const Eigen::VectorXcd& lambda, double step, double limit, std::vector<bool>& slow) {
  slow.assign(static_cast<std::size_t>(lambda.size()), false);
  bool any = false;
  for (Eigen::Index k = 0; k < lambda.size(); ++k) {
    const bool is_slow = std::abs(lambda(k)) * step <= limit;
    slow[static_cast<std::size_t>(k)] = is_slow;
    any = any || is_slow;
  }
  if (!any) slow.clear();
}

/// The velocity rows of a slow mode's balanced eigenvector set to what A's first block row
/// imposes, λ times its displacement rows over D: the eigen-solver gives them to ε of the
/// vector's norm, while they are |λ|/ω_i of it — a relative error ε ω_i/|λ| (8e-11 for a floor of
/// 1e-6 N/m in contact at 1e5 N/m), which the energy integrals' velocities V c carried into the
/// balance. Not the Jordan columns (generalised eigenvectors).
void tie_slow_velocities(const Eigen::VectorXcd& lambda, const Eigen::VectorXd& scale, const std::vector<bool>& slow,
                         const std::vector<Eigen::Index>& jordan, Eigen::MatrixXcd& vectors) {
  const Eigen::Index n = vectors.rows() / 2;
  for (Eigen::Index k = 0; k < vectors.cols(); ++k) {
    if (!slow[static_cast<std::size_t>(k)] || std::find(jordan.begin(), jordan.end(), k) != jordan.end()) continue;
    vectors.col(k).tail(n) = lambda(k) * vectors.col(k).head(n).cwiseQuotient(scale.tail(n).cast<std::complex<double>>());
  }
}
}  // namespace

void ExactPhase::polynomial_particular(const Eigen::VectorXd& c0, const Eigen::VectorXd& c1,
                                       std::array<Eigen::VectorXd, 4>& p) const {
  const Eigen::Index m = 2 * n_;
  if (!polynomial_) {
    Eigen::MatrixXd blocks = Eigen::MatrixXd::Zero(4 * m, 4 * m);
    for (Eigen::Index k = 0; k < 4; ++k) {
      blocks.block(k * m, k * m, m, m) = a_;
      if (k < 3) blocks.block(k * m, (k + 1) * m, m, m) = -static_cast<double>(k + 1) * Eigen::MatrixXd::Identity(m, m);
    }
    polynomial_ = std::make_unique<Eigen::CompleteOrthogonalDecomposition<Eigen::MatrixXd>>(blocks);
  }
  Eigen::VectorXd rhs = Eigen::VectorXd::Zero(4 * m);
  rhs.head(m) = -c0;
  rhs.segment(m, m) = -c1;
  const Eigen::VectorXd z = polynomial_->solve(rhs);
  const double residual = (a_ * z.head(m) - z.segment(m, m) + c0).norm() +
                          (a_ * z.segment(m, m) - 2 * z.segment(2 * m, m) + c1).norm() +
                          (a_ * z.segment(2 * m, m) - 3 * z.segment(3 * m, m)).norm() + (a_ * z.tail(m)).norm();
  const double size = c0.norm() + c1.norm() + a_.norm() * z.norm();
  if (!(residual <= 1e-9 * size)) {
    throw SimulationError(fmt::format("exact integrator: a phase with a rigid-body mode has no polynomial "
                                      "particular solution (residual {:.3g} of {:.3g}); use integrator = \"newmark\"",
                                      residual, size),
                          StopReason::resonance);
  }
  for (Eigen::Index k = 0; k < 4; ++k) p[static_cast<std::size_t>(k)] = z.segment(k * m, m);
}

ExactPhase::ExactPhase(const LinearPhase& phase, const ExactPhaseTolerances& tolerances) : n_(phase.reduced_size()) {
  const Eigen::VectorXd inv_m = phase.mass().cwiseInverse();
  a_ = Eigen::MatrixXd::Zero(2 * n_, 2 * n_);
  a_.topRightCorner(n_, n_).setIdentity();
  a_.bottomLeftCorner(n_, n_) = -(inv_m.asDiagonal() * Eigen::MatrixXd(phase.stiffness()));
  a_.bottomRightCorner(n_, n_) = -(inv_m.asDiagonal() * Eigen::MatrixXd(phase.damping()));
  a_lu_.compute(a_);

  // Decompose the balanced Â = D⁻¹ A D, D = diag(1, ω_i) with ω_i = √(K_ii/M_ii): each velocity
  // measured in units of its own floor's frequency. Unbalanced, an oscillator of frequency ω has
  // the modes (1, ±iω)/‖·‖, nearly parallel when ω is large, so rcond(V) ~ 1/ω: a stiff neighbour
  // (a wall, 1e4 times the frequency of its frame) failed the conditioning test and sent the
  // phase to the matrix exponential, whose derivative bounds (‖A‖⁴ ~ ω⁸) then stalled the root
  // search. Balanced, the modes of well-separated oscillators are orthogonal whatever ω. A's
  // modes are V = D V̂ with the same eigenvalues; V⁻¹ r = V̂⁻¹ D⁻¹ r.
  scale_ = Eigen::VectorXd::Ones(2 * n_);
  for (Eigen::Index i = 0; i < n_; ++i) {
    const double omega2 = phase.stiffness().coeff(i, i) / phase.mass()(i);
    if (omega2 > 0 && std::isfinite(omega2)) scale_(n_ + i) = std::sqrt(omega2);
  }
  const Eigen::MatrixXd balanced =
      scale_.cwiseInverse().asDiagonal() * a_ * scale_.asDiagonal();
  // A rigid-body mode (K singular) makes A singular. Judged balanced: unbalanced, a stiff wall
  // beside a frame (‖A‖ ~ 1e14) has rcond(A) ~ 1e-14 with no rigid mode at all.
  singular_ = is_singular(balanced);
  Eigen::VectorXd e = Eigen::VectorXd::Zero(2 * n_);
  e.tail(n_).setConstant(-1.0);
  if (!singular_) a_inv_e_ = a_lu_.solve(e);
  // A singular phase is decomposed without its Jordan pairs (D⁻¹PAD) and its kernel set exactly.
  const RigidModes rigid = singular_ ? find_rigid_modes(phase, tolerances) : RigidModes{};
  const Eigen::MatrixXd projected =
      rigid.found ? projected_balanced(a_, rigid.undamped, phase.mass(), scale_) : Eigen::MatrixXd();
  const Eigen::EigenSolver<Eigen::MatrixXd> eig(rigid.found ? projected : balanced, true);
  if (eig.info() == Eigen::Success) {
    Eigen::VectorXcd values = eig.eigenvalues();
    Eigen::MatrixXcd vectors = eig.eigenvectors();
    const bool exact_kernel =
        rigid.found && set_exact_kernel(rigid, scale_, tolerances.kernel, values, vectors, jordan_columns_);
    mark_slow_modes(values, phase.step(), tolerances.slow_mode, slow_);
    if (!slow_.empty()) tie_slow_velocities(values, scale_, slow_, jordan_columns_, vectors);
    lambda_ = values;
    v_lu_.compute(vectors);
    v_ = scale_.cast<std::complex<double>>().asDiagonal() * vectors;
    modal_ = v_lu_.rcond() > kMinModeConditioning && (!singular_ || exact_kernel);
    if (modal_ && exact_kernel) {
      rigid_ = rigid.undamped;
      rigid_weights_ = rigid_.transpose() * phase.mass().asDiagonal();
      rigid_work_.resize(rigid_.cols());
      rigid_part_.resize(n_);
    } else {
      jordan_columns_.clear();
    }
    if (!modal_) slow_.clear();
    spectral_radius_ = lambda_.cwiseAbs().maxCoeff();
    conjugate_of_previous_.assign(static_cast<std::size_t>(lambda_.size()), false);
    for (Eigen::Index k = 1; k < lambda_.size(); ++k) {
      conjugate_of_previous_[static_cast<std::size_t>(k)] =
          lambda_(k).imag() != 0.0 && lambda_(k) == std::conj(lambda_(k - 1)) && !conjugate_of_previous_[static_cast<std::size_t>(k - 1)];
    }
  }
  if (!modal_) {
    // Only the matrix-exponential path bounds e^{As} by norms (the modal path bounds each mode
    // by its eigenvalue), and without eigenvalues ‖A‖₂ ≥ max |λ| stands for the fastest rate.
    // Bound the balanced Â, not A: for a contact spring k on a floor of mass m, ‖A‖ ~ k/m and
    // μ(A) ~ k/(2m) (e^{μs} of 1e10 within a millisecond), where ‖Â‖ ~ √(k/m) and μ(Â) is about
    // the damping; A's bounds made the root search of a free pair in contact (a near-defective
    // rigid mode) bisect to 1e-8 s and stall. e^{As} = D e^{Âs} D⁻¹, so the guard expansion
    // bounds r e^{As} h by ‖r D‖ ‖e^{Âs}‖ ‖D⁻¹ h‖.
    const Eigen::JacobiSVD<Eigen::MatrixXd> svd(balanced);
    norm_ = svd.singularValues()(0);
    const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> sym(0.5 * (balanced + balanced.transpose()),
                                                             Eigen::EigenvaluesOnly);
    log_norm_ = sym.eigenvalues().maxCoeff();
    spectral_radius_ = norm_;
  }
}

void ExactPhase::absorb_rigid_motion(Eigen::VectorXd& r, Eigen::VectorXd& p0, Eigen::VectorXd& p1) const {
  if (rigid_.cols() == 0) return;
  // d = (I − P) r = [N NᵀM r_q; N NᵀM r_v]: the homogeneous motion in J is d + s A d with
  // A d = [N NᵀM r_v; 0] (K N = C N = 0).
  for (const bool velocity : {false, true}) {
    auto part = velocity ? r.tail(n_) : r.head(n_);
    rigid_work_.noalias() = rigid_weights_ * part;
    rigid_part_.noalias() = rigid_ * rigid_work_;
    part -= rigid_part_;
    (velocity ? p0.tail(n_) : p0.head(n_)) += rigid_part_;
    if (velocity) p1.head(n_) += rigid_part_;
  }
}

Eigen::MatrixXd ExactPhase::rigid_rate(const Eigen::MatrixXd& r) const {
  // A(I − P) r = [N NᵀM r_v; 0].
  Eigen::MatrixXd out = Eigen::MatrixXd::Zero(r.rows(), r.cols());
  out.topRows(n_) = rigid_ * (rigid_weights_ * r.bottomRows(n_));
  return out;
}

void ExactPhase::exponentials(double s, Eigen::VectorXcd& out) const {
  out.resize(lambda_.size());
  for (Eigen::Index k = 0; k < lambda_.size(); ++k) {
    out(k) = conjugate_of_previous_[static_cast<std::size_t>(k)] ? std::conj(out(k - 1)) : complex_exp(lambda_(k) * s);
  }
}

void ExactPhase::modal_coordinates(const Eigen::VectorXd& r, Eigen::VectorXcd& scaled, Eigen::VectorXcd& out) const {
  scaled = r.cwiseQuotient(scale_).cast<std::complex<double>>();
  out = v_lu_.solve(scaled);
}

const Eigen::VectorXcd& ExactPhase::harmonic_response(double omega) const {
  using Complex = std::complex<double>;
  if (omega == harmonic_omega_) return harmonic_response_;
  // Solved balanced, D⁻¹(iωI − A)D ĥ = D⁻¹e, h = D ĥ: unbalanced, a stiff neighbour (‖A‖ ~ 10¹⁴
  // for a wall) makes rcond ~ ω/‖A‖ and would pass for a resonance.
  Eigen::MatrixXcd m = -(scale_.cwiseInverse().asDiagonal() * a_ * scale_.asDiagonal()).cast<Complex>();
  m.diagonal().array() += Complex(0.0, omega);
  harmonic_omega_ = std::numeric_limits<double>::quiet_NaN();  // the factorisation is another ω's now
  harmonic_rate_omega_ = std::numeric_limits<double>::quiet_NaN();
  harmonic_lu_.compute(m);
  const Eigen::PartialPivLU<Eigen::MatrixXcd>& lu = harmonic_lu_;
  if (!(lu.rcond() > 1e-13)) {
    throw SimulationError(fmt::format(
        "exact integrator: the forcing frequency {} rad/s is a natural frequency of an undamped "
        "phase, which has no bounded steady state; add damping or use integrator = \"newmark\"",
        omega), StopReason::resonance);
  }
  Eigen::VectorXcd e = Eigen::VectorXcd::Zero(2 * n_);
  e.tail(n_).setConstant(-1.0);
  harmonic_response_ = scale_.cast<Complex>().cwiseProduct(lu.solve(e.cwiseQuotient(scale_.cast<Complex>())));
  harmonic_omega_ = omega;
  return harmonic_response_;
}

const Eigen::VectorXcd& ExactPhase::harmonic_response_rate(double omega) const {
  using Complex = std::complex<double>;
  if (omega == harmonic_rate_omega_) return harmonic_response_rate_;
  const Eigen::VectorXcd& h = harmonic_response(omega);  // factorises D⁻¹(iωI − A)D at ω
  // d/dω of (iωI − A) h = e: (iωI − A) h' = −i h; balanced as harmonic_response solves.
  const Eigen::VectorXcd scale = scale_.cast<Complex>();
  harmonic_response_rate_ = scale.cwiseProduct(harmonic_lu_.solve(Complex(0.0, -1.0) * h.cwiseQuotient(scale)));
  harmonic_rate_omega_ = omega;
  return harmonic_response_rate_;
}

void ExactTrajectory::start(const ExactPhase& phase, const Eigen::VectorXd& mass,
                            const Eigen::VectorXd& constant_load, double t0,
                            const Eigen::VectorXd& x0, const ForcingPiece& piece) {
  phase_ = &phase;
  t0_ = t0;
  piece_ = piece;
  const Eigen::Index n = phase.groups();
  // Work vectors are members: a segment starts at every event, and allocates nothing.
  Eigen::VectorXd& f = load_;
  f.setZero(2 * n);
  f.tail(n) = constant_load.cwiseQuotient(mass);
  beta_.setZero(2 * n);
  quadratic_.setZero(2 * n);
  cubic_.setZero(2 * n);
  harmonic_.setZero(2 * n);
  if (phase.singular()) {
    // The polynomial part for c₀ + c₁s: f + e a₀ + e a₁ s on a linear piece, f on a harmonic one
    // (whose harmonic part is as below). e = [0; −1].
    Eigen::VectorXd c0 = f, c1 = Eigen::VectorXd::Zero(2 * n);
    if (piece.kind == ForcingPiece::Kind::linear) {
      c0.tail(n).array() -= piece.at(t0);
      c1.tail(n).setConstant(-piece.slope);
    }
    phase.polynomial_particular(c0, c1, polynomial_work_);
    xc_ = polynomial_work_[0];
    beta_ = polynomial_work_[1];
    quadratic_ = polynomial_work_[2];
    cubic_ = polynomial_work_[3];
  } else {
    phase.solve(f, xc_);
    xc_ = -xc_;
  }
  Eigen::VectorXd& x_p0 = particular_start_;
  x_p0 = xc_;
  if (phase.singular()) {
    if (piece.kind == ForcingPiece::Kind::harmonic) {
      harmonic_ = piece.amplitude * phase.harmonic_response(piece.omega);
      x_p0 += (harmonic_ * std::exp(std::complex<double>(0.0, piece.omega * t0))).imag();
    }
  } else if (piece.kind == ForcingPiece::Kind::linear) {
    // a_g = a₀ + a₁ s with s = t − t₀ (the piece may have started earlier).
    const double a0 = piece.at(t0), a1 = piece.slope;
    beta_ = -a1 * phase.ground_response();
    phase.solve(beta_, solved_);
    xc_ += solved_ - a0 * phase.ground_response();
    x_p0 = xc_;
  } else {
    harmonic_ = piece.amplitude * phase.harmonic_response(piece.omega);
    x_p0 += (harmonic_ * std::exp(std::complex<double>(0.0, piece.omega * t0))).imag();
  }
  r0_ = x0 - x_p0;
  if (phase.singular()) phase.absorb_rigid_motion(r0_, xc_, beta_);
  if (phase.modal()) {
    phase.modal_coordinates(r0_, scaled_start_, c_);
    for (const Eigen::Index k : phase.jordan_columns()) c_(k) = 0.0;  // (I − P) r₀ = 0
  }
  slow_constant_.resize(0);
  if (phase.modal() && !phase.slow_modes().empty()) {
    work_ = c_;
    for (Eigen::Index k = 0; k < c_.size(); ++k) {
      if (phase.slow_modes()[static_cast<std::size_t>(k)]) work_(k) = 0.0;
    }
    product_.noalias() = phase.modes() * work_;
    slow_constant_ = r0_ - product_.real();
  }
  increments_at_ = std::numeric_limits<double>::quiet_NaN();
  exponentials_at_ = std::numeric_limits<double>::quiet_NaN();
  work_.resize(2 * n);
  product_.resize(2 * n);
}

const Eigen::VectorXcd& ExactTrajectory::increments(double s) const {
  if (s != increments_at_) {
    const Eigen::VectorXcd& lambda = phase_->eigenvalues();
    const std::vector<bool>& slow = phase_->slow_modes();
    increments_.resize(lambda.size());
    for (Eigen::Index k = 0; k < lambda.size(); ++k) {
      increments_(k) = slow[static_cast<std::size_t>(k)] ? complex_expm1(lambda(k) * s) : 0.0;
    }
    increments_at_ = s;
  }
  return increments_;
}

void ExactTrajectory::add_slow_modal(double s, Eigen::VectorXd& x, Eigen::VectorXd* x_rate) const {
  const ExactPhase& ph = *phase_;
  const Eigen::VectorXcd& e = exponentials(s);
  const Eigen::VectorXcd& d = increments(s);
  for (Eigen::Index k = 0; k < c_.size(); ++k) work_(k) = (ph.slow_modes()[static_cast<std::size_t>(k)] ? d(k) : e(k)) * c_(k);
  product_.noalias() = ph.modes() * work_;
  x += slow_constant_;
  x += product_.real();
  if (x_rate != nullptr) {
    work_ = e.cwiseProduct(c_).cwiseProduct(ph.eigenvalues());
    product_.noalias() = ph.modes() * work_;
    *x_rate += product_.real();
  }
}

const Eigen::VectorXcd& ExactTrajectory::exponentials(double s) const {
  if (s != exponentials_at_) {
    phase_->exponentials(s, exponentials_);
    exponentials_at_ = s;
  }
  return exponentials_;
}

Eigen::MatrixXd ExactPhase::propagator(double s) const {
  if (!modal_) return (a_ * s).exp();
  Eigen::VectorXcd e;
  exponentials(s, e);
  Eigen::MatrixXd out = (v_ * e.asDiagonal() * inverse_modes()).real();
  // The Jordan pairs: V e^{Λs} V⁻¹ keeps (I − P) as it is (λ = 0); e^{As} adds s A(I − P).
  if (rigid_.cols() > 0) out += s * rigid_rate(Eigen::MatrixXd::Identity(2 * n_, 2 * n_));
  return out;
}

const Eigen::MatrixXcd& ExactPhase::inverse_modes() const {
  // V = D V̂ with V̂ factorised: V⁻¹ = V̂⁻¹ D⁻¹.
  if (inverse_modes_.size() == 0) {
    inverse_modes_ = v_lu_.solve(scale_.cwiseInverse().cast<std::complex<double>>().asDiagonal().toDenseMatrix());
  }
  return inverse_modes_;
}

void ExactPhase::keep_modes() const {
  if (!kept_modes_.empty()) return;
  const Eigen::MatrixXcd& inverse = inverse_modes();
  const Eigen::Index size = lambda_.size();
  std::vector<double> weight;
  for (Eigen::Index k = 0; k < size; ++k) {
    if (conjugate_of_previous_[static_cast<std::size_t>(k)]) continue;  // its pair's term, doubled
    const bool paired = k + 1 < size && conjugate_of_previous_[static_cast<std::size_t>(k + 1)];
    kept_modes_.push_back(k);
    weight.push_back(paired ? 2.0 : 1.0);
  }
  const auto kept = static_cast<Eigen::Index>(kept_modes_.size());
  kept_weight_ = Eigen::Map<const Eigen::VectorXd>(weight.data(), kept);
  kept_inverse_real_.resize(kept, size);
  kept_inverse_imag_.resize(kept, size);
  kept_real_.resize(size, kept);
  kept_imag_.resize(size, kept);
  for (Eigen::Index i = 0; i < kept; ++i) {
    const Eigen::Index k = kept_modes_[static_cast<std::size_t>(i)];
    kept_inverse_real_.row(i) = inverse.row(k).real();
    kept_inverse_imag_.row(i) = inverse.row(k).imag();
    kept_real_.col(i) = v_.col(k).real();
    kept_imag_.col(i) = v_.col(k).imag();
  }
}

void ExactPhase::project_modes(const Eigen::MatrixXd& r, Projection& projected) const {
  keep_modes();
  projected.real.noalias() = kept_inverse_real_ * r;
  projected.imag.noalias() = kept_inverse_imag_ * r;
  if (rigid_.cols() > 0) {
    projected.rigid_rate = rigid_rate(r);
  } else {
    projected.rigid_rate.resize(0, 0);
  }
}

void ExactPhase::propagate_projected(double s, const Projection& projected, Eigen::MatrixXd& out) const {
  const auto kept = static_cast<Eigen::Index>(kept_modes_.size());
  const Eigen::Index columns = projected.real.cols();
  projected_real_.resize(kept, columns);
  projected_imag_.resize(kept, columns);
  for (Eigen::Index i = 0; i < kept; ++i) {
    const std::complex<double> factor = kept_weight_(i) * complex_exp(lambda_(kept_modes_[static_cast<std::size_t>(i)]) * s);
    for (Eigen::Index c = 0; c < columns; ++c) {
      const std::complex<double> z = factor * std::complex<double>(projected.real(i, c), projected.imag(i, c));
      projected_real_(i, c) = z.real();
      projected_imag_(i, c) = z.imag();
    }
  }
  out.noalias() = kept_real_ * projected_real_;
  out.noalias() -= kept_imag_ * projected_imag_;
  if (projected.rigid_rate.size() > 0) out += s * projected.rigid_rate;
}

void ExactTrajectory::evaluate(double s, Eigen::VectorXd& x, Eigen::VectorXd& x_rate) const { evaluate(s, x, &x_rate); }

void ExactTrajectory::evaluate(double s, Eigen::VectorXd& x) const { evaluate(s, x, nullptr); }

void ExactTrajectory::evaluate(double s, Eigen::VectorXd& x, Eigen::VectorXd* x_rate) const {
  using Complex = std::complex<double>;
  const ExactPhase& ph = *phase_;
  // x is computed by the same operations whether or not the rate is wanted: the two overloads
  // agree bit for bit on x.
  x = xc_ + s * beta_;
  if (x_rate != nullptr) *x_rate = beta_;
  if (ph.singular()) {
    x += (s * s) * quadratic_ + (s * s * s) * cubic_;
    if (x_rate != nullptr) *x_rate += (2 * s) * quadratic_ + (3 * s * s) * cubic_;
  }
  if (piece_.kind == ForcingPiece::Kind::harmonic) {
    const Complex phase_factor = complex_exp(Complex(0.0, piece_.omega * (t0_ + s)));
    const double sine = phase_factor.imag(), cosine = phase_factor.real(), w = piece_.omega;
    // Im(h e^{iφ}) = Re h sin φ + Im h cos φ, and its rate ω (Re h cos φ − Im h sin φ).
    x += sine * harmonic_.real() + cosine * harmonic_.imag();
    if (x_rate != nullptr) *x_rate += (w * cosine) * harmonic_.real() - (w * sine) * harmonic_.imag();
  }
  if (ph.modal() && !ph.slow_modes().empty()) {
    add_slow_modal(s, x, x_rate);
  } else if (ph.modal()) {
    work_ = exponentials(s).cwiseProduct(c_);
    product_.noalias() = ph.modes() * work_;
    x += product_.real();
    if (x_rate != nullptr) {
      work_.array() *= ph.eigenvalues().array();
      product_.noalias() = ph.modes() * work_;
      *x_rate += product_.real();
    }
  } else {
    const Eigen::MatrixXd propagator = (ph.matrix() * s).exp();
    const Eigen::VectorXd h = propagator * r0_;
    x += h;
    if (x_rate != nullptr) x_rate->noalias() += ph.matrix() * h;
  }
}

}  // namespace poundsim
