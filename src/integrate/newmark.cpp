#include "poundsim/integrate/newmark.hpp"

#include <algorithm>
#include <cmath>
#include <span>
#include <stdexcept>

namespace poundsim {

NewmarkIntegrator::NewmarkIntegrator(Eigen::Index dofs)
    : q_(dofs), qd_(dofs), qdd_(dofs), w1_(dofs), w2_(dofs), rhs_(dofs), qdd_new_(dofs), residual_(dofs),
      correction_(dofs),
      band_w1_(static_cast<std::size_t>(dofs + 2 * LinearPhase::Bands::kMaxWidth), 0.0),
      band_w2_(band_w1_.size(), 0.0),
      band_y_(band_w1_.size(), 0.0),
      band_x_(band_w1_.size(), 0.0) {}

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

namespace {
/// One past the last stored entry of column j of a column-major sparse matrix, compressed or not
/// (Eigen's InnerIterator's end).
[[gnu::always_inline]] inline int column_end(const LinearPhase::SparseMatrix& a, int j) {
  const int* starts = a.outerIndexPtr();
  const int* counts = a.innerNonZeroPtr();  // null when compressed
  return counts != nullptr ? starts[j] + counts[j] : starts[j + 1];
}

/// y(i) += A(i,j)·(−x(j)) column by column: Eigen's `y.noalias() -= A * x` for a column-major
/// sparse A (SparseDenseProduct.h), operation for operation, hence the same bits.
[[gnu::always_inline]] inline void subtract_product(const LinearPhase::SparseMatrix& a, const double* x, double* y) {
  const double* values = a.valuePtr();
  const int* rows = a.innerIndexPtr();
  const int* starts = a.outerIndexPtr();
  for (int j = 0; j < static_cast<int>(a.outerSize()); ++j) {
    const double xj = -1.0 * x[j];
    for (int p = starts[j], end = column_end(a, j); p < end; ++p) y[rows[p]] += values[p] * xj;
  }
}

/// Solves L D Lᵀ x = b in place as SimplicialLDLT::_solve_impl does without a permutation
/// (SimplicialCholesky.h, TriangularSolver.h): forward with the unit lower L column by column
/// (skipping the columns whose right-hand-side entry is zero, as Eigen does), x(i) = (1/d(i))·x(i),
/// backward with Lᵀ row by row. No FMA: the build targets x86-64 without it (docs/numerics.md).
[[gnu::always_inline]] inline void solve_in_place(const LinearPhase::Solver& solver, double* x) {
  const LinearPhase::SparseMatrix& l = solver.unit_lower_factor();
  const double* values = l.valuePtr();
  const int* rows = l.innerIndexPtr();
  const int* starts = l.outerIndexPtr();
  const double* d = solver.diagonal_factor().data();
  const auto n = static_cast<int>(l.cols());
  for (int i = 0; i < n; ++i) {
    const double xi = x[i];
    if (xi == 0.0) continue;
    for (int p = starts[i], end = column_end(l, i); p < end; ++p) {
      if (rows[p] > i) x[rows[p]] -= xi * values[p];
    }
  }
  for (int i = 0; i < n; ++i) x[i] = (1.0 / d[i]) * x[i];
  for (int i = n - 1; i >= 0; --i) {
    double sum = x[i];
    for (int p = starts[i], end = column_end(l, i); p < end; ++p) {
      if (rows[p] > i) sum -= values[p] * x[rows[p]];
    }
    x[i] = sum;
  }
}

/// Names the smooth link to blame for Newton's failure: the first whose force is not finite
/// (a comparison with NaN is always false, so a NaN would otherwise never be "the largest
/// change"), else the one whose force changed most in the last iteration.
void blame_worst_element(std::span<const LinearPhase::SmoothLink> smooth, std::span<const ForceTangent> by_element,
                         const std::vector<double>& previous_force, NewtonOutcome& outcome) {
  double worst = -1.0;
  for (const auto& link : smooth) {
    const auto p = static_cast<std::size_t>(link.element);
    if (!std::isfinite(by_element[p].force)) {
      outcome.worst_element = link.element;
      outcome.worst_not_finite = true;
      return;
    }
    const double change = std::abs(by_element[p].force - previous_force[p]);
    if (!(change <= worst)) {  // also takes a change that is not finite
      worst = change;
      outcome.worst_element = link.element;
    }
  }
}
}  // namespace

void NewmarkIntegrator::step_banded(const LinearPhase& phase, const LinearPhase::Bands& bands, const double* u,
                                    const double* v, const double* a, double tau, double ground_end, double* u_new,
                                    double* v_new, double* a_new) {
  switch (bands.width) {
    case 0: step_banded<0>(phase, bands, u, v, a, tau, ground_end, u_new, v_new, a_new); return;
    case 1: step_banded<1>(phase, bands, u, v, a, tau, ground_end, u_new, v_new, a_new); return;
    case 2: step_banded<2>(phase, bands, u, v, a, tau, ground_end, u_new, v_new, a_new); return;
    case 3: step_banded<3>(phase, bands, u, v, a, tau, ground_end, u_new, v_new, a_new); return;
    case 4: step_banded<4>(phase, bands, u, v, a, tau, ground_end, u_new, v_new, a_new); return;
    default: throw std::logic_error("NewmarkIntegrator: a band wider than Bands::kMaxWidth");
  }
}

[[gnu::noinline]] void NewmarkIntegrator::step_groups_banded(const LinearPhase& phase, const LinearPhase::Bands& bands,
                                                            const KinematicState& from, double tau, double ground_end,
                                                            KinematicState& to) {
  const Eigen::Index nr = phase.reduced_size();
  phase.gather(from.u, q_.head(nr));
  phase.gather(from.v, qd_.head(nr));
  phase.gather(from.a, qdd_.head(nr));
  double *q_new = w1_.data(), *qd_new = w2_.data(), *qdd_new = qdd_new_.data();
  step_banded(phase, bands, q_.data(), qd_.data(), qdd_.data(), tau, ground_end, q_new, qd_new, qdd_new);
  const std::span<const int> group = phase.group_of();
  const double* offset = phase.offset().data();
  double *u_new = to.u.data(), *v_new = to.v.data(), *a_new = to.a.data();
  for (std::size_t i = 0; i < group.size(); ++i) {
    const auto r = static_cast<std::size_t>(group[i]);
    u_new[i] = q_new[r] + offset[i];
    v_new[i] = qd_new[r];
    a_new[i] = qdd_new[r];
  }
}

void NewmarkIntegrator::step(const LinearPhase& phase, const LinearPhase::Solver& solver,
                             const KinematicState& from, double tau, double ground_end,
                             KinematicState& to) {
  // Bands exist for phases without smooth links, and for their step solver (factorised, natural
  // order).
  if (const LinearPhase::Bands* bands = phase.bands_for(solver)) {
    to.t = from.t + tau;
    to.ground = ground_end;
    if (phase.is_unreduced()) {
      step_banded(phase, *bands, from.u.data(), from.v.data(), from.a.data(), tau, ground_end, to.u.data(),
                  to.v.data(), to.a.data());
      return;
    }
    // Locked links: the same rows over the groups (q = u of each group's representative floor),
    // then u = T q + o as finish() writes it — (w2 + τ²/4 q̈⁺) + o, the same sum. Out of line, so
    // that the common, unreduced step stays as small as it was (2 × 1: 29 instructions a step
    // more with this path written in here; docs/numerics.md, "Locked links in bands").
    step_groups_banded(phase, *bands, from, tau, ground_end, to);
    return;
  }
  if (phase.is_unreduced() && solver.info() == Eigen::Success && solver.permutationP().size() == 0) {
    step_unreduced(phase, solver, from, tau, ground_end, to);
    return;
  }
  prepare(phase, from, tau, ground_end);
  const Eigen::Index nr = phase.reduced_size();
  qdd_new_.head(nr) = solver.solve(rhs_.head(nr));
  finish(phase, from, tau, ground_end, to);
}

void NewmarkIntegrator::step_unreduced(const LinearPhase& phase, const LinearPhase::Solver& solver,
                                       const KinematicState& from, double tau, double ground_end,
                                       KinematicState& to) {
  // prepare() and finish() of the general step written out for T = I, in the same operations.
  const auto n = static_cast<int>(phase.reduced_size());
  const double half = 0.5 * tau, quarter_sq = 0.25 * tau * tau;
  const double *u = from.u.data(), *v = from.v.data(), *a = from.a.data();
  const double *mass = phase.mass().data(), *load = phase.constant_load().data();
  double *w1 = w1_.data(), *w2 = w2_.data(), *x = qdd_new_.data();
  for (int i = 0; i < n; ++i) {
    w1[i] = v[i] + half * a[i];
    w2[i] = u[i] + tau * v[i] + quarter_sq * a[i];
    x[i] = load[i] - ground_end * mass[i];
  }
  subtract_product(phase.damping(), w1, x);
  subtract_product(phase.stiffness(), w2, x);
  solve_in_place(solver, x);
  to.t = from.t + tau;
  to.ground = ground_end;
  double *u_new = to.u.data(), *v_new = to.v.data(), *a_new = to.a.data();
  for (int i = 0; i < n; ++i) {
    u_new[i] = w2[i] + quarter_sq * x[i];
    v_new[i] = v[i] + half * (a[i] + x[i]);
    a_new[i] = x[i];
  }
}

template <int B>
inline void NewmarkIntegrator::step_banded(const LinearPhase& phase, const LinearPhase::Bands& bands,
                                    const double* __restrict u, const double* __restrict v,
                                    const double* __restrict a, double tau, double ground_end,
                                    double* __restrict u_new, double* __restrict v_new, double* __restrict a_new) {
  static_assert(B >= 0 && B <= LinearPhase::Bands::kMaxWidth);
  constexpr int kRow = 2 * B + 1;
  constexpr int kPad = LinearPhase::Bands::kMaxWidth;
  const auto n = static_cast<int>(phase.reduced_size());
  const double half = 0.5 * tau, quarter_sq = 0.25 * tau * tau;
  const double* __restrict mass = phase.mass().data();
  const double* __restrict load = phase.constant_load().data();
  if constexpr (B == 0) {
    // No DOF couples to another (single-storey frames apart, the common case of the paper's
    // systems): each row's whole step in one pass, the same operations as the passes below.
    const double* __restrict c = bands.damping.data();
    const double* __restrict k = bands.stiffness.data();
    const double* __restrict inverse_d = bands.inverse_diagonal.data();
    for (int r = 0; r < n; ++r) {
      const DiagonalRowStep end = newmark_diagonal_row(u[r], v[r], a[r], tau, half, quarter_sq, load[r], ground_end,
                                                       mass[r], c[r], k[r], inverse_d[r]);
      u_new[r] = end.u;
      v_new[r] = end.v;
      a_new[r] = end.a;
    }
    return;
  }
  // −w1 and −w2 (the column loop's x_j = −1·w_j, negated once instead of at each of its uses; −(−w2)
  // is w2 exactly), and the solve's vector before and after the diagonal, padded: indices −B …
  // n − 1 + B. The pads before row 0 are never written. Those after row n − 1 are rows of a larger
  // phase stepped earlier (a phase with locked links has fewer rows), so they are zeroed here: a
  // stale ±∞ or NaN there would make 0·x a NaN.
  double* __restrict w1 = band_w1_.data() + kPad;
  double* __restrict w2 = band_w2_.data() + kPad;
  double* __restrict y = band_y_.data() + kPad;
  double* __restrict x = band_x_.data() + kPad;
  for (int e = n; e < n + B; ++e) {
    w1[e] = 0.0;
    w2[e] = 0.0;
    x[e] = 0.0;
  }
  for (int i = 0; i < n; ++i) {
    const NewmarkPredictors w = newmark_predictors(u[i], v[i], a[i], tau, half, quarter_sq);
    w1[i] = w.minus_w1;
    w2[i] = w.minus_w2;
  }
  // Row r (banded_forward_row): the terms a column loop adds to it, in its order, then the forward
  // solve; D⁻¹ kept apart: the rows below read the value before it.
  const double* __restrict c = bands.damping.data();
  const double* __restrict k = bands.stiffness.data();
  const double* __restrict lower = bands.lower.data() + static_cast<std::ptrdiff_t>(B) * B;  // column 0
  const double* __restrict inverse_d = bands.inverse_diagonal.data();
  for (int r = 0; r < n; ++r) {
    const std::ptrdiff_t row = static_cast<std::ptrdiff_t>(r) * kRow;
    y[r] = banded_forward_row<B, 1>(load[r], ground_end, mass[r], c + row, k + row, w1, w2, y, lower, r);
    x[r] = inverse_d[r] * y[r];
  }
  // Backward with Lᵀ; each DOF's end state as soon as its acceleration is final.
  for (int i = n - 1; i >= 0; --i) {
    x[i] = banded_backward_row<B, 1>(x, lower, i);
    const DiagonalRowStep end = newmark_end(w2[i], v[i], a[i], half, quarter_sq, x[i]);
    u_new[i] = end.u;
    v_new[i] = end.v;
    a_new[i] = end.a;
  }
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
  blame_worst_element(smooth, by_element, previous_force_, outcome);
  return outcome;  // `to` holds the last iterate (finish() at the loop's top)
}

}  // namespace poundsim
