#include "poundsim/integrate/guard_expansion.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <utility>

#include <unsupported/Eigen/MatrixFunctions>

#include "hermite_cubic.hpp"
#include "poundsim/integrate/bracketed_roots.hpp"
#include "poundsim/error.hpp"

namespace poundsim {

namespace {
using Complex = std::complex<double>;

double power(double x, int order) {
  double p = 1.0;
  for (int i = 0; i < order; ++i) p *= x;
  return p;
}
}  // namespace

GuardRows::GuardRows(Eigen::MatrixXd rows, const ExactPhase& phase)
    : real(std::move(rows)), complex(real.cast<Complex>()) {
  if (phase.modal()) {
    modal = complex * phase.modes();
    modal_size = modal.cwiseAbs();
    // |λ_k|^p for the bounds' orders p = 0 … 4 (by power(), the products the bounds took).
    const Eigen::Index modes = phase.eigenvalues().size();
    rate_powers.resize(modes, kBoundOrders);
    for (Eigen::Index k = 0; k < modes; ++k) {
      const double size = std::abs(phase.eigenvalues()(k));
      for (int p = 0; p < kBoundOrders; ++p) rate_powers(k, p) = power(size, p);
    }
  }
}

void GuardExpansion::build(const ExactTrajectory& trajectory, const GuardRows& guard_rows,
                           std::span<const double> at_start, std::span<const double> memory_amplitude,
                           std::span<const double> memory_rate) {
  const Eigen::MatrixXd& rows = guard_rows.real;
  trajectory_ = &trajectory;
  const ExactPhase& phase = trajectory.phase();
  const Eigen::Index g = rows.rows();
  remembered_.assign(static_cast<std::size_t>(g), {});
  active_.assign(static_cast<std::size_t>(g), false);
  Eigen::VectorXd& x0 = start_state_;  // a member: a segment starts at every event
  trajectory.evaluate(0.0, x0);
  memory_ = Eigen::Map<const Eigen::VectorXd>(memory_amplitude.data(), g);
  memory_rate_ = Eigen::Map<const Eigen::VectorXd>(memory_rate.data(), g);
  // κ from the start: g(0) = R x₀ + κ − m; the expansion's constant collects κ, R x_c and m.
  constant_.noalias() = rows * trajectory.constant_part();
  constant_ += memory_;
  for (Eigen::Index j = 0; j < g; ++j) {
    const double start = at_start[static_cast<std::size_t>(j)];
    active_[static_cast<std::size_t>(j)] = std::isfinite(start);
    constant_(j) += std::isfinite(start) ? start - rows.row(j).dot(x0) : 0.0;
  }
  slope_.noalias() = rows * trajectory.linear_part();
  if (phase.singular()) {
    quadratic_ = rows * trajectory.quadratic_part();
    cubic_ = rows * trajectory.cubic_part();
  } else {
    quadratic_.resize(0);
    cubic_.resize(0);
  }
  harmonic_.noalias() = guard_rows.complex * trajectory.harmonic_part();
  harmonic_size_ = harmonic_.cwiseAbs();
  slow_ = phase.modal() && !phase.slow_modes().empty();
  if (phase.modal()) {
    // γ = R V diag(c), taken for the kept modes alone.
    const Eigen::VectorXcd& c = trajectory.modal_coefficients();
    const std::vector<Eigen::Index>& kept = phase.kept_modes();
    // Sized as γ (the kept count varies between phases of one size: a phase with real modes
    // keeps more), so that a new segment of a known size allocates nothing; the first columns used.
    kept_modal_.resize(g, c.size());
    for (std::size_t i = 0; i < kept.size(); ++i) {
      const auto column = static_cast<Eigen::Index>(i);
      const Eigen::Index k = kept[i];
      kept_modal_.col(column) = guard_rows.modal.col(k) * c(k);
      if (phase.paired(i)) kept_modal_.col(column) += (guard_rows.modal.col(k + 1) * c(k + 1)).conjugate();
    }
    growth_a_ = growth_b_ = std::numeric_limits<double>::quiet_NaN();
    growth_.resize(phase.eigenvalues().size());
    // |γ_jk| = |R V|_jk |c_k|: the phase's sizes times the segment's, one hypot per mode.
    coefficient_size_ = trajectory.modal_coefficients().cwiseAbs();
    modal_size_.noalias() = guard_rows.modal_size * coefficient_size_.asDiagonal();
    rate_powers_ = &guard_rows.rate_powers;
  } else {
    rows_ = rows;
    row_norm_ = rows.rowwise().norm();
    balanced_row_norm_.resize(g);
    for (Eigen::Index j = 0; j < g; ++j)
      balanced_row_norm_(j) = rows.row(j).cwiseProduct(phase.scale().transpose()).norm();
    balanced_start_norm_ = trajectory.homogeneous_start().cwiseQuotient(phase.scale()).norm();
  }
  // At s = 0 each expansion returns the start value itself rather than its sum (which differs
  // from it by round-off), so a guard that starts a segment exactly at zero (just biased after an
  // impact) cannot fire again at once through the last bit of a sum.
  start_ = Eigen::Map<const Eigen::VectorXd>(at_start.data(), g);
  // Each value is a sum of terms much larger than itself near a root; its round-off is a few ulps
  // of their sizes. Shift every guard down by that much, so that only a crossing the sum can
  // resolve counts (a pair just bounced off the stop must not "cross" again in the noise of its
  // first femtoseconds).
  constexpr double eps = std::numeric_limits<double>::epsilon();
  if (slow_) add_slow_constant(trajectory, rows);
  for (Eigen::Index j = 0; j < g; ++j) {
    if (!active_[static_cast<std::size_t>(j)]) continue;
    double size = std::abs(constant_(j)) + std::abs(harmonic_(j)) + std::abs(memory_(j));
    if (slow_) {
      // A slow mode's term γ(e^{λs} − 1) is at most |γ λ| s (Re λ ≤ 0): its round-off grows
      // from zero, a margin in the slope rather than the constant.
      const auto [fast, rate] = slow_sizes(j);
      size += fast;
      slope_(j) -= 16 * eps * rate;
    } else if (phase.modal()) {
      size += modal_size_.row(j).sum();  // |γ_jk|, taken once above
    } else {
      size += row_norm_(j) * trajectory.homogeneous_start().norm();
    }
    const double noise = 16 * eps * size;
    constant_(j) -= noise;
    start_(j) -= noise;
  }
}

void GuardExpansion::add_slow_constant(const ExactTrajectory& trajectory, const Eigen::MatrixXd& rows) {
  // Re Σ_slow γ_jk = R_j Σ_slow V_k c_k: the slow modes' constant, from the trajectory's.
  constant_.noalias() += rows * trajectory.slow_constant();
}

std::pair<double, double> GuardExpansion::slow_sizes(Eigen::Index j) const {
  const ExactPhase& phase = trajectory_->phase();
  double fast = 0.0, rate = 0.0;
  for (Eigen::Index k = 0; k < modal_size_.cols(); ++k) {
    if (phase.slow_modes()[static_cast<std::size_t>(k)]) {
      rate += modal_size_(j, k) * std::abs(phase.eigenvalues()(k));
    } else {
      fast += modal_size_(j, k);
    }
  }
  return {fast, rate};
}

std::pair<double, double> GuardExpansion::value_and_rate(int j, double s) const {
  auto& slots = remembered_[static_cast<std::size_t>(j)];
  for (const Remembered& r : slots) {
    if (r.s == s) return {r.value, r.rate};
  }
  const auto [g, d] = compute(j, s);
  slots[1] = slots[0];
  slots[0] = Remembered{s, g, d};
  return {g, d};
}

std::pair<double, double> GuardExpansion::compute(int j, double s) const {
  const ExactTrajectory& tr = *trajectory_;
  // e^{−0·s} = 1 exactly: no exponential for the guards without a relaxing end (nearly all).
  const double decay = memory_rate_(j) != 0.0 ? std::exp(-memory_rate_(j) * s) : 1.0;
  double g = constant_(j) + slope_(j) * s - memory_(j) * decay;
  double d = slope_(j) + memory_(j) * memory_rate_(j) * decay;
  if (quadratic_.size() > 0) {
    g += s * s * (quadratic_(j) + s * cubic_(j));
    d += s * (2 * quadratic_(j) + 3 * s * cubic_(j));
  }
  if (tr.omega() != 0.0) {
    const Complex rotation = complex_exp(Complex(0.0, tr.omega() * (tr.start_time() + s)));
    g += (harmonic_(j) * rotation).imag();
    d += (harmonic_(j) * Complex(0.0, tr.omega()) * rotation).imag();
  }
  if (slow_) {
    const auto [value, rate] = slow_modal_sum(j, s);
    g += value;
    d += rate;
  } else if (tr.phase().modal()) {
    const Eigen::VectorXcd& lambda = tr.phase().eigenvalues();
    const Eigen::VectorXcd& exponentials = tr.exponentials(s);
    const std::vector<Eigen::Index>& kept = tr.phase().kept_modes();
    Complex sum = 0.0, sum_rate = 0.0;
    for (std::size_t i = 0; i < kept.size(); ++i) {
      const Eigen::Index k = kept[i];
      const Complex term = kept_modal_(j, static_cast<Eigen::Index>(i)) * exponentials(k);
      sum += term;
      sum_rate += lambda(k) * term;
    }
    g += sum.real();
    d += sum_rate.real();
  } else {
    const Eigen::MatrixXd propagator = (tr.phase().matrix() * s).exp();
    const Eigen::VectorXd h = propagator * tr.homogeneous_start();
    const Eigen::VectorXd h_rate = tr.phase().matrix() * h;
    g += rows_.row(j).dot(h);
    d += rows_.row(j).dot(h_rate);
  }
  return {s == 0.0 ? start_(j) : g, d};
}

std::pair<double, double> GuardExpansion::slow_modal_sum(int j, double s) const {
  // The slow modes' constants are in constant_: their terms are γ(e^{λs} − 1), by expm1.
  const ExactTrajectory& tr = *trajectory_;
  const Eigen::VectorXcd& lambda = tr.phase().eigenvalues();
  const Eigen::VectorXcd& exponentials = tr.exponentials(s);
  const Eigen::VectorXcd& increments = tr.increments(s);
  const std::vector<Eigen::Index>& kept = tr.phase().kept_modes();
  const std::vector<bool>& slow = tr.phase().slow_modes();
  Complex sum = 0.0, sum_rate = 0.0;
  for (std::size_t i = 0; i < kept.size(); ++i) {
    const Eigen::Index k = kept[i];
    const Complex gamma = kept_modal_(j, static_cast<Eigen::Index>(i));
    sum += gamma * (slow[static_cast<std::size_t>(k)] ? increments(k) : exponentials(k));
    sum_rate += lambda(k) * gamma * exponentials(k);
  }
  return {sum.real(), sum_rate.real()};
}

double GuardExpansion::derivative_bound(int j, int order, double a, double b) const {
  const ExactTrajectory& tr = *trajectory_;
  double bound = order == 1 ? std::abs(slope_(j)) : 0.0;
  if (quadratic_.size() > 0) {
    // |d^p/ds^p (Q s² + P s³)| on [a, b] (s ≥ 0).
    const double q = std::abs(quadratic_(j)), p = std::abs(cubic_(j));
    if (order == 1) bound += 2 * q * b + 3 * p * b * b;
    if (order == 2) bound += 2 * q + 6 * p * b;
    if (order == 3) bound += 6 * p;
  }
  bound += harmonic_size_(j) * power(tr.omega(), order);
  bound += std::abs(memory_(j)) * power(memory_rate_(j), order) *
           (memory_rate_(j) != 0.0 ? std::exp(-memory_rate_(j) * a) : 1.0);
  if (tr.phase().modal()) {
    update_growth(a, b);
    if (order >= kBoundOrders) throw std::invalid_argument("derivative_bound: an order above 4");
    const auto rate_power = rate_powers_->col(order);
    for (Eigen::Index k = 0; k < growth_.size(); ++k) {
      bound += modal_size_(j, k) * rate_power(k) * growth_(k);
    }
  } else {
    // r Aᵖ e^{As} h = (r D) Âᵖ e^{Âs} (D⁻¹ h) and ‖e^{Âs}‖ ≤ e^{μ s}, μ the logarithmic norm of Â.
    const double mu = tr.phase().log_norm();
    bound += balanced_row_norm_(j) * power(tr.phase().norm(), order) * balanced_start_norm_ *
             std::exp(mu * (mu > 0 ? b : a));
  }
  return bound;
}

void GuardExpansion::update_growth(double a, double b) const {
  if (a == growth_a_ && b == growth_b_) return;
  const Eigen::VectorXcd& lambda = trajectory_->phase().eigenvalues();
  for (Eigen::Index k = 0; k < lambda.size(); ++k) {
    const double re = lambda(k).real();
    // A conjugate pair shares its real part: one exponential for both.
    growth_(k) = k > 0 && re == lambda(k - 1).real() ? growth_(k - 1) : std::exp(re * (re > 0 ? b : a));
  }
  growth_a_ = a;
  growth_b_ = b;
}

namespace {

/// Shrinks [lo, hi] (g(lo) ≤ 0 < g(hi)) to width ≤ resolution (bracketed_roots.hpp), Newton
/// starting from `start`.
Crossing refine(const GuardExpansion& guards, int j, double lo, double hi, double resolution, double start) {
  const detail::RootBracket bracket =
      detail::newton_bracket([&](double s) { return guards.value_and_rate(j, s); }, lo, hi, resolution, start);
  return Crossing{j, bracket.lo, bracket.hi};
}

/// The least rate of the cubic Hermite model p over [0, h].
double least_model_rate(const detail::HermiteCubic& cubic, double da, double db, double h) {
  return std::min({da, db, cubic.least_slope() / h});
}

/// The first crossing of guard j in (a, b], b ≤ limit, proven by subdivision.
std::optional<Crossing> search(const GuardExpansion& guards, int j, double a, double b,
                               double resolution) {
  struct Interval {
    double a, b, ga, da, gb, db;
  };
  // Depth-first bisection: each level halves the interval and pushes at most two, and the
  // resolution (16 ulps of the time) is reached within log₂(1/(16ε)) ≈ 48 levels, so a fixed stack
  // of 128 suffices — and a step allocates nothing.
  std::array<Interval, 128> stack;
  std::size_t depth = 0;
  const auto push = [&](const Interval& in) {
    if (depth == stack.size())
      throw SimulationError(
          "event location: the guard search went deeper than its stack (a resolution below 2^-60 "
          "of the step)",
          StopReason::event_location);
    stack[depth++] = in;
  };
  const auto [ga, da] = guards.value_and_rate(j, a);
  const auto [gb, db] = guards.value_and_rate(j, b);
  push({a, b, ga, da, gb, db});
  // A proof that needs more pieces than this means bounds far looser than the guard (the stall
  // the balanced bounds of exact_phase.cpp removed): stop with a message rather than hang.
  constexpr int kMaxPieces = 1 << 20;
  int pieces = 0;
  while (depth > 0) {
    if (++pieces > kMaxPieces)
      throw SimulationError(
          "event location: proving where a guard crosses zero took more than 2^20 sub-intervals of "
          "one step (derivative bounds far looser than the guard); try the newmark integrator",
          StopReason::event_location);
    const Interval in = stack[--depth];
    const double h = in.b - in.a;
    if (in.ga > 0) return Crossing{j, in.a, in.a};  // already past zero at the start
    const detail::HermiteCubic cubic(in.ga, in.da, in.gb, in.db, h);
    const double d4 = guards.derivative_bound(j, 4, in.a, in.b);
    // Largest value of the cubic on [0, 1].
    double top = std::max(in.ga, in.gb);
    for (const double theta : cubic.critical_points()) {
      if (theta > 0 && theta < 1) top = std::max(top, cubic(theta));
    }
    if (top + d4 * h * h * h * h / 384.0 <= 0.0) continue;  // proven non-positive
    if (in.gb > 0) {
      // A single crossing when the rate stays positive. Two proofs: g' ≥ min(g'(a), g'(b)) − h
      // max|g''|; or g' ≥ min p' − max|g' − p'|, where g' − p' vanishes at a, b and (Rolle, as
      // g − p does at both ends) once between, so |g' − p'| ≤ max|g⁗| max|s(s − c)(s − h)|/3! ≤
      // (2/81) h³ max|g⁗| — with the bound of order 4 already taken, and far tighter than the
      // first once h is below the fastest mode's period.
      const bool rising_by_model = least_model_rate(cubic, in.da, in.db, h) - (2.0 / 81.0) * d4 * h * h * h > 0;
      const bool rising = rising_by_model || std::min(in.da, in.db) - guards.derivative_bound(j, 2, in.a, in.b) * h > 0;
      if (rising || h <= resolution) {
        const double theta = cubic.rising_root();
        return refine(guards, j, in.a, in.b, resolution, in.a + theta * h);
      }
    } else if (h <= resolution) {
      continue;  // touches zero within the resolution without crossing
    }
    const double m = 0.5 * (in.a + in.b);
    const auto [gm, dm] = guards.value_and_rate(j, m);
    if (gm <= 0) push({m, in.b, gm, dm, in.gb, in.db});
    push({in.a, m, in.ga, in.da, gm, dm});
  }
  return std::nullopt;
}

}  // namespace

std::optional<Crossing> first_crossing(const GuardExpansion& guards, double a, double b,
                                       double resolution) {
  std::optional<Crossing> best;
  for (int j = 0; j < guards.size(); ++j) {
    if (!guards.active(j)) continue;
    const double limit = best ? best->hi : b;
    if (!(limit > a)) break;
    if (auto c = search(guards, j, a, limit, resolution)) {
      if (!best || c->hi < best->hi) best = c;
    }
  }
  return best;
}

}  // namespace poundsim
