// The exact integrator: closed-form phases between events, events as proven first roots of exact
// guard functions (exact_phase.hpp, guard_expansion.hpp).

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

#include <Eigen/Eigenvalues>

#include "steppers.hpp"
#include "tangent_flow.hpp"

#include "../dynamics/contact_links.hpp"

namespace poundsim::detail {


namespace {

/// Gauss–Legendre rules on [−1, 1] with n = 1 … 12 nodes, from the Golub–Welsch eigenproblem.
struct GaussLegendre {
  std::vector<double> nodes, weights;
};

const GaussLegendre& gauss_legendre(int n) {
  static const std::vector<GaussLegendre> rules = [] {
    std::vector<GaussLegendre> out(13);
    for (int m = 1; m <= 12; ++m) {
      Eigen::MatrixXd jacobi = Eigen::MatrixXd::Zero(m, m);
      for (int i = 1; i < m; ++i) jacobi(i, i - 1) = jacobi(i - 1, i) = i / std::sqrt(4.0 * i * i - 1);
      const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(jacobi);
      for (int i = 0; i < m; ++i) {
        out[static_cast<std::size_t>(m)].nodes.push_back(eig.eigenvalues()(i));
        out[static_cast<std::size_t>(m)].weights.push_back(2 * eig.eigenvectors()(0, i) * eig.eigenvectors()(0, i));
      }
    }
    return out;
  }();
  return rules[static_cast<std::size_t>(n)];
}

/// The fewest Gauss–Legendre nodes whose error for an integrand oscillating or decaying at rate r
/// over an interval h is below 1e-17 of the integral: (rh)^{2n} (n!)⁴ / ((2n+1) ((2n)!)³).
int nodes_for(double rh) {
  double factorial_n = 1, factorial_2n = 1, rh_2n = 1;
  for (int n = 1; n <= 12; ++n) {
    factorial_n *= n;
    factorial_2n *= (2.0 * n - 1) * (2.0 * n);
    rh_2n *= rh * rh;
    const double f4 = factorial_n * factorial_n * factorial_n * factorial_n;
    const double error = rh_2n * f4 / ((2 * n + 1) * factorial_2n * factorial_2n * factorial_2n);
    if (error < 1e-17) return n;
  }
  return 12;
}

}  // namespace

Eigen::MatrixXd ExactStepper::guard_rows(const Loop& loop, const ExactPhase& exact) const {
  // Guards as affine functions of x = [q; q̇] of the phase (their constants come from the guard
  // values at the start of each segment). See evaluate_guards for the guards themselves.
  const Eigen::Index n = exact.groups();
  const auto group = loop.phase().group_of();
  const auto g = [&](int dof) { return static_cast<Eigen::Index>(group[static_cast<std::size_t>(dof)]); };
  Eigen::MatrixXd rows = Eigen::MatrixXd::Zero(2 * loop.system().tracked_count(), 2 * n);
  // Stop reactions: λ_out = f_L + λ_in along each chain, f_L = f_S − m(a_g + ü) − C u̇ − K u;
  // the ground acceleration cancels between m a_g and m ü.
  std::vector<Eigen::RowVectorXd> link_in(static_cast<std::size_t>(loop.system().layout().size()));
  const LinearPhase::SparseMatrix& c = loop.phase().full_damping();
  const LinearPhase::SparseMatrix& k = loop.phase().full_stiffness();
  for (std::size_t p = 0; p < loop.contact().config.size(); ++p) {
    const Link& link = loop.system().tracked_links()[p];
    const int l = link.a, r = link.b;  // r = −1: a first storey's ground
    for (int i = 0; i < 2; ++i) {
      const Eigen::Index j = 2 * static_cast<Eigen::Index>(p) + i;
      const GuardForm form = with_event_law<GuardForm>(
          link,
          [&](const auto& law) { return law.guard_form(i, loop.contact().config[p], loop.system().rules().separation); },
          [] { return GuardForm{}; });
      switch (form.kind) {
        case GuardForm::Kind::inactive: break;
        case GuardForm::Kind::affine: {
          // d = nᵀu over the link's terms (u_l − u_r between floors).
          const LinkDofs dofs = link_dofs(link);
          for (const DofTerm& t : dofs.terms()) {
            rows(j, g(t.dof)) += t.coefficient * form.d_coefficient;
            if (form.rate_coefficient != 0.0) rows(j, n + g(t.dof)) += t.coefficient * form.rate_coefficient;
          }
          break;
        }
        case GuardForm::Kind::reaction: {
          Eigen::RowVectorXd f = -loop.phase().full_mass()(l) * exact.matrix().row(n + g(l));
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
  }
  return rows;
}

void ExactStepper::start_segment(Loop& loop) {
  auto it = phases_.find(loop.contact().config);
  if (it == phases_.end()) {
    PhaseData data;
    data.phase = std::make_unique<ExactPhase>(loop.phase());
    data.guard_rows = GuardRows(guard_rows(loop, *data.phase), *data.phase);
    if (data.phase->modal()) {
      data.powers = std::make_unique<ExactPowerIntegrals>(
          *data.phase, loop.meter().power_forms(loop.contact().config, loop.phase().group_of(), data.phase->groups()));
    }
    it = phases_.emplace(loop.contact().config, std::move(data)).first;
  }
  const ExactPhase& exact = *it->second.phase;
  const Eigen::Index n = exact.groups();
  x_work_.resize(2 * n);
  loop.phase().gather(loop.state().u, x_work_.head(n));
  loop.phase().gather(loop.state().v, x_work_.tail(n));
  trajectory_.start(exact, loop.phase().mass(), loop.phase().constant_load(), loop.state().t, x_work_,
                    forcing_piece(loop.system().excitation(), loop.state().t));
  segment_powers_ = it->second.powers.get();
  segment_guard_rows_ = &it->second.guard_rows.real;
  if (TangentFlow* tangent = loop.tangent()) tangent->start_segment(loop.phase(), trajectory_, loop.state().t);
  // The power integrals serve the energy balance only: a run that records nothing (a shooting
  // run of the periodic orbits) never needs them, so they start with the first recorded step.
  powers_started_ = false;
  for (std::size_t p = 0; p < loop.contact().config.size(); ++p) {
    const Link& link = loop.system().tracked_links()[p];
    const Relaxation relaxation = with_event_law<Relaxation>(
        link,
        [&](const auto& law) {
          return law.relaxation(loop.contact().config[p], loop.contact().states.at(law, link.slot), loop.state().t);
        },
        [] { return Relaxation{}; });
    memory_amplitude_[2 * p] = relaxation.amplitude;
    memory_rate_[2 * p] = relaxation.rate;
  }
  expansion_.build(trajectory_, it->second.guard_rows, loop.guards().lo, memory_amplitude_, memory_rate_);
  segment_valid_ = true;
}

void ExactStepper::tangent_restarted(Loop& loop) {
  // The flow from here is the segment's propagator from the current time: Φ depends on the time
  // elapsed alone, and the harmonic part on the absolute time (tangent_flow.hpp).
  if (TangentFlow* tangent = loop.tangent(); tangent != nullptr && segment_valid_) {
    tangent->start_segment(loop.phase(), trajectory_, loop.state().t);
  }
}

void ExactStepper::state_at(const Loop& loop, double s, KinematicState& out) {
  trajectory_.evaluate(s, x_work_, x_rate_work_);
  const Eigen::Index n = trajectory_.phase().groups();
  loop.phase().scatter(x_work_.head(n), out.u, true);
  loop.phase().scatter(x_work_.tail(n), out.v, false);
  loop.phase().scatter(x_rate_work_.tail(n), out.a, false);
  out.t = trajectory_.start_time() + s;
  out.ground = trajectory_.piece().at(out.t);
}

void ExactStepper::motion_at(const Loop& loop, double s, KinematicState& out) {
  trajectory_.evaluate(s, x_work_);
  const Eigen::Index n = trajectory_.phase().groups();
  loop.phase().scatter(x_work_.head(n), out.u, true);
  loop.phase().scatter(x_work_.tail(n), out.v, false);
  out.t = trajectory_.start_time() + s;
}

void ExactStepper::accept(Loop& loop, KinematicState& next) {
  if (loop.recording()) {
    if (loop.metering()) {
      if (segment_powers_ != nullptr && !powers_started_) {
        segment_powers_->start(trajectory_);
        powers_started_ = true;
      }
      const double t0 = trajectory_.start_time();
      const double a = loop.state().t - t0, b = next.t - t0;
      const EnergyMeter::Powers integral =
          segment_powers_ != nullptr ? segment_powers_->integrate(a, b) : quadrature_powers(loop, a, b);
      loop.meter().step_with(loop.state(), next, integral, loop.contact().config, loop.contact().states);
    }
    Output output(*this, loop);
    loop.monitor().observe_step(loop.state(), next, trajectory_.start_time(), output);
  }
  loop.evaluate_guards(next, loop.guards().lo, loop.guards().rate_lo);
  loop.after_accept(next);
}

EnergyMeter::Powers ExactStepper::quadrature_powers(const Loop& loop, double a, double b) {
  // The matrix-exponential path has no modes to integrate in closed form: Gauss–Legendre
  // quadrature on sub-intervals over which the fastest product of two modes turns by at most one
  // radian, and enough nodes that the rule's error is far below round-off.
  const double rate = 2 * std::max(trajectory_.phase().spectral_radius(), trajectory_.omega());
  const int pieces = std::max(1, static_cast<int>(std::ceil((b - a) * rate)));
  EnergyMeter::Powers integral;
  const double width = (b - a) / pieces;
  const GaussLegendre& rule = gauss_legendre(nodes_for(rate * width));
  for (int piece = 0; piece < pieces; ++piece) {
    const double mid = a + (piece + 0.5) * width;
    for (std::size_t k = 0; k < rule.nodes.size(); ++k) {
      state_at(loop, mid + 0.5 * width * rule.nodes[k], node_);
      const EnergyMeter::Powers p = loop.meter().powers(node_, loop.contact().config, loop.contact().states);
      const double w = 0.5 * width * rule.weights[k];
      integral.input += w * p.input;
      integral.storey_damping += w * p.storey_damping;
      integral.gap_damping += w * p.gap_damping;
    }
  }
  return integral;
}

ExactStepper::ExactStepper(int dofs, int tracked_links) {
  memory_amplitude_.assign(2 * static_cast<std::size_t>(tracked_links), 0.0);
  memory_rate_.assign(2 * static_cast<std::size_t>(tracked_links), 0.0);
  node_.resize(dofs);
  upper_.resize(dofs);
}

void ExactStepper::integrate_to(Loop& loop, double t_end, bool /*nominal*/) {
  constexpr double eps = std::numeric_limits<double>::epsilon();
  while (loop.state().t < t_end) {
    if (!segment_valid_) start_segment(loop);
    const double t0 = trajectory_.start_time();
    const double limit = std::min(t_end, trajectory_.piece().end);
    const double resolution = 16 * eps * std::max(1.0, std::abs(limit));
    const std::optional<Crossing> crossing =
        first_crossing(expansion_, loop.state().t - t0, limit - t0, resolution);
    if (!crossing) {
      state_at(loop, limit - t0, upper_);
      upper_.t = limit;
      accept(loop, upper_);
      if (limit >= trajectory_.piece().end) segment_valid_ = false;  // the next forcing piece
      continue;
    }
    // The bracket is a few ulps wide, below the round-off of the guards computed from a state.
    // Move its upper end past the root until the guard of the state there has fired too, so the
    // event decision and every later guard evaluation agree; all guards positive there fire
    // together (simultaneous events).
    const double lo = std::max(crossing->lo, loop.state().t - t0);
    double hi = std::max(crossing->hi, lo);
    const double end = limit - t0;
    for (int widen = 0;; ++widen) {
      state_at(loop, hi, upper_);
      loop.evaluate_guards(upper_, loop.guards().work, loop.guards().rate_work);
      if (loop.guards().work[static_cast<std::size_t>(crossing->guard)] > 0 || hi >= end || widen > 60) break;
      hi = std::min(end, lo + 2 * (hi - lo) + resolution);
    }
    const bool fired = any_fired(loop.guards().work);
    accept(loop, upper_);  // loop.guards().lo = the guards at upper_: loop.guards().work
    if (!fired) continue;  // a touch within round-off: no event
    apply_events(loop, crossing->guard);
    segment_valid_ = false;
  }
}

void ExactStepper::apply_events(Loop& loop, int guard) {
  TangentFlow* tangent = loop.tangent();
  if (tangent == nullptr) {
    loop.apply_pending_events();
    return;
  }
  // ∇h in floor coordinates: the guard row is in the phase's (gathered) coordinates.
  tangent->propagate_to(loop.state().t);
  const Eigen::Index n = loop.state().u.size();
  const auto rows = segment_guard_rows_->row(guard);
  const std::span<const int> representative = loop.phase().representatives();
  const auto groups = static_cast<Eigen::Index>(representative.size());
  gradient_.setZero(2 * n);
  for (Eigen::Index r = 0; r < groups; ++r) {
    gradient_(representative[static_cast<std::size_t>(r)]) = rows(r);
    gradient_(n + representative[static_cast<std::size_t>(r)]) = rows(groups + r);
  }
  tangent->begin_events(gradient_, loop.state().v, loop.state().a);
  loop.apply_pending_events();
  tangent->end_events(loop.state().v, loop.state().a);
  tangent->end_segment();
}

}  // namespace poundsim::detail
