#include "poundsim/exact_energy.hpp"

#include <array>
#include <cmath>
#include <utility>

namespace poundsim {

namespace {

using Complex = std::complex<double>;

constexpr std::array<double, 32> inverse_factorials = [] {
  std::array<double, 32> out{};
  double f = 1.0;
  for (std::size_t k = 0; k < out.size(); ++k) {
    if (k > 0) f *= static_cast<double>(k);
    out[k] = 1.0 / f;
  }
  return out;
}();

/// φ₁(z), φ₂(z), φ₃(z) from e^z. Near z = 0 the differences e^z − 1 − … cancel, so there the
/// Taylor series is summed instead (enough terms that the first left out is below 1e-17 of φ).
std::array<Complex, 3> phi(Complex z, Complex exp_z) {
  const double r = std::abs(z);
  if (r >= 2.0) {
    const Complex phi1 = (exp_z - 1.0) / z;
    const Complex phi2 = (phi1 - 1.0) / z;
    return {phi1, phi2, (phi2 - 0.5) / z};
  }
  const int terms = r < 0.01 ? 6 : r < 0.25 ? 12 : 22;
  Complex phi3 = inverse_factorials[static_cast<std::size_t>(terms + 3)];
  for (int j = terms - 1; j >= 0; --j) phi3 = phi3 * z + inverse_factorials[static_cast<std::size_t>(j + 3)];
  const Complex phi2 = 0.5 + z * phi3;
  return {1.0 + z * phi2, phi2, phi3};
}

/// ∫_a^{a+h} s^d e^{μs} ds given e^{μa} and e^{μh}. With s = b − σ, b = a + h, and
/// ∫_0^h σ^l e^{μ(h−σ)} dσ = l! h^{l+1} φ_{l+1}(μh):
///     ∫_a^b s^d e^{μs} ds = e^{μa} Σ_{l≤d} C(d,l) (−1)^l b^{d−l} l! h^{l+1} φ_{l+1}(μh).
Complex moment(int degree, Complex mu, double a, double h, Complex exp_mu_a, Complex exp_mu_h) {
  const auto [phi1, phi2, phi3] = phi(mu * h, exp_mu_h);
  const double b = a + h;
  switch (degree) {
    case 0: return exp_mu_a * (h * phi1);
    case 1: return exp_mu_a * (b * h * phi1 - h * h * phi2);
    default: return exp_mu_a * (b * b * h * phi1 - 2 * b * h * h * phi2 + 2 * h * h * h * phi3);
  }
}

}  // namespace

Complex exponential_moment(int degree, Complex mu, double a, double h) {
  return moment(degree, mu, a, h, std::exp(mu * a), std::exp(mu * h));
}

ExactPowerIntegrals::ExactPowerIntegrals(const ExactPhase& phase, PowerForms forms)
    : phase_(&phase), forms_(std::move(forms)) {
  const Eigen::Index n = phase.groups();
  const Eigen::MatrixXcd w = phase.modes().bottomRows(n);
  modal_storey_ = w.transpose() * forms_.storey_damping * w;
  modal_gap_ = w.transpose() * forms_.gap_damping * w;
  modal_mass_ = forms_.mass.transpose() * w;
}

void ExactPowerIntegrals::start(const ExactTrajectory& trajectory) {
  const Eigen::Index n = phase_->groups(), modes = 2 * n;
  const ForcingPiece& piece = trajectory.piece();
  const bool harmonic = piece.kind == ForcingPiece::Kind::harmonic;
  const Eigen::VectorXcd& c = trajectory.modal_coefficients();

  // The terms of q̇ that are not modes: u₀, s u₁ and, on a harmonic piece, Im(z e^{iω̄s}) =
  // (z e^{iω̄s} − z̄ e^{−iω̄s}) / 2i with z = h_v e^{iω̄t₀}.
  const Eigen::Index extras = harmonic ? 4 : 2;
  Eigen::MatrixXcd& x = extra_terms_;
  x.resize(n, extras);
  x.col(0) = trajectory.constant_part().tail(n).cast<Complex>();
  x.col(1) = trajectory.linear_part().tail(n).cast<Complex>();
  const Eigen::Index terms = modes + extras;
  mu_.assign(static_cast<std::size_t>(terms), Complex(0.0));
  degree_.assign(static_cast<std::size_t>(terms), 0);
  for (Eigen::Index k = 0; k < modes; ++k) mu_[static_cast<std::size_t>(k)] = phase_->eigenvalues()(k);
  degree_[static_cast<std::size_t>(modes + 1)] = 1;
  if (harmonic) {
    const Complex rotation = std::exp(Complex(0.0, piece.omega * trajectory.start_time()));
    x.col(2) = trajectory.harmonic_part().tail(n) * (rotation / Complex(0.0, 2.0));
    x.col(3) = x.col(2).conjugate();
    mu_[static_cast<std::size_t>(modes + 2)] = Complex(0.0, piece.omega);
    mu_[static_cast<std::size_t>(modes + 3)] = Complex(0.0, -piece.omega);
  }

  // Pair coefficients g_iᵀ C g_j of each quadratic form, i ≤ j, doubled for i < j.
  const auto w = phase_->modes().bottomRows(n);
  const auto pairs = [&](const Eigen::MatrixXd& form, const Eigen::MatrixXcd& modal, Eigen::MatrixXcd& out) {
    out.setZero(terms, terms);
    for (Eigen::Index j = 0; j < modes; ++j) {
      for (Eigen::Index i = 0; i <= j; ++i) out(i, j) = (i == j ? 1.0 : 2.0) * c(i) * c(j) * modal(i, j);
    }
    form_x_.noalias() = form * x;
    cross_.noalias() = form_x_.transpose() * w;  // x_eᵀ C W_k
    extra_.noalias() = x.transpose() * form_x_;  // x_eᵀ C x_f
    for (Eigen::Index e = 0; e < extras; ++e) {
      for (Eigen::Index k = 0; k < modes; ++k) out(k, modes + e) = 2.0 * cross_(e, k) * c(k);
      for (Eigen::Index f = 0; f <= e; ++f) out(modes + f, modes + e) = (e == f ? 1.0 : 2.0) * extra_(f, e);
    }
  };
  pairs(forms_.storey_damping, modal_storey_, pair_storey_);
  pairs(forms_.gap_damping, modal_gap_, pair_gap_);

  // Input −a_g m_rᵀq̇: a_g = α₀ + α₁ s on a linear piece, or A sin ω̄(t₀ + s) = Im(w e^{iω̄s}),
  // w = A e^{iω̄t₀}, as two exponentials.
  std::array<InputTerm, 2> ground{};
  if (harmonic) {
    const Complex half = piece.amplitude * std::exp(Complex(0.0, piece.omega * trajectory.start_time())) /
                         Complex(0.0, 2.0);
    ground = {InputTerm{half, Complex(0.0, piece.omega), 0}, InputTerm{std::conj(half), Complex(0.0, -piece.omega), 0}};
  } else {
    ground = {InputTerm{piece.at(trajectory.start_time()), 0.0, 0}, InputTerm{piece.slope, 0.0, 1}};
  }
  extra_mass_.noalias() = forms_.mass.transpose().cast<Complex>() * x;
  input_.clear();
  for (const InputTerm& a : ground) {
    for (Eigen::Index k = 0; k < terms; ++k) {
      const Complex m = k < modes ? modal_mass_(k) * c(k) : extra_mass_(k - modes);
      input_.push_back({-a.coefficient * m, a.mu + mu_[static_cast<std::size_t>(k)],
                        a.degree + degree_[static_cast<std::size_t>(k)]});
    }
  }
  start_factor_.resize(static_cast<std::size_t>(terms));
  step_factor_.resize(static_cast<std::size_t>(terms));
}

EnergyMeter::Powers ExactPowerIntegrals::integrate(double a, double b) const {
  const double h = b - a;
  const std::size_t terms = mu_.size();
  for (std::size_t i = 0; i < terms; ++i) {
    start_factor_[i] = std::exp(mu_[i] * a);
    step_factor_[i] = std::exp(mu_[i] * h);
  }
  Complex storey = 0.0, gap = 0.0, input = 0.0;
  for (std::size_t j = 0; j < terms; ++j) {
    for (std::size_t i = 0; i <= j; ++i) {
      const auto ii = static_cast<Eigen::Index>(i), jj = static_cast<Eigen::Index>(j);
      const Complex ps = pair_storey_(ii, jj), pg = pair_gap_(ii, jj);
      if (ps == 0.0 && pg == 0.0) continue;
      const Complex m = moment(degree_[i] + degree_[j], mu_[i] + mu_[j], a, h,
                               start_factor_[i] * start_factor_[j], step_factor_[i] * step_factor_[j]);
      storey += ps * m;
      gap += pg * m;
    }
  }
  for (const InputTerm& t : input_) {
    if (t.coefficient == 0.0) continue;
    input += t.coefficient * moment(t.degree, t.mu, a, h, std::exp(t.mu * a), std::exp(t.mu * h));
  }
  return {.input = input.real(), .storey_damping = storey.real(), .gap_damping = gap.real()};
}

}  // namespace poundsim
