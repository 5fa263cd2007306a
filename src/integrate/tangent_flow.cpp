#include "tangent_flow.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace poundsim::detail {

TangentFlow::TangentFlow(Eigen::Index dofs) : n_(dofs) {
  j_.setIdentity(2 * n_, 2 * n_);
  velocity_map_.setIdentity(n_, n_);
}

void TangentFlow::reset(double t) {
  j_.setIdentity(2 * n_, 2 * n_);
  time_ = start_ = t;
  segment_ = in_events_ = false;
  events_ = 0;
  least_transversality_ = 1.0;
}

void TangentFlow::start_segment(const LinearPhase& phase, const ExactPhase& exact, double t) {
  if (segment_) propagate_to(t);  // a forcing piece ended: the same phase goes on
  phase_ = &phase;
  exact_ = &exact;
  start_ = t;
  segment_ = true;
  j_start_ = j_;
  // G J: the rows of the leftmost floor of each group, displacements then velocities.
  const Eigen::Index groups = exact.groups();
  gathered_.resize(2 * groups, 2 * n_);
  for (Eigen::Index c = 0; c < 2 * n_; ++c) {
    phase.gather(j_start_.col(c).head(n_), gathered_.col(c).head(groups));
    phase.gather(j_start_.col(c).tail(n_), gathered_.col(c).tail(groups));
  }
}

void TangentFlow::propagate_to(double t) {
  if (!segment_ || t == time_) return;
  const Eigen::Index groups = exact_->groups();
  propagated_.noalias() = exact_->propagator(t - start_) * gathered_;
  for (Eigen::Index c = 0; c < 2 * n_; ++c) {
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
  Eigen::VectorXd jump(2 * n_);
  jump.head(n_) = velocity - before_.head(n_);
  jump.tail(n_) = acceleration - velocity_map_ * before_.tail(n_);
  const Eigen::RowVectorXd sensitivity_of_time = gradient_ * j_ / rate;  // −∂t*/∂x₀
  j_.bottomRows(n_) = velocity_map_ * j_.bottomRows(n_);
  j_.noalias() += jump * sensitivity_of_time;
}

}  // namespace poundsim::detail
