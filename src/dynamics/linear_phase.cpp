#include "poundsim/dynamics/linear_phase.hpp"

#include <algorithm>
#include <optional>
#include <utility>

#include <fmt/format.h>

#include "poundsim/error.hpp"

namespace poundsim {

namespace {
using Triplet = Eigen::Triplet<double>;

void add_link(std::vector<Triplet>& t, int i, int j, double value) {
  // A two-node element (storey or gap) between DOF i and DOF j (j < 0: the ground).
  t.emplace_back(i, i, value);
  if (j >= 0) {
    t.emplace_back(j, j, value);
    t.emplace_back(i, j, -value);
    t.emplace_back(j, i, -value);
  }
}
}  // namespace

LinearPhase::LinearPhase(const Model& model, const DofLayout& layout,
                         ContactConfiguration configuration, double step)
    : configuration_(std::move(configuration)), step_(step) {
  const int n = layout.size();

  // Full system: every link's linear form in its mode, F = k d + c ḋ + f₀ with d = u_a − u_b,
  // adds k and c to the matrices and moves −f₀ to floor a's load, +f₀ to floor b's.
  mass_full_.resize(n);
  for (int i = 0; i < n; ++i) {
    mass_full_(i) = model.frames[layout.frame_of(i)].mass[layout.floor_of(i)];
  }
  std::vector<Triplet> k_triplets, c_triplets;
  load_full_ = Eigen::VectorXd::Zero(n);
  // Groups of floors joined by rigid links. Gap elements are ordered by frame pair, so a left
  // floor's group is known before its right neighbour's.
  std::vector<int> leader(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) leader[i] = i;
  for (const Link& link : make_links(model, layout)) {
    if (link.smooth_in(mode_of(link, configuration_))) {
      smooth_links_.push_back({.element = link.element, .a = link.a, .b = link.b});
      continue;
    }
    const std::optional<LinearForm> form = link.linear_form(mode_of(link, configuration_));
    if (!form) continue;  // the link transmits nothing in this mode (an open gap element)
    add_link(k_triplets, link.a, link.b, form->stiffness);
    add_link(c_triplets, link.a, link.b, form->damping);
    if (form->force_at_zero != 0.0) {
      load_full_(link.a) -= form->force_at_zero;
      if (link.b >= 0) load_full_(link.b) += form->force_at_zero;
    }
    if (std::visit([](const auto& law) { return StateLoadedLaw<std::decay_t<decltype(law)>>; }, link.law)) {
      state_loaded_.push_back({.link = link, .mode = mode_of(link, configuration_)});
    }
    if (form->rigid) {
      leader[static_cast<std::size_t>(link.b)] = leader[static_cast<std::size_t>(link.a)];
      rigid_links_.push_back({link.a, link.b, link.element});
      unreduced_ = false;
    }
  }
  // Damping that is not a link's (dashpots to the ground, modal damping): a matrix per frame.
  for (int f = 0; f < model.frame_count(); ++f) {
    const Frame& frame = model.frames[static_cast<std::size_t>(f)];
    if (!has_frame_damping(frame)) continue;
    const Eigen::MatrixXd c = frame_damping_matrix(frame);
    for (int i = 0; i < frame.storeys(); ++i) {
      for (int j = 0; j < frame.storeys(); ++j) {
        if (c(i, j) != 0.0) c_triplets.emplace_back(layout.dof(f, i), layout.dof(f, j), c(i, j));
      }
    }
  }
  load_of_forms_ = load_full_;
  stiffness_full_.resize(n, n);
  stiffness_full_.setFromTriplets(k_triplets.begin(), k_triplets.end());
  damping_full_.resize(n, n);
  damping_full_.setFromTriplets(c_triplets.begin(), c_triplets.end());

  group_of_.assign(static_cast<std::size_t>(n), -1);
  for (int i = 0; i < n; ++i) {
    if (leader[i] == i) {
      group_of_[i] = static_cast<int>(representative_.size());
      representative_.push_back(i);
    }
  }
  for (int i = 0; i < n; ++i) group_of_[i] = group_of_[leader[i]];
  for (SmoothLink& link : smooth_links_) {
    link.group_a = group_of_[static_cast<std::size_t>(link.a)];
    link.group_b = link.b >= 0 ? group_of_[static_cast<std::size_t>(link.b)] : -1;  // −1: the ground
  }
  const auto nr = static_cast<Eigen::Index>(representative_.size());

  offset_ = Eigen::VectorXd::Zero(n);
  if (unreduced_) {
    mass_ = mass_full_;
    stiffness_ = stiffness_full_;
    damping_ = damping_full_;
    constant_load_ = load_full_;
  } else {
    SparseMatrix t(n, nr);
    std::vector<Triplet> t_triplets;
    for (int i = 0; i < n; ++i) t_triplets.emplace_back(i, group_of_[i], 1.0);
    t.setFromTriplets(t_triplets.begin(), t_triplets.end());
    transfer_t_ = t.transpose();
    mass_ = transfer_t_ * mass_full_;
    stiffness_ = transfer_t_ * stiffness_full_ * t;
    damping_ = transfer_t_ * damping_full_ * t;
    constant_load_.resize(nr);
    load_work_.resize(n);
    std::vector<double> nominal(static_cast<std::size_t>(model.gap_count()));
    for (int p = 0; p < model.gap_count(); ++p) {
      nominal[p] = std::visit([](const auto& law) { return law.locked_length(); }, model.gaps[p].law);
    }
    set_link_lengths(nominal);
  }

  // Effective-matrix pattern: the union of K_r, C_r and the diagonal, upper triangle.
  std::vector<Triplet> pattern;
  for (const SparseMatrix* m : {&stiffness_, &damping_}) {
    for (Eigen::Index j = 0; j < m->outerSize(); ++j) {
      for (SparseMatrix::InnerIterator it(*m, j); it; ++it) {
        if (it.row() <= it.col()) pattern.emplace_back(it.row(), it.col(), 0.0);
      }
    }
  }
  for (Eigen::Index i = 0; i < nr; ++i) pattern.emplace_back(i, i, 0.0);
  for (const SmoothLink& link : smooth_links_) {
    if (link.group_b >= 0 && link.group_a != link.group_b) {
      pattern.emplace_back(std::min(link.group_a, link.group_b), std::max(link.group_a, link.group_b), 0.0);
    }
  }
  effective_.resize(nr, nr);
  effective_.setFromTriplets(pattern.begin(), pattern.end());
  effective_.makeCompressed();
  const Eigen::Index nnz = effective_.nonZeros();
  effective_m_.setZero(nnz);
  effective_c_.setZero(nnz);
  effective_k_.setZero(nnz);
  for (Eigen::Index j = 0, k = 0; j < nr; ++j) {
    for (SparseMatrix::InnerIterator it(effective_, j); it; ++it, ++k) {
      effective_m_(k) = it.row() == it.col() ? mass_(j) : 0.0;
      effective_c_(k) = damping_.coeff(it.row(), it.col());
      effective_k_(k) = stiffness_.coeff(it.row(), it.col());
    }
  }
  step_solver_.analyzePattern(effective_);
  substep_solver_.analyzePattern(effective_);
  if (!smooth_links_.empty()) {
    const auto slot = [&](int row, int col) -> Eigen::Index {
      if (row > col) std::swap(row, col);
      const Eigen::Index start = effective_.outerIndexPtr()[col], end = effective_.outerIndexPtr()[col + 1];
      for (Eigen::Index k = start; k < end; ++k) {
        if (effective_.innerIndexPtr()[k] == row) return k;
      }
      return -1;
    };
    for (const SmoothLink& link : smooth_links_) {
      if (link.group_b < 0) {  // a first storey: its tangent on its floor's diagonal only
        tangent_slots_.push_back({.aa = slot(link.group_a, link.group_a)});
      } else {
        tangent_slots_.push_back(link.group_a == link.group_b
                                     ? TangentSlots{}
                                     : TangentSlots{.aa = slot(link.group_a, link.group_a),
                                                    .bb = slot(link.group_b, link.group_b),
                                                    .ab = slot(link.group_a, link.group_b)});
      }
    }
    tangent_solver_.analyzePattern(effective_);
  }
  q_work_.resize(nr);
  qd_work_.resize(nr);
  rhs_work_.resize(nr);
}

void LinearPhase::equilibrate(double ground, KinematicState& state, std::span<const ForceTangent> smooth) const {
  gather(state.u, q_work_);
  gather(state.v, qd_work_);
  rhs_work_ = constant_load_ - ground * mass_;
  rhs_work_.noalias() -= damping_ * qd_work_;
  rhs_work_.noalias() -= stiffness_ * q_work_;
  if (!smooth_links_.empty()) add_smooth_loads(smooth, rhs_work_);
  rhs_work_.array() /= mass_.array();
  state.ground = ground;
  if (unreduced_) {
    state.a = rhs_work_;
  } else {
    for (Eigen::Index i = 0; i < state.a.size(); ++i) {
      state.a(i) = rhs_work_(group_of_[static_cast<std::size_t>(i)]);
    }
  }
}

const LinearPhase::Solver& LinearPhase::step_solver() const {
  if (!step_factorised_) {
    factorize(step_solver_, step_);
    step_factorised_ = true;
  }
  return step_solver_;
}

void LinearPhase::set_law_states(const LinkStates& states) {
  if (state_loaded_.empty()) return;
  load_full_ = load_of_forms_;
  for (const StateLoadedLink& s : state_loaded_) {
    const double f0 = s.link.state_force(s.mode, states);
    load_full_(s.link.a) -= f0;
    if (s.link.b >= 0) load_full_(s.link.b) += f0;
  }
  if (unreduced_) {
    constant_load_ = load_full_;
    return;
  }
  load_work_ = load_full_;
  load_work_.noalias() -= stiffness_full_ * offset_;
  constant_load_.noalias() = transfer_t_ * load_work_;
}

void LinearPhase::set_link_lengths(std::span<const double> length) {
  if (unreduced_) return;
  offset_.setZero();
  for (const RigidLink& link : rigid_links_) {
    offset_(link.b) = offset_(link.a) - length[static_cast<std::size_t>(link.element)];
  }
  load_work_ = load_full_;
  load_work_.noalias() -= stiffness_full_ * offset_;
  constant_load_.noalias() = transfer_t_ * load_work_;
}

void LinearPhase::factorize(Solver& solver, double tau, std::span<const ForceTangent> smooth) const {
  Eigen::Map<Eigen::VectorXd> values(effective_.valuePtr(), effective_.nonZeros());
  values = effective_m_ + (0.5 * tau) * effective_c_ + (0.25 * tau * tau) * effective_k_;
  // The smooth links' tangents, at the entries of their groups (tangent_solver).
  for (std::size_t i = 0; !smooth.empty() && i < smooth_links_.size(); ++i) {
    const TangentSlots& slots = tangent_slots_[i];
    if (slots.aa < 0) continue;  // both floors in one group: the force is internal to it
    const ForceTangent& t = smooth[static_cast<std::size_t>(smooth_links_[i].element)];
    const double entry = 0.5 * tau * t.damping + 0.25 * tau * tau * t.stiffness;
    values(slots.aa) += entry;
    if (slots.bb < 0) continue;  // to the ground
    values(slots.bb) += entry;
    values(slots.ab) -= entry;
  }
  solver.factorize_in_place(effective_);
  if (solver.info() != Eigen::Success) {
    throw SimulationError(fmt::format("the Newmark {} matrix could not be factorised (step {} s)",
                                      smooth.empty() ? "effective" : "tangent", tau),
                          StopReason::singular_phase);
  }
}

void LinearPhase::add_smooth_loads(std::span<const ForceTangent> by_element, Eigen::Ref<Eigen::VectorXd> reduced) const {
  for (const SmoothLink& link : smooth_links_) {
    const double force = by_element[static_cast<std::size_t>(link.element)].force;
    reduced(link.group_a) -= force;
    if (link.group_b >= 0) reduced(link.group_b) += force;
  }
}

const LinearPhase::Solver& LinearPhase::tangent_solver(double tau, std::span<const ForceTangent> by_element) const {
  factorize(tangent_solver_, tau, by_element);
  return tangent_solver_;
}

const LinearPhase::Solver& LinearPhase::substep_solver(double tau) const {
  factorize(substep_solver_, tau);
  return substep_solver_;
}

void LinearPhase::gather(const Eigen::Ref<const Eigen::VectorXd>& full,
                         Eigen::Ref<Eigen::VectorXd> reduced) const {
  if (unreduced_) {
    reduced = full;
    return;
  }
  for (std::size_t r = 0; r < representative_.size(); ++r) {
    reduced(static_cast<Eigen::Index>(r)) = full(representative_[r]);
  }
}

void LinearPhase::scatter(const Eigen::Ref<const Eigen::VectorXd>& reduced,
                          Eigen::Ref<Eigen::VectorXd> full, bool add_offset) const {
  if (unreduced_) {
    full = reduced;
    return;
  }
  for (Eigen::Index i = 0; i < full.size(); ++i) {
    full(i) = reduced(group_of_[static_cast<std::size_t>(i)]) + (add_offset ? offset_(i) : 0.0);
  }
}

}  // namespace poundsim
