#include "tangent_flow.hpp"

#include <algorithm>
#include <cmath>
#include <complex>
#include <stdexcept>

namespace poundsim::detail {

TangentFlow::TangentFlow(Eigen::Index dofs) : n_(dofs) {
  j_.setIdentity(2 * n_, columns());
  velocity_map_.setIdentity(n_, n_);
}

void TangentFlow::track_frequency(bool track) { frequency_ = track; }

void TangentFlow::reset(double t) {
  j_.setIdentity(2 * n_, columns());  // y's column (if any) starts at 0
  time_ = start_ = t;
  segment_ = in_events_ = false;
  events_ = 0;
  least_transversality_ = 1.0;
}

void TangentFlow::start_segment(const LinearPhase& phase, const ExactTrajectory& trajectory, double t) {
  if (segment_) propagate_to(t);  // a forcing piece ended: the same phase goes on
  const ExactPhase& exact = trajectory.phase();
  phase_ = &phase;
  exact_ = &exact;
  start_ = t;
  segment_ = true;
  // G J: the rows of the leftmost floor of each group, displacements then velocities.
  const Eigen::Index groups = exact.groups();
  gathered_.resize(2 * groups, columns());
  for (Eigen::Index c = 0; c < columns(); ++c) {
    phase.gather(j_.col(c).head(n_), gathered_.col(c).head(groups));
    phase.gather(j_.col(c).tail(n_), gathered_.col(c).tail(groups));
  }
  if (frequency_) {
    if (trajectory.omega() == 0.0) throw std::logic_error("TangentFlow: ∂x/∂ω̄ needs a harmonic forcing");
    omega_ = trajectory.omega();
    harmonic_ = trajectory.harmonic_part();
    harmonic_rate_ = trajectory.piece().amplitude * exact.harmonic_response_rate(omega_);
    particular_rate(t);
    gathered_.col(2 * n_) -= particular_;  // y − z follows the homogeneous flow
  }
  if (exact.modal()) exact.project_modes(gathered_, projected_);
}

void TangentFlow::particular_rate(double t) {
  using Complex = std::complex<double>;
  // z(t) = Im((H' + i t H) e^{iω̄t}).
  const Complex rotation = std::exp(Complex(0.0, omega_ * t));
  const Complex it(0.0, t);
  particular_.resize(harmonic_.size());
  for (Eigen::Index i = 0; i < harmonic_.size(); ++i) particular_(i) = ((harmonic_rate_(i) + it * harmonic_(i)) * rotation).imag();
}

void TangentFlow::propagate_to(double t) {
  if (!segment_ || t == time_) return;
  const Eigen::Index groups = exact_->groups();
  if (exact_->modal()) {
    exact_->propagate_projected(t - start_, projected_, propagated_);
  } else {
    propagated_.noalias() = exact_->propagator(t - start_) * gathered_;
  }
  if (frequency_) {
    particular_rate(t);
    propagated_.col(2 * n_) += particular_;
  }
  for (Eigen::Index c = 0; c < columns(); ++c) {
    phase_->scatter(propagated_.col(c).head(groups), j_.col(c).head(n_), false);
    phase_->scatter(propagated_.col(c).tail(groups), j_.col(c).tail(n_), false);
  }
  time_ = t;
}

void TangentFlow::begin_events(const Eigen::Ref<const Eigen::RowVectorXd>& gradient,
                               const Eigen::VectorXd& velocity, const Eigen::VectorXd& acceleration) {
  gradient_ = gradient;
  before_.resize(2 * n_);
  before_ << velocity, acceleration;
  velocity_map_.setIdentity(n_, n_);
  in_events_ = true;
}

void TangentFlow::pair_impact(std::span<const int> group, int left, int right, double mass_left,
                              double mass_right, double restitution) {
  if (!in_events_) return;
  const double total = mass_left + mass_right;
  // v_L⁺ = a_LL v_L + a_LR v_R, v_R⁺ = a_RL v_L + a_RR v_R (centre ∓ e × share of w).
  const double all = (mass_left - restitution * mass_right) / total;
  const double alr = (mass_right + restitution * mass_right) / total;
  const double arl = (mass_left + restitution * mass_left) / total;
  const double arr = (mass_right - restitution * mass_left) / total;
  const Eigen::RowVectorXd row_left = velocity_map_.row(left), row_right = velocity_map_.row(right);
  const int gl = group[static_cast<std::size_t>(left)], gr = group[static_cast<std::size_t>(right)];
  for (Eigen::Index i = 0; i < n_; ++i) {
    const int g = group[static_cast<std::size_t>(i)];
    if (g == gl) velocity_map_.row(i) = all * row_left + alr * row_right;
    if (g == gr) velocity_map_.row(i) = arl * row_left + arr * row_right;
  }
}

void TangentFlow::merge(std::span<const int> group, const Eigen::VectorXd& floor_mass,
                        const Eigen::VectorXd& group_mass) {
  if (!in_events_) return;
  Eigen::MatrixXd momentum = Eigen::MatrixXd::Zero(group_mass.size(), n_);
  for (Eigen::Index i = 0; i < n_; ++i) momentum.row(group[static_cast<std::size_t>(i)]) += floor_mass(i) * velocity_map_.row(i);
  for (Eigen::Index i = 0; i < n_; ++i) {
    const int g = group[static_cast<std::size_t>(i)];
    velocity_map_.row(i) = momentum.row(g) / group_mass(g);
  }
}

void TangentFlow::end_events(const Eigen::VectorXd& velocity, const Eigen::VectorXd& acceleration) {
  if (!in_events_) return;
  in_events_ = false;
  const double rate = gradient_.dot(before_);
  const double scale = gradient_.norm() * before_.norm();
  least_transversality_ = std::min(least_transversality_, scale > 0 ? std::abs(rate) / scale : 0.0);
  ++events_;
  // d = f⁺ − G f⁻, with G f⁻ = [u̇⁻; Γ ü⁻].
  Eigen::VectorXd& jump = jump_;
  jump.resize(2 * n_);
  jump.head(n_) = velocity - before_.head(n_);
  jump.tail(n_).noalias() = velocity_map_ * before_.tail(n_);
  jump.tail(n_) = acceleration - jump.tail(n_);
  Eigen::RowVectorXd& sensitivity_of_time = time_sensitivity_;  // −∂t*/∂x₀
  sensitivity_of_time.noalias() = gradient_ * j_;
  sensitivity_of_time /= rate;
  velocity_rows_.noalias() = velocity_map_ * j_.bottomRows(n_);
  j_.bottomRows(n_) = velocity_rows_;
  j_.noalias() += jump * sensitivity_of_time;
}

}  // namespace poundsim::detail
