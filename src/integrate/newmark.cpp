#include "poundsim/integrate/newmark.hpp"

namespace poundsim {

NewmarkIntegrator::NewmarkIntegrator(Eigen::Index dofs)
    : q_(dofs), qd_(dofs), qdd_(dofs), w1_(dofs), w2_(dofs), rhs_(dofs), qdd_new_(dofs) {}

void NewmarkIntegrator::step(const LinearPhase& phase, const LinearPhase::Solver& solver,
                             const KinematicState& from, double tau, double ground_end,
                             KinematicState& to) {
  const Eigen::Index nr = phase.reduced_size();
  // Work in the reduced coordinates; buffers are sized for the full system and used in part.
  auto q = q_.head(nr), qd = qd_.head(nr), qdd = qdd_.head(nr), w1 = w1_.head(nr),
       w2 = w2_.head(nr), rhs = rhs_.head(nr), qdd_new = qdd_new_.head(nr);
  phase.gather(from.u, q);
  phase.gather(from.v, qd);
  phase.gather(from.a, qdd);

  const double half = 0.5 * tau, quarter_sq = 0.25 * tau * tau;
  w1 = qd + half * qdd;
  w2 = q + tau * qd + quarter_sq * qdd;
  rhs = phase.constant_load() - ground_end * phase.mass();
  rhs.noalias() -= phase.damping() * w1;
  rhs.noalias() -= phase.stiffness() * w2;
  qdd_new = solver.solve(rhs);

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

}  // namespace poundsim
