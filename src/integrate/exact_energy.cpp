#include "poundsim/integrate/exact_energy.hpp"

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

/// Taylor terms of φ_k beyond which the first left out is below 1e-17 of φ_k, for |z| < 2, by
/// |z|² (std::abs would cost a hypot per pair, a quarter of a step).
int series_terms(double r2) {
  return r2 < 1e-6 ? 4 : r2 < 1e-4 ? 6 : r2 < 1e-2 ? 9 : r2 < 0.0625 ? 12 : r2 < 0.25 ? 14 : r2 < 1.0 ? 17 : 22;
}

/// φ₁(z) = (e^z − 1)/z from e^z; near z = 0, where e^z − 1 cancels, by its Taylor series.
Complex phi1(Complex z, Complex exp_z) {
  const double r2 = std::norm(z);
  if (r2 >= 4.0) return (exp_z - 1.0) / z;
  const int terms = series_terms(r2);
  Complex sum = inverse_factorials[static_cast<std::size_t>(terms + 1)];
  for (int j = terms - 1; j >= 0; --j) sum = sum * z + inverse_factorials[static_cast<std::size_t>(j + 1)];
  return sum;
}

/// φ₁(z) … φ₄(z) from e^z, by the same rule (for the cubic moments alone: phi's φ₁ … φ₃ keep
/// their own operations).
std::array<Complex, 4> phi_to_4(Complex z, Complex exp_z) {
  const double r2 = std::norm(z);
  if (r2 >= 4.0) {
    const Complex p1 = (exp_z - 1.0) / z;
    const Complex p2 = (p1 - 1.0) / z;
    const Complex p3 = (p2 - 0.5) / z;
    return {p1, p2, p3, (p3 - 1.0 / 6.0) / z};
  }
  const int terms = series_terms(r2);
  Complex p4 = inverse_factorials[static_cast<std::size_t>(terms + 4)];
  for (int j = terms - 1; j >= 0; --j) p4 = p4 * z + inverse_factorials[static_cast<std::size_t>(j + 4)];
  const Complex p3 = 1.0 / 6.0 + z * p4;
  const Complex p2 = 0.5 + z * p3;
  return {1.0 + z * p2, p2, p3, p4};
}

/// φ₁(z), φ₂(z), φ₃(z) from e^z, by the same rule.
std::array<Complex, 3> phi(Complex z, Complex exp_z) {
  const double r2 = std::norm(z);
  if (r2 >= 4.0) {
    const Complex p1 = (exp_z - 1.0) / z;
    const Complex p2 = (p1 - 1.0) / z;
    return {p1, p2, (p2 - 0.5) / z};
  }
  const int terms = series_terms(r2);
  Complex p3 = inverse_factorials[static_cast<std::size_t>(terms + 3)];
  for (int j = terms - 1; j >= 0; --j) p3 = p3 * z + inverse_factorials[static_cast<std::size_t>(j + 3)];
  const Complex p2 = 0.5 + z * p3;
  return {1.0 + z * p2, p2, p3};
}

/// ∫_a^{a+h} s^d e^{μs} ds given e^{μa} and e^{μh}. With s = b − σ, b = a + h, and
/// ∫_0^h σ^l e^{μ(h−σ)} dσ = l! h^{l+1} φ_{l+1}(μh):
///     ∫_a^b s^d e^{μs} ds = e^{μa} Σ_{l≤d} C(d,l) (−1)^l b^{d−l} l! h^{l+1} φ_{l+1}(μh).
Complex moment(int degree, Complex mu, double a, double h, Complex exp_mu_a, Complex exp_mu_h) {
  if (degree == 0) return exp_mu_a * (h * phi1(mu * h, exp_mu_h));
  if (degree == 3) {
    const auto [p1, p2, p3, p4] = phi_to_4(mu * h, exp_mu_h);
    const double b = a + h;
    return exp_mu_a * (b * b * b * h * p1 - 3 * b * b * h * h * p2 + 6 * b * h * h * h * p3 - 6 * h * h * h * h * p4);
  }
  const auto [p1, p2, p3] = phi(mu * h, exp_mu_h);
  const double b = a + h;
  if (degree == 1) return exp_mu_a * (b * h * p1 - h * h * p2);
  return exp_mu_a * (b * b * h * p1 - 2 * b * h * h * p2 + 2 * h * h * h * p3);
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
  complex_mass_transposed_ = forms_.mass.transpose().cast<Complex>();
  gap_active_ = forms_.gap_damping.cwiseAbs().maxCoeff() > 0.0;
}

void ExactPowerIntegrals::start(const ExactTrajectory& trajectory) {
  const Eigen::Index n = phase_->groups(), modes = 2 * n;
  const Eigen::VectorXcd& lambda = phase_->eigenvalues();
  const ForcingPiece& piece = trajectory.piece();
  const bool harmonic = piece.kind == ForcingPiece::Kind::harmonic;
  const double omega = harmonic ? piece.omega : 0.0;
  c_ = trajectory.modal_coefficients();

  // The terms of q̇ that are not modes: u₀, s u₁, on a singular phase s² u₂ and, on a harmonic
  // piece, Im(z e^{iω̄s}) = (z e^{iω̄s} − z̄ e^{−iω̄s}) / 2i with z = h_v e^{iω̄t₀}. u₂ lies in the
  // undamped rigid modes (exact_phase.hpp: p₂ is in the generalised kernel of A, whose velocities
  // are N), so C u₂ = 0: it enters the input alone. q̇'s s³ term is zero (p₃ is in A's kernel).
  const Eigen::Index polynomial = phase_->singular() ? 3 : 2;
  const Eigen::Index extras = polynomial + (harmonic ? 2 : 0);
  const int one = static_cast<int>(modes), plus = one + 1, minus = one + 2;  // factor ids
  Eigen::MatrixXcd& x = extra_terms_;
  x.resize(n, extras);
  x.col(0) = trajectory.constant_part().tail(n).cast<Complex>();
  x.col(1) = trajectory.linear_part().tail(n).cast<Complex>();
  extra_mu_.assign(static_cast<std::size_t>(extras), Complex(0.0));
  extra_degree_.assign(static_cast<std::size_t>(extras), 0);
  extra_factor_.assign(static_cast<std::size_t>(extras), one);
  extra_degree_[1] = 1;
  if (polynomial == 3) {
    x.col(2) = trajectory.quadratic_part().tail(n).cast<Complex>();
    extra_degree_[2] = 2;
  }
  if (harmonic) {
    const Eigen::Index h = polynomial;
    const auto uh = static_cast<std::size_t>(h);
    const Complex rotation = std::exp(Complex(0.0, omega * trajectory.start_time()));
    x.col(h) = trajectory.harmonic_part().tail(n) * (rotation / Complex(0.0, 2.0));
    x.col(h + 1) = x.col(h).conjugate();
    extra_mu_[uh] = Complex(0.0, omega);
    extra_mu_[uh + 1] = Complex(0.0, -omega);
    extra_factor_[uh] = plus;
    extra_factor_[uh + 1] = minus;
  }
  const auto undamped = [&](Eigen::Index e) { return extra_degree_[static_cast<std::size_t>(e)] == 2; };

  const auto w = phase_->modes().bottomRows(n);
  const auto cross = [&](const Eigen::MatrixXd& form, Eigen::MatrixXcd& with_modes, Eigen::MatrixXcd& among) {
    form_x_.noalias() = form * x;
    with_modes.noalias() = form_x_.transpose() * w;  // x_eᵀ C W_k
    among.noalias() = x.transpose() * form_x_;       // x_eᵀ C x_f
  };
  cross(forms_.storey_damping, cross_storey_, among_storey_);
  cross(forms_.gap_damping, cross_gap_, among_gap_);
  extra_mass_.noalias() = complex_mass_transposed_ * x;

  terms_.clear();
  for (Eigen::Index e = 0; e < extras; ++e) {
    if (undamped(e)) continue;  // no dashpot power
    const auto ue = static_cast<std::size_t>(e);
    for (Eigen::Index k = 0; k < modes; ++k) {
      terms_.push_back({lambda(k) + extra_mu_[ue], extra_degree_[ue], static_cast<int>(k), extra_factor_[ue],
                        2.0 * cross_storey_(e, k) * c_(k), 2.0 * cross_gap_(e, k) * c_(k), 0.0});
    }
    for (Eigen::Index f = 0; f <= e; ++f) {
      if (undamped(f)) continue;
      const auto uf = static_cast<std::size_t>(f);
      const double twice = e == f ? 1.0 : 2.0;
      terms_.push_back({extra_mu_[ue] + extra_mu_[uf], extra_degree_[ue] + extra_degree_[uf], extra_factor_[ue],
                        extra_factor_[uf], twice * among_storey_(f, e), twice * among_gap_(f, e), 0.0});
    }
  }
  // Input −a_g m_rᵀq̇: a_g = α₀ + α₁ s on a linear piece, or A sin ω̄(t₀ + s) = Im(w e^{iω̄s}),
  // w = A e^{iω̄t₀}, as two exponentials; times each term of m_rᵀq̇.
  struct Ground {
    Complex coefficient, mu;
    int degree, factor;
  };
  std::array<Ground, 2> ground{};
  if (harmonic) {
    const Complex half = piece.amplitude * std::exp(Complex(0.0, omega * trajectory.start_time())) /
                         Complex(0.0, 2.0);
    ground = {Ground{half, Complex(0.0, omega), 0, plus}, Ground{std::conj(half), Complex(0.0, -omega), 0, minus}};
  } else {
    ground = {Ground{piece.at(trajectory.start_time()), 0.0, 0, one}, Ground{piece.slope, 0.0, 1, one}};
  }
  for (const Ground& a : ground) {
    for (Eigen::Index k = 0; k < modes; ++k) {
      terms_.push_back({a.mu + lambda(k), a.degree, a.factor, static_cast<int>(k), 0.0, 0.0,
                        -a.coefficient * modal_mass_(k) * c_(k)});
    }
    for (Eigen::Index e = 0; e < extras; ++e) {
      const auto ue = static_cast<std::size_t>(e);
      terms_.push_back({a.mu + extra_mu_[ue], a.degree + extra_degree_[ue], a.factor, extra_factor_[ue], 0.0,
                        0.0, -a.coefficient * extra_mass_(e)});
    }
  }
  const std::pair<double, std::size_t> signature{omega, terms_.size()};
  if (signature != signature_) cached_step_ = -1.0;  // other exponents: the kept weights are stale
  signature_ = signature;
  start_factor_.resize(modes + 3);
  step_factor_.resize(modes + 3);
  advanced_.resize(modes);
  product_.resize(modes);
}

void ExactPowerIntegrals::factors(double a, double h) const {
  const Eigen::VectorXcd& lambda = phase_->eigenvalues();
  const Eigen::Index modes = lambda.size();
  for (Eigen::Index k = 0; k < modes; ++k) {
    start_factor_(k) = std::exp(lambda(k) * a);
    step_factor_(k) = std::exp(lambda(k) * h);
  }
  const Complex start = std::polar(1.0, signature_.first * a), step = std::polar(1.0, signature_.first * h);
  start_factor_.tail(3) << 1.0, start, std::conj(start);
  step_factor_.tail(3) << 1.0, step, std::conj(step);
}

namespace {
/// p_l = l! h^{l+1} φ_{l+1}(μh), l = 0 … degree (the rest 0).
std::array<Complex, 4> step_weights(int degree, Complex mu, double h, Complex exp_mu_h) {
  if (degree == 0) return {h * phi1(mu * h, exp_mu_h), 0.0, 0.0, 0.0};
  if (degree == 3) {
    const auto [p1, p2, p3, p4] = phi_to_4(mu * h, exp_mu_h);
    return {h * p1, h * h * p2, 2 * h * h * h * p3, 6 * h * h * h * h * p4};
  }
  const auto [p1, p2, p3] = phi(mu * h, exp_mu_h);
  return {h * p1, h * h * p2, 2 * h * h * h * p3, 0.0};
}

/// ∫_a^b s^d e^{μs} ds from e^{μa} and the step weights (moment() above, with b = a + h).
Complex from_weights(int degree, double b, Complex exp_mu_a, const std::array<Complex, 4>& p) {
  if (degree == 0) return exp_mu_a * p[0];
  if (degree == 1) return exp_mu_a * (b * p[0] - p[1]);
  if (degree == 3) return exp_mu_a * (b * b * b * p[0] - 3 * b * b * p[1] + 3 * b * p[2] - p[3]);
  return exp_mu_a * (b * b * p[0] - 2 * b * p[1] + p[2]);
}
}  // namespace

void ExactPowerIntegrals::weigh(double h) const {
  const Eigen::Index modes = c_.size();
  weighted_storey_.resize(modes, modes);
  weighted_gap_.resize(modes, modes);
  const Eigen::VectorXcd& lambda = phase_->eigenvalues();
  for (Eigen::Index j = 0; j < modes; ++j) {
    for (Eigen::Index i = 0; i <= j; ++i) {
      const Complex weight = h * phi1((lambda(i) + lambda(j)) * h, step_factor_(i) * step_factor_(j));
      weighted_storey_(i, j) = weighted_storey_(j, i) = modal_storey_(i, j) * weight;
      weighted_gap_(i, j) = weighted_gap_(j, i) = modal_gap_(i, j) * weight;
    }
  }
  term_weights_.resize(terms_.size());
  for (std::size_t t = 0; t < terms_.size(); ++t) {
    const Term& term = terms_[t];
    term_weights_[t] = step_weights(term.degree, term.mu, h, step_factor_(term.first) * step_factor_(term.second));
  }
  cached_step_ = h;
}

EnergyMeter::Powers ExactPowerIntegrals::integrate(double a, double b) const {
  const double h = b - a;
  const Eigen::VectorXcd& lambda = phase_->eigenvalues();
  const Eigen::Index modes = c_.size();
  factors(a, h);
  advanced_ = start_factor_.head(modes).cwiseProduct(c_);  // e^{Λa} c

  // A step within 1e-13 of the kept length (the grid step, up to the round-off of b − a) uses the
  // kept weights; a length seen twice in a row becomes the kept one.
  const auto same = [h](double other) { return std::abs(h - other) <= 1e-13 * h; };
  if (!same(cached_step_) && same(last_step_)) weigh(h);
  last_step_ = h;
  const bool cached = same(cached_step_);

  // Modal block: Σ_ij (e^{λ_i a} c_i) C_ij h φ₁((λ_i+λ_j)h) (e^{λ_j a} c_j).
  Complex storey = 0.0, gap = 0.0, input = 0.0;
  if (cached) {
    product_.noalias() = weighted_storey_ * advanced_;
    storey = advanced_.transpose() * product_;
    if (gap_active_) {
      product_.noalias() = weighted_gap_ * advanced_;
      gap = advanced_.transpose() * product_;
    }
  } else {
    for (Eigen::Index j = 0; j < modes; ++j) {
      for (Eigen::Index i = 0; i <= j; ++i) {
        const Complex weight = (i == j ? h : 2 * h) * advanced_(i) * advanced_(j) *
                               phi1((lambda(i) + lambda(j)) * h, step_factor_(i) * step_factor_(j));
        storey += modal_storey_(i, j) * weight;
        if (gap_active_) gap += modal_gap_(i, j) * weight;
      }
    }
  }
  for (std::size_t t = 0; t < terms_.size(); ++t) {
    const Term& term = terms_[t];
    if (term.storey == 0.0 && term.gap == 0.0 && term.input == 0.0) continue;
    const Complex exp_mu_a = start_factor_(term.first) * start_factor_(term.second);
    const Complex m =
        cached ? from_weights(term.degree, b, exp_mu_a, term_weights_[t])
               : moment(term.degree, term.mu, a, h, exp_mu_a, step_factor_(term.first) * step_factor_(term.second));
    storey += term.storey * m;
    gap += term.gap * m;
    input += term.input * m;
  }
  return {.input = input.real(), .storey_damping = storey.real(), .gap_damping = gap.real()};
}

}  // namespace poundsim
