#pragma once
/// @file
/// The linear equations of motion that hold while the contact configuration does not change.
///
/// In full coordinates (floor displacements u relative to the ground, see DofLayout):
///
///     M ü + C_S u̇ + K_S u = −M·1·a_g(t) + f_S
///
/// M is diagonal (floor masses); C_S and K_S are the frames' tridiagonal storey matrices plus, for
/// every element in contact or locked, the paper's modifications (C_ii += c, C_ij = −c, ...); f_S
/// holds +kδ on the left floor and −kδ on the right floor of those elements (the paper's a(t)).
///
/// A locked element is a rigid link u_L − u_R = ℓ, its length when it locked (δ + ε up to the
/// event tolerance: the link keeps the floors where they were, so locking moves nothing). Links
/// merge floors into groups that move as one; with the 0/1 matrix T (floor → group) and the
/// offsets o (o = 0 for the leftmost floor of each group), u = T q + o and the reduced system is
///
///     M_r q̈ + C_r q̇ + K_r q = −m_r a_g(t) + b_r,   M_r = TᵀMT, C_r = TᵀC_S T, K_r = TᵀK_S T,
///     m_r = TᵀM1, b_r = Tᵀ(f_S − K_S o).
///
/// The constraint forces of the links are internal to the groups and vanish from it.
/// Groups are contiguous in the DOF numbering, so the reduced matrices stay banded.
///
/// The Newmark effective matrix M_r + (h/2) C_r + (h²/4) K_r is factorised once for the step h
/// given at construction (step_solver) and on demand for other sub-step lengths (substep_solver).
///
/// A link whose law is smooth in its mode (a Hertz-type contact, Link::smooth_in) adds no linear
/// terms: its force F(d, ḋ) is an extra load, −F on floor a and +F on floor b, which Newmark's
/// Newton iterations solve with the tangent matrix M_r + (τ/2)(C_r + C_t) + (τ²/4)(K_r + K_t), where
/// K_t and C_t hold each smooth link's ∂F/∂d and ∂F/∂ḋ in its two groups (tangent_solver). The
/// pattern of the effective matrix includes those entries, so both share one analysis.

#include <span>
#include <vector>

#include <Eigen/Core>
#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>

#include "poundsim/dynamics/state.hpp"
#include "poundsim/model/contact_state.hpp"
#include "poundsim/model/laws/smooth_contact.hpp"
#include "poundsim/model/model.hpp"

namespace poundsim {

class LinearPhase {
 public:
  using SparseMatrix = Eigen::SparseMatrix<double>;
  /// Sparse LDLᵀ in the natural (banded) order, reading the upper triangle: Eigen's, whose
  /// numeric factorisation is called directly. In this order factorize() only points at the
  /// matrix, but it builds an empty temporary matrix first — one allocation per factorisation,
  /// which Newton's iterations would make at every step.
  class Solver : public Eigen::SimplicialLDLT<SparseMatrix, Eigen::Upper, Eigen::NaturalOrdering<int>> {
   public:
    /// The numeric factorisation of `a`, whose pattern analyzePattern() saw. Allocation-free.
    void factorize_in_place(const SparseMatrix& a) { this->template factorize_preordered<true>(a); }
    /// The factors without copies (Eigen's matrixL() wraps a view, its vectorD() copies D):
    /// L's strictly lower entries, column-major, and D, for the lean Newmark step's solve.
    [[nodiscard]] const SparseMatrix& unit_lower_factor() const { return this->m_matrix; }
    [[nodiscard]] const Eigen::VectorXd& diagonal_factor() const { return this->m_diag; }
  };

  /// Assembles the system of `configuration` for the Newmark step `step` [s]. The factorisations
  /// throw SimulationError when the effective matrix cannot be factorised.
  LinearPhase(const Model& model, const DofLayout& layout, ContactConfiguration configuration,
              double step);

  LinearPhase(const LinearPhase&) = delete;
  LinearPhase& operator=(const LinearPhase&) = delete;

  [[nodiscard]] Eigen::Index reduced_size() const { return mass_.size(); }
  /// The Newmark step h given at construction [s].
  [[nodiscard]] double step() const { return step_; }
  /// True when no element is locked (T = I, o = 0).
  [[nodiscard]] bool is_unreduced() const { return unreduced_; }

  /// Group (reduced DOF) of each floor DOF.
  [[nodiscard]] std::span<const int> group_of() const { return group_of_; }
  /// The floor DOF whose values gather() takes for each group (its leftmost floor).
  [[nodiscard]] std::span<const int> representatives() const { return representative_; }
  /// o: floor displacement minus its group coordinate [m].
  [[nodiscard]] const Eigen::VectorXd& offset() const { return offset_; }
  /// Sets the lengths ℓ of the rigid links (by gap element; others ignored), which fix the
  /// offsets o and the constant load b_r. Construction uses ℓ = δ + ε. Allocation-free.
  void set_link_lengths(std::span<const double> length);

  /// Whether a link's force at zero in this configuration depends on its law's State (a yielding
  /// storey's plastic drift, StateLoadedLaw): then set_law_states must follow every change of it.
  [[nodiscard]] bool has_state_loads() const { return !state_loaded_.empty(); }
  /// Sets the part of the constant load that the laws' States set (−f₀ on floor a, +f₀ on b).
  /// Allocation-free.
  void set_law_states(const LinkStates& states);

  // Both take views, so that parts of work buffers can be passed without copies; sizes must
  // match (reduced_size() and the layout's size). Allocation-free.

  /// q = the values of a full vector at the leftmost floor of each group.
  void gather(const Eigen::Ref<const Eigen::VectorXd>& full,
              Eigen::Ref<Eigen::VectorXd> reduced) const;
  /// full = T q (+ o when `add_offset`).
  void scatter(const Eigen::Ref<const Eigen::VectorXd>& reduced, Eigen::Ref<Eigen::VectorXd> full,
               bool add_offset) const;

  // Reduced system.
  [[nodiscard]] const Eigen::VectorXd& mass() const { return mass_; }
  [[nodiscard]] const SparseMatrix& damping() const { return damping_; }
  [[nodiscard]] const SparseMatrix& stiffness() const { return stiffness_; }
  [[nodiscard]] const Eigen::VectorXd& constant_load() const { return constant_load_; }

  /// A link whose law is smooth in this configuration: tracked link `element`, whose deformation
  /// is `dofs` over the floors and `groups` over the reduced coordinates (the same terms with the
  /// DOFs replaced by their groups, the coefficients of one group added).
  struct SmoothLink {
    int element = 0;
    LinkDofs dofs{};
    LinkDofs groups{};
    int first_slot = 0, end_slot = 0;  ///< Its range of tangent_slots_.
  };
  [[nodiscard]] std::span<const SmoothLink> smooth_links() const { return smooth_links_; }
  [[nodiscard]] bool has_smooth_links() const { return !smooth_links_.empty(); }
  /// Adds the smooth links' loads, −F n (−F on group a and +F on group b), to a reduced vector
  /// (`by_element`: each gap element's force and tangent, indexed by element).
  void add_smooth_loads(std::span<const ForceTangent> by_element, Eigen::Ref<Eigen::VectorXd> reduced) const;
  /// Factorisation of M_r + (τ/2)(C_r + C_t) + (τ²/4)(K_r + K_t) with the tangents of the smooth
  /// links (`by_element`, as above), valid until the next call. Throws SimulationError on failure.
  /// Allocation-free.
  const Solver& tangent_solver(double tau, std::span<const ForceTangent> by_element) const;

  // Full system (for forces on individual floors).
  [[nodiscard]] const Eigen::VectorXd& full_mass() const { return mass_full_; }
  [[nodiscard]] const SparseMatrix& full_damping() const { return damping_full_; }
  [[nodiscard]] const SparseMatrix& full_stiffness() const { return stiffness_full_; }
  [[nodiscard]] const Eigen::VectorXd& full_constant_load() const { return load_full_; }

  /// Sets the accelerations from the phase's equation of motion at the state's time, with
  /// `ground` = a_g there: ü = M⁻¹(−m a_g + b − C u̇ − K u − f_smooth), f_smooth the smooth links'
  /// forces there (by element; empty when the phase has none). Used after every event, when the
  /// phase or the velocities change.
  void equilibrate(double ground, KinematicState& state, std::span<const ForceTangent> smooth = {}) const;

  /// Factorisation of M_r + (h/2) C_r + (h²/4) K_r for the step given at construction, made on
  /// first use.
  [[nodiscard]] const Solver& step_solver() const {
    if (!step_factorised_) factorize_step();
    return step_solver_;
  }

  /// C, K and the step solver's factors as dense bands, for the Newmark step of a phase whose
  /// effective matrix is banded: F frames interleaved floor by floor have a half-bandwidth F (a
  /// storey joins DOFs F apart; two one-storey frames apart: 0). With locked links they are the
  /// reduced matrices', whose groups are contiguous: merging floors narrows no band. Read by rows
  /// with a bandwidth known at compile time, a step needs no index arrays and no loop per column
  /// (NewmarkIntegrator). Entries inside the band that the sparse matrices do not store are zeros.
  struct Bands {
    static constexpr int kMaxWidth = 4;
    /// b, the largest |i − j| of a stored entry; −1 when the phase has no bands (smooth links, or
    /// b > kMaxWidth: frame damping that couples distant floors, column strikes).
    int width = -1;
    /// Row r holds the entries (r, r − b) … (r, r + b): (2b + 1) n values each, zero outside.
    std::vector<double> damping, stiffness;
    /// Column i of the step solver's unit lower L holds (i + 1, i) … (i + b, i), for i = −b … n − 1
    /// (b leading columns of zeros, zeros below row n − 1): (n + b) b values.
    std::vector<double> lower;
    std::vector<double> inverse_diagonal;  ///< 1/D of the step solver, n values
  };
  /// The bands when `solver` is this phase's step_solver() and the phase has them, else null.
  [[nodiscard]] const Bands* bands_for(const Solver& solver) const {
    return bands_.width >= 0 && step_factorised_ && &solver == &step_solver_ ? &bands_ : nullptr;
  }
  /// Factorisation for a sub-step τ ≠ h (event location, last partial step). The returned solver
  /// is valid until the next call. Throws SimulationError on failure.
  const Solver& substep_solver(double tau) const;

 private:
  /// The full matrices and loads of every link in its mode and of the frames' own damping;
  /// returns each floor's group leader (floors joined by rigid links share one).
  std::vector<int> assemble(const Model& model, const DofLayout& layout);
  /// The groups (one representative each) and the smooth links' terms by group.
  void make_groups(const std::vector<int>& leader);
  /// The reduced system M_r, C_r, K_r and its constant load (the full one when no link is rigid).
  void reduce(const Model& model);
  /// The effective matrix's pattern and its M, C, K values aligned with it.
  void make_effective();
  /// Where each smooth link's tangent adds to the effective matrix.
  void make_tangent_slots();
  /// Factorises M_r + (τ/2) C_r + (τ²/4) K_r, plus the smooth links' tangents when `smooth`
  /// (by element) is given.
  void factorize(Solver& solver, double tau, std::span<const ForceTangent> smooth = {}) const;
  /// step_solver()'s first use: the factorisation for the step, and the bands' factors.
  void factorize_step() const;

  ContactConfiguration configuration_;
  bool unreduced_ = true;
  struct RigidLink {
    int a, b, element;
  };
  std::vector<RigidLink> rigid_links_;  ///< In link order: each b joins a's group.
  std::vector<int> group_of_;
  std::vector<int> representative_;
  Eigen::VectorXd offset_;

  Eigen::VectorXd mass_full_;
  SparseMatrix damping_full_, stiffness_full_;
  Eigen::VectorXd load_full_;
  Eigen::VectorXd load_of_forms_;  ///< load_full_ without the laws' State parts
  /// The links whose f₀ depends on their State, with their modes here.
  struct StateLoadedLink {
    Link link;
    LinkDofs dofs;
    LinkMode mode;
  };
  std::vector<StateLoadedLink> state_loaded_;

  Eigen::VectorXd mass_;
  SparseMatrix damping_, stiffness_;
  Eigen::VectorXd constant_load_;
  SparseMatrix transfer_t_;              ///< Tᵀ (empty when unreduced).
  Eigen::VectorXd load_work_;
  mutable Eigen::VectorXd q_work_, qd_work_, rhs_work_;  ///< equilibrate()'s, sized once

  // Upper-triangular pattern of the effective matrix and the aligned M, C, K values.
  mutable SparseMatrix effective_;
  Eigen::VectorXd effective_m_, effective_c_, effective_k_;

  /// An entry of effective_'s values that a smooth link's tangent adds to, times n_i n_j of its
  /// groups' terms (the diagonal and the upper triangle; none for a force internal to a group);
  /// each link's range is SmoothLink::first_slot … end_slot.
  struct TangentSlot {
    Eigen::Index slot = -1;
    double coefficient = 0.0;
  };
  std::vector<SmoothLink> smooth_links_;
  std::vector<TangentSlot> tangent_slots_;
  mutable Solver tangent_solver_;

  /// Fills bands_ (sizes and C, K; the reduced ones with locked links) for a phase whose bandwidth
  /// allows it.
  void make_bands();

  double step_ = 0.0;
  mutable Bands bands_;  ///< L and 1/D filled with the step solver
  mutable bool step_factorised_ = false;
  mutable Solver step_solver_;
  mutable Solver substep_solver_;
};

}  // namespace poundsim
