// The exact integrator's path through Simulator: closed-form phases between events, events as
// proven first roots of exact guard functions (exact_phase.hpp, guard_expansion.hpp).

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

#include "poundsim/simulator.hpp"

namespace poundsim {

namespace {

/// 10-point Gauss–Legendre rule on [−1, 1].
constexpr std::array<double, 10> kNodes{
    -0.9739065285171717, -0.8650633666889845, -0.6794095682990244, -0.4333953941292472,
    -0.1488743389816312, 0.1488743389816312,  0.4333953941292472,  0.6794095682990244,
    0.8650633666889845,  0.9739065285171717};
constexpr std::array<double, 10> kWeights{
    0.0666713443086881, 0.1494513491505806, 0.2190863625159820, 0.2692667193099963,
    0.2955242247147529, 0.2955242247147529, 0.2692667193099963, 0.2190863625159820,
    0.1494513491505806, 0.0666713443086881};

}  // namespace

Eigen::MatrixXd Simulator::guard_rows(const ExactPhase& exact) const {
  // Guards as affine functions of x = [q; q̇] of the phase (their constants come from the guard
  // values at the start of each segment). See evaluate_guards for the guards themselves.
  const Eigen::Index n = exact.groups();
  const auto group = phase_->group_of();
  const auto g = [&](int dof) { return static_cast<Eigen::Index>(group[static_cast<std::size_t>(dof)]); };
  const bool force_criterion = options_.separation == SeparationCriterion::force;
  Eigen::MatrixXd rows = Eigen::MatrixXd::Zero(2 * model_.gap_count(), 2 * n);
  // Stop reactions: λ_out = f_L + λ_in along each chain, f_L = f_S − m(a_g + ü) − C u̇ − K u;
  // the ground acceleration cancels between m a_g and m ü.
  std::vector<Eigen::RowVectorXd> link_in(static_cast<std::size_t>(layout_.size()));
  const LinearPhase::SparseMatrix& c = phase_->full_damping();
  const LinearPhase::SparseMatrix& k = phase_->full_stiffness();
  for (std::size_t p = 0; p < config_.size(); ++p) {
    const GapProperties& gp = model_.gaps[p].properties;
    const int l = gap_left_[p], r = gap_right_[p];
    const Eigen::Index j = 2 * static_cast<Eigen::Index>(p);
    switch (config_[p]) {
      case GapMode::open:
        rows(j, g(l)) += 1.0;
        rows(j, g(r)) -= 1.0;
        break;
      case GapMode::contact:
        rows(j, g(l)) += 1.0;
        rows(j, g(r)) -= 1.0;
        if (force_criterion) {
          rows(j + 1, g(l)) -= gp.stiffness;
          rows(j + 1, g(r)) += gp.stiffness;
          rows(j + 1, n + g(l)) -= gp.damping;
          rows(j + 1, n + g(r)) += gp.damping;
        } else {
          rows(j + 1, g(l)) -= 1.0;
          rows(j + 1, g(r)) += 1.0;
        }
        break;
      case GapMode::locked: {
        Eigen::RowVectorXd f = -phase_->full_mass()(l) * exact.matrix().row(n + g(l));
        for (LinearPhase::SparseMatrix::InnerIterator it(c, l); it; ++it) {
          f(n + g(static_cast<int>(it.row()))) -= it.value();
        }
        for (LinearPhase::SparseMatrix::InnerIterator it(k, l); it; ++it) {
          f(g(static_cast<int>(it.row()))) -= it.value();
        }
        auto& in = link_in[static_cast<std::size_t>(l)];
        if (in.size() > 0) f += in;
        rows.row(j) = -f;
        link_in[static_cast<std::size_t>(r)] = f;
        break;
      }
    }
  }
  return rows;
}

void Simulator::start_exact_segment() {
  auto it = exact_phases_.find(config_);
  if (it == exact_phases_.end()) {
    ExactData data;
    data.phase = std::make_unique<ExactPhase>(*phase_);
    data.guard_rows = guard_rows(*data.phase);
    it = exact_phases_.emplace(config_, std::move(data)).first;
  }
  const ExactPhase& exact = *it->second.phase;
  const Eigen::Index n = exact.groups();
  x_work_.resize(2 * n);
  reduced_work_.resize(n);
  phase_->gather(state_.u, reduced_work_);
  x_work_.head(n) = reduced_work_;
  phase_->gather(state_.v, reduced_work_);
  x_work_.tail(n) = reduced_work_;
  trajectory_.start(exact, phase_->mass(), phase_->constant_load(), state_.t, x_work_,
                    forcing_piece(excitation_, state_.t));
  for (std::size_t p = 0; p < config_.size(); ++p) {
    const GapProperties& gp = model_.gaps[p].properties;
    const bool relaxing = config_[p] == GapMode::open && memory_[p].released_shortening != 0.0 &&
                          gp.damping > 0;
    memory_amplitude_[2 * p] =
        relaxing ? memory_[p].free_end_shortening(state_.t, gp.stiffness, gp.damping) : 0.0;
    memory_rate_[2 * p] = relaxing ? gp.stiffness / gp.damping : 0.0;
  }
  expansion_.build(trajectory_, it->second.guard_rows, g_lo_, memory_amplitude_, memory_rate_);
  segment_valid_ = true;
}

void Simulator::exact_state(double s, KinematicState& out) {
  trajectory_.evaluate(s, x_work_, x_rate_work_);
  const Eigen::Index n = trajectory_.phase().groups();
  reduced_work_ = x_work_.head(n);
  phase_->scatter(reduced_work_, out.u, true);
  reduced_work_ = x_work_.tail(n);
  phase_->scatter(reduced_work_, out.v, false);
  reduced_work_ = x_rate_work_.tail(n);
  phase_->scatter(reduced_work_, out.a, false);
  out.t = trajectory_.start_time() + s;
  out.ground = trajectory_.piece().at(out.t);
}

void Simulator::accept_exact(KinematicState& next) {
  // Integrate the powers on the exact trajectory: Gauss–Legendre, sub-intervals short enough that
  // the fastest mode turns by at most one radian (error far below round-off).
  const double t0 = trajectory_.start_time();
  const double a = state_.t - t0, b = next.t - t0;
  const double rate = std::max(trajectory_.phase().spectral_radius(), trajectory_.omega());
  const int pieces = std::max(1, static_cast<int>(std::ceil((b - a) * rate)));
  EnergyMeter::Powers integral;
  const double width = (b - a) / pieces;
  for (int piece = 0; piece < pieces; ++piece) {
    const double mid = a + (piece + 0.5) * width;
    for (std::size_t k = 0; k < kNodes.size(); ++k) {
      exact_state(mid + 0.5 * width * kNodes[k], node_);
      const EnergyMeter::Powers p = energy_.powers(node_, config_);
      const double w = 0.5 * width * kWeights[k];
      integral.input += w * p.input;
      integral.storey_damping += w * p.storey_damping;
      integral.gap_damping += w * p.gap_damping;
    }
  }
  energy_.step_with(state_, next, integral, config_, memory_);
  after_accept(next);
  evaluate_guards(state_, g_lo_, dg_lo_);
}

void Simulator::integrate_exact_to(double t_end) {
  constexpr double eps = std::numeric_limits<double>::epsilon();
  while (state_.t < t_end) {
    if (!segment_valid_) start_exact_segment();
    const double t0 = trajectory_.start_time();
    const double limit = std::min(t_end, trajectory_.piece().end);
    const double resolution = 16 * eps * std::max(1.0, std::abs(limit));
    const std::optional<Crossing> crossing =
        first_crossing(expansion_, state_.t - t0, limit - t0, resolution);
    if (!crossing) {
      exact_state(limit - t0, upper_);
      upper_.t = limit;
      accept_exact(upper_);
      if (limit >= trajectory_.piece().end) segment_valid_ = false;  // the next forcing piece
      continue;
    }
    // Every guard positive at the upper end of the bracket fires: simultaneous events.
    const double hi = std::max(crossing->hi, state_.t - t0);
    for (int j = 0; j < expansion_.size(); ++j) {
      g_work_[static_cast<std::size_t>(j)] =
          expansion_.active(j) ? expansion_.value(j, hi) : -std::numeric_limits<double>::infinity();
    }
    g_work_[static_cast<std::size_t>(crossing->guard)] =
        std::max(g_work_[static_cast<std::size_t>(crossing->guard)], std::numeric_limits<double>::min());
    exact_state(hi, upper_);
    const std::vector<double> fired = g_work_;
    accept_exact(upper_);
    apply_events(fired);
    while (std::any_of(g_lo_.begin(), g_lo_.end(), [](double x) { return x > 0.0; })) {
      g_work_ = g_lo_;
      apply_events(g_work_);
    }
    segment_valid_ = false;
  }
}

}  // namespace poundsim
