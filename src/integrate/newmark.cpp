#include "poundsim/integrate/newmark.hpp"

#include <algorithm>
#include <cmath>

namespace poundsim {

NewmarkIntegrator::NewmarkIntegrator(Eigen::Index dofs)
    : q_(dofs), qd_(dofs), qdd_(dofs), w1_(dofs), w2_(dofs), rhs_(dofs), qdd_new_(dofs), residual_(dofs),
      correction_(dofs) {}

void NewmarkIntegrator::prepare(const LinearPhase& phase, const KinematicState& from, double tau, double ground_end) {
  const Eigen::Index nr = phase.reduced_size();
  // Work in the reduced coordinates; buffers are sized for the full system and used in part.
  auto q = q_.head(nr), qd = qd_.head(nr), qdd = qdd_.head(nr), w1 = w1_.head(nr),
       w2 = w2_.head(nr), rhs = rhs_.head(nr);
  phase.gather(from.u, q);
  phase.gather(from.v, qd);
  phase.gather(from.a, qdd);

  const double half = 0.5 * tau, quarter_sq = 0.25 * tau * tau;
  w1 = qd + half * qdd;
  w2 = q + tau * qd + quarter_sq * qdd;
  rhs = phase.constant_load() - ground_end * phase.mass();
  rhs.noalias() -= phase.damping() * w1;
  rhs.noalias() -= phase.stiffness() * w2;
}

void NewmarkIntegrator::finish(const LinearPhase& phase, const KinematicState& from, double tau, double ground_end,
                               KinematicState& to) {
  const Eigen::Index nr = phase.reduced_size();
  auto qd = qd_.head(nr), qdd = qdd_.head(nr), w2 = w2_.head(nr), qdd_new = qdd_new_.head(nr);
  const double half = 0.5 * tau, quarter_sq = 0.25 * tau * tau;
  to.t = from.t + tau;
  to.ground = ground_end;
  if (phase.is_unreduced()) {
    to.u = w2 + quarter_sq * qdd_new;
    to.v = qd + half * (qdd + qdd_new);
    to.a = qdd_new;
  } else {
    const auto group = phase.group_of();
    const Eigen::VectorXd& offset = phase.offset();
    for (Eigen::Index i = 0; i < to.u.size(); ++i) {
      const int r = group[static_cast<std::size_t>(i)];
      to.u(i) = w2(r) + quarter_sq * qdd_new(r) + offset(i);
      to.v(i) = qd(r) + half * (qdd(r) + qdd_new(r));
      to.a(i) = qdd_new(r);
    }
  }
}

void NewmarkIntegrator::step(const LinearPhase& phase, const LinearPhase::Solver& solver,
                             const KinematicState& from, double tau, double ground_end,
                             KinematicState& to) {
  prepare(phase, from, tau, ground_end);
  const Eigen::Index nr = phase.reduced_size();
  qdd_new_.head(nr) = solver.solve(rhs_.head(nr));
  finish(phase, from, tau, ground_end, to);
}

NewtonOutcome NewmarkIntegrator::step_newton(const LinearPhase& phase, const KinematicState& from, double tau,
                                             double ground_end, SmoothForces& forces,
                                             std::span<ForceTangent> by_element, const NewtonOptions& options,
                                             KinematicState& to) {
  // rhs: the linear part of the residual that does not depend on ü⁺.
  prepare(phase, from, tau, ground_end);
  const Eigen::Index nr = phase.reduced_size();
  auto qdd = qdd_.head(nr), rhs = rhs_.head(nr), qdd_new = qdd_new_.head(nr), residual = residual_.head(nr),
       correction = correction_.head(nr);
  const double half = 0.5 * tau, quarter_sq = 0.25 * tau * tau;
  // The accelerations' size: the start's, the linear load's (per unit mass), the iterate's.
  const double load_scale = std::max(qdd.cwiseAbs().maxCoeff(), (rhs.array() / phase.mass().array()).abs().maxCoeff());

  const auto smooth = phase.smooth_links();
  previous_force_.resize(by_element.size());  // sized on the first call, then reused
  NewtonOutcome outcome;
  qdd_new = qdd;
  for (outcome.iterations = 0;; ++outcome.iterations) {
    finish(phase, from, tau, ground_end, to);
    for (const auto& link : smooth) {
      previous_force_[static_cast<std::size_t>(link.element)] = by_element[static_cast<std::size_t>(link.element)].force;
    }
    forces.evaluate(to, by_element);
    // R = rhs − (M + τ/2 C + τ²/4 K) ü⁺ − Tᵀ f.
    residual = rhs - phase.mass().cwiseProduct(qdd_new);
    correction = half * qdd_new;  // scratch until the solve
    residual.noalias() -= phase.damping() * correction;
    correction = quarter_sq * qdd_new;
    residual.noalias() -= phase.stiffness() * correction;
    phase.add_smooth_loads(by_element, residual);
    // Converged when the iterate satisfies the equation of motion to `tolerance`: its residual
    // per unit mass, which bounds the correction Newton would still make (J ⪰ M), is below it.
    // Tested before the solve, a converged iterate costs no factorisation.
    const double size = std::max(load_scale, qdd_new.cwiseAbs().maxCoeff());
    if ((residual.array() / phase.mass().array()).abs().maxCoeff() <= options.tolerance * size) return outcome;
    if (outcome.iterations == options.max_iterations) break;
    correction = phase.tangent_solver(tau, by_element).solve(residual);
    qdd_new += correction;
  }
  outcome.converged = false;
  double worst = -1.0;
  for (const auto& link : smooth) {
    const auto p = static_cast<std::size_t>(link.element);
    const double change = std::abs(by_element[p].force - previous_force_[p]);
    if (change > worst) {
      worst = change;
      outcome.worst_element = link.element;
    }
  }
  return outcome;  // `to` holds the last iterate (finish() at the loop's top)
}

}  // namespace poundsim
