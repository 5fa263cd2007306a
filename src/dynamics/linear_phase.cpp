#include "poundsim/dynamics/linear_phase.hpp"

#include <algorithm>
#include <cstdlib>
#include <optional>
#include <stdexcept>
#include <utility>

#include <fmt/format.h>

#include "poundsim/error.hpp"

namespace poundsim {

namespace {
using Triplet = Eigen::Triplet<double>;

void add_link(std::vector<Triplet>& t, const LinkDofs& dofs, double value) {
  // value·n nᵀ with d = nᵀu: a two-node element's value on the diagonal and −value off it.
  const auto terms = dofs.terms();
  for (const DofTerm& i : terms) t.emplace_back(i.dof, i.dof, value * (i.coefficient * i.coefficient));
  for (std::size_t i = 0; i < terms.size(); ++i) {
    for (std::size_t j = i + 1; j < terms.size(); ++j) {
      const double entry = value * (terms[i].coefficient * terms[j].coefficient);
      t.emplace_back(terms[i].dof, terms[j].dof, entry);
      t.emplace_back(terms[j].dof, terms[i].dof, entry);
    }
  }
}

/// −f n: a force f of the link on its floors (−f on a, +f on b between floors).
void add_link_load(Eigen::VectorXd& load, const LinkDofs& dofs, double force) {
  for (const DofTerm& t : dofs.terms()) load(t.dof) -= t.coefficient * force;
}
}  // namespace

LinearPhase::LinearPhase(const Model& model, const DofLayout& layout,
                         ContactConfiguration configuration, double step)
    : configuration_(std::move(configuration)), step_(step) {
  const int n = layout.size();
  mass_full_.resize(n);
  for (int i = 0; i < n; ++i) {
    mass_full_(i) = model.frames[layout.frame_of(i)].mass[layout.floor_of(i)];
  }
  make_groups(assemble(model, layout));
  reduce(model);
  make_effective();
  step_solver_.analyzePattern(effective_);
  substep_solver_.analyzePattern(effective_);
  if (!smooth_links_.empty()) {
    make_tangent_slots();
    tangent_solver_.analyzePattern(effective_);
  }
  const auto nr = static_cast<Eigen::Index>(representative_.size());
  q_work_.resize(nr);
  qd_work_.resize(nr);
  rhs_work_.resize(nr);
  if (smooth_links_.empty()) make_bands();
}

std::vector<int> LinearPhase::assemble(const Model& model, const DofLayout& layout) {
  const int n = layout.size();
  // Full system: every link's linear form in its mode, F = k d + c ḋ + f₀ with d = nᵀu (u_a − u_b
  // between floors, link_dofs), adds k n nᵀ and c n nᵀ to the matrices and −f₀ n to the loads
  // (−f₀ on floor a, +f₀ on floor b).
  std::vector<Triplet> k_triplets, c_triplets;
  load_full_ = Eigen::VectorXd::Zero(n);
  // Groups of floors joined by rigid links. Gap elements are ordered by frame pair, so a left
  // floor's group is known before its right neighbour's.
  std::vector<int> leader(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) leader[i] = i;
  for (const Link& link : make_links(model, layout)) {
    const LinkDofs dofs = link_dofs(link);
    if (link.smooth_in(mode_of(link, configuration_))) {
      smooth_links_.push_back({.element = link.element, .dofs = dofs});
      continue;
    }
    const std::optional<LinearForm> form = link.linear_form(mode_of(link, configuration_));
    if (!form) continue;  // the link transmits nothing in this mode (an open gap element)
    add_link(k_triplets, dofs, form->stiffness);
    add_link(c_triplets, dofs, form->damping);
    if (form->force_at_zero != 0.0) add_link_load(load_full_, dofs, form->force_at_zero);
    if (std::visit([](const auto& law) { return StateLoadedLaw<std::decay_t<decltype(law)>>; }, link.law)) {
      state_loaded_.push_back({.link = link, .dofs = dofs, .mode = mode_of(link, configuration_)});
    }
    if (form->rigid) {
      // A rigid link merges two floors into one group; a column point is not a floor (the
      // model refuses laws with a stop there, validate(Model)).
      if (!link.joins_floors()) throw std::logic_error("a rigid link at a column point");
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
  return leader;
}

void LinearPhase::make_groups(const std::vector<int>& leader) {
  const auto n = static_cast<int>(leader.size());
  group_of_.assign(static_cast<std::size_t>(n), -1);
  for (int i = 0; i < n; ++i) {
    if (leader[i] == i) {
      group_of_[i] = static_cast<int>(representative_.size());
      representative_.push_back(i);
    }
  }
  for (int i = 0; i < n; ++i) group_of_[i] = group_of_[leader[i]];
  for (SmoothLink& link : smooth_links_) {
    // The link's terms by group: floors of one group add their coefficients.
    for (const DofTerm& t : link.dofs.terms()) {
      const int group = group_of_[static_cast<std::size_t>(t.dof)];
      auto& groups = link.groups.term;
      const auto end = groups.begin() + link.groups.size;
      const auto same = std::find_if(groups.begin(), end, [&](const DofTerm& g) { return g.dof == group; });
      if (same != end) {
        same->coefficient += t.coefficient;
      } else {
        groups[static_cast<std::size_t>(link.groups.size++)] = {group, t.coefficient};
      }
    }
  }
}

void LinearPhase::reduce(const Model& model) {
  const auto n = static_cast<int>(mass_full_.size());
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
}

void LinearPhase::make_effective() {
  const auto nr = static_cast<Eigen::Index>(representative_.size());
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
    const auto groups = link.groups.terms();
    for (std::size_t i = 0; i < groups.size(); ++i) {
      for (std::size_t j = i + 1; j < groups.size(); ++j) {
        pattern.emplace_back(std::min(groups[i].dof, groups[j].dof), std::max(groups[i].dof, groups[j].dof), 0.0);
      }
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
}

void LinearPhase::make_tangent_slots() {
  const auto slot = [&](int row, int col) -> Eigen::Index {
    if (row > col) std::swap(row, col);
    const Eigen::Index start = effective_.outerIndexPtr()[col], end = effective_.outerIndexPtr()[col + 1];
    for (Eigen::Index k = start; k < end; ++k) {
      if (effective_.innerIndexPtr()[k] == row) return k;
    }
    return -1;
  };
  // The tangent t adds t n_i n_j at the groups of terms i and j: t on the diagonal of a link
  // between floors and −t off it; nothing when both floors are in one group (the force is
  // internal to it).
  for (SmoothLink& link : smooth_links_) {
    link.first_slot = static_cast<int>(tangent_slots_.size());
    const auto groups = link.groups.terms();
    for (const DofTerm& g : groups) {
      if (g.coefficient != 0.0) {
        tangent_slots_.push_back({.slot = slot(g.dof, g.dof), .coefficient = g.coefficient * g.coefficient});
      }
    }
    for (std::size_t i = 0; i < groups.size(); ++i) {
      for (std::size_t j = i + 1; j < groups.size(); ++j) {
        const double coefficient = groups[i].coefficient * groups[j].coefficient;
        if (coefficient != 0.0) {
          tangent_slots_.push_back({.slot = slot(groups[i].dof, groups[j].dof), .coefficient = coefficient});
        }
      }
    }
    link.end_slot = static_cast<int>(tangent_slots_.size());
  }
}

void LinearPhase::make_bands() {
  const auto n = static_cast<int>(effective_.outerSize());
  // Over both triangles of C and K (the effective pattern is their union and the diagonal): frame
  // damping is stored entry by entry where nonzero, and a modal damping matrix need not be
  // symmetric to the last bit (nor zero where its mirror is).
  int width = 0;
  for (const SparseMatrix* m : {&damping_, &stiffness_}) {
    for (int j = 0; j < n; ++j) {
      for (SparseMatrix::InnerIterator it(*m, j); it; ++it) width = std::max(width, std::abs(j - static_cast<int>(it.row())));
    }
  }
  if (width > Bands::kMaxWidth) return;
  const auto row_entries = static_cast<std::size_t>(2 * width + 1);
  bands_.width = width;
  bands_.damping.assign(row_entries * static_cast<std::size_t>(n), 0.0);
  bands_.stiffness.assign(row_entries * static_cast<std::size_t>(n), 0.0);
  bands_.lower.assign(static_cast<std::size_t>((n + width) * width), 0.0);
  bands_.inverse_diagonal.assign(static_cast<std::size_t>(n), 0.0);
  // Every stored entry, as the sparse products use it: (row, column) of the column-major matrix
  // (C and K are symmetric in exact arithmetic, but frame damping need not be to the last bit).
  for (const auto& [matrix, band] : {std::pair{&damping_, &bands_.damping}, std::pair{&stiffness_, &bands_.stiffness}}) {
    for (int j = 0; j < n; ++j) {
      for (SparseMatrix::InnerIterator it(*matrix, j); it; ++it) {
        const auto r = static_cast<std::size_t>(it.row());
        (*band)[r * row_entries + static_cast<std::size_t>(j - static_cast<int>(it.row()) + width)] = it.value();
      }
    }
  }
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

void LinearPhase::factorize_step() const {
  factorize(step_solver_, step_);
  if (bands_.width >= 0) {
    // The natural order keeps L's fill inside the effective matrix's band; were it not, the phase
    // would step by the sparse loops rather than with part of L.
    const int b = bands_.width;
    const SparseMatrix& l = step_solver_.unit_lower_factor();
    for (int i = 0; i < static_cast<int>(l.outerSize()) && bands_.width >= 0; ++i) {
      for (SparseMatrix::InnerIterator it(l, i); it; ++it) {
        const int r = static_cast<int>(it.row());
        if (r <= i) continue;  // the solve reads the strictly lower entries only
        if (r - i > b) {
          bands_.width = -1;
          break;
        }
        bands_.lower[static_cast<std::size_t>((i + b) * b + (r - i - 1))] = it.value();
      }
    }
    const Eigen::VectorXd& d = step_solver_.diagonal_factor();
    for (Eigen::Index i = 0; i < d.size(); ++i) bands_.inverse_diagonal[static_cast<std::size_t>(i)] = 1.0 / d(i);
  }
  step_factorised_ = true;
}

void LinearPhase::set_law_states(const LinkStates& states) {
  if (state_loaded_.empty()) return;
  load_full_ = load_of_forms_;
  for (const StateLoadedLink& s : state_loaded_) add_link_load(load_full_, s.dofs, s.link.state_force(s.mode, states));
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
    const SmoothLink& link = smooth_links_[i];
    const ForceTangent& t = smooth[static_cast<std::size_t>(link.element)];
    const double entry = 0.5 * tau * t.damping + 0.25 * tau * tau * t.stiffness;
    for (int k = link.first_slot; k < link.end_slot; ++k) {
      const TangentSlot& s = tangent_slots_[static_cast<std::size_t>(k)];
      values(s.slot) += s.coefficient * entry;
    }
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
    for (const DofTerm& g : link.groups.terms()) reduced(g.dof) -= g.coefficient * force;
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
