#pragma once
/// @file
/// Energy bookkeeping in the relative (floor-to-ground) formulation.
///
///     E₀ + E_input = T + U_storey + U_gap + D_storey + D_gap + E_impact + H_storey
///
/// E₀ is the mechanical energy of the initial conditions, E_input = −∫ a_g 1ᵀM u̇ dt the work of
/// the ground motion, T = ½ u̇ᵀM u̇, U the strain energy of the storeys (½ K Δu²) and of the
/// gap-element springs (½ k s², or ½ k s_e² for an element relaxing after a force separation),
/// D the energy dissipated by the storey and gap-element dashpots, E_impact the kinetic
/// energy lost in impacts and in locking, and H_storey the hysteretic energy of yielding storeys
/// (their plastic work, law by law: bilinear_storey.hpp).
///
/// The integrals use the trapezoidal rule on each Newmark step: Newmark's average-acceleration
/// scheme satisfies this balance exactly for a linear phase, so the residual measures round-off
/// and the energy jumps at events only — a check on the event handling, not on the step size.

#include <optional>
#include <span>
#include <vector>

#include "poundsim/dynamics/state.hpp"
#include "poundsim/model/contact_state.hpp"
#include "poundsim/model/model.hpp"

namespace poundsim {

/// The terms of the balance [J].
struct EnergyBalance {
  double initial = 0.0;         ///< E₀
  double input = 0.0;           ///< E_input
  double kinetic = 0.0;         ///< T
  double storey_strain = 0.0;   ///< U_storey
  double gap_strain = 0.0;      ///< U_gap
  double storey_damping = 0.0;  ///< D_storey
  double gap_damping = 0.0;     ///< D_gap
  double impact_loss = 0.0;     ///< E_impact
  double storey_hysteretic = 0.0;  ///< H_storey

  [[nodiscard]] double supplied() const { return initial + input; }
  [[nodiscard]] double accounted() const {
    return kinetic + storey_strain + gap_strain + storey_damping + gap_damping + impact_loss + storey_hysteretic;
  }
  /// E₀ + E_input − (everything accounted for) [J].
  [[nodiscard]] double residual() const { return supplied() - accounted(); }
};

/// The integrated powers of a phase as forms in its reduced velocities q̇ (one per group of floors
/// moving as one, linear_phase.hpp), for integrating them in closed form (exact_energy.hpp).
struct PowerForms {
  Eigen::MatrixXd storey_damping;  ///< C_s: Σ_i C_i (u̇_i − u̇_below)² = q̇ᵀ C_s q̇
  Eigen::MatrixXd gap_damping;     ///< C_g: Σ c ṡ² over the elements in contact or locked = q̇ᵀ C_g q̇
  Eigen::VectorXd mass;            ///< m_r = TᵀM1: the ground input is −a_g m_rᵀ q̇
};

/// Accumulates the balance step by step.
class EnergyMeter {
 public:
  /// Takes the masses and the links (make_links) of `model`.
  EnergyMeter(const Model& model, const DofLayout& layout);

  /// Sets E₀ and the stored terms from the initial state.
  void start(const KinematicState& x, const ContactConfiguration& config,
             const LinkStates& states);

  /// Adds one Newmark (sub-)step from x0 to x1 taken in the phase `config`, with the
  /// trapezoidal rule (exact for Newmark's average-acceleration scheme).
  void step(const KinematicState& x0, const KinematicState& x1, const ContactConfiguration& config,
            const LinkStates& states);

  /// The rates of the integrated terms at a state [W].
  struct Powers {
    double input = 0.0;           ///< −a_g 1ᵀM u̇
    double storey_damping = 0.0;  ///< Σ C_i (u̇_i − u̇_{i−1})²
    double gap_damping = 0.0;     ///< Σ c ṡ² over elements in contact or locked
  };
  [[nodiscard]] Powers powers(const KinematicState& x, const ContactConfiguration& config,
                              const LinkStates& states) const;

  /// The forms of powers() in the reduced velocities of a phase whose floor DOF i moves with group
  /// group_of[i] (of `groups`).
  [[nodiscard]] PowerForms power_forms(const ContactConfiguration& config,
                                       std::span<const int> group_of, Eigen::Index groups) const;

  /// Adds a segment from x0 to x1 whose integrals of the powers were computed elsewhere (the
  /// exact integrator integrates them on its exact trajectory, exact_energy.hpp).
  void step_with(const KinematicState& x0, const KinematicState& x1, const Powers& integrals,
                 const ContactConfiguration& config, const LinkStates& states);

  /// Re-evaluates the stored terms after an event changed the state without a step.
  void refresh(const KinematicState& x, const ContactConfiguration& config,
               const LinkStates& states) {
    update_stored(x, config, states);
  }

  /// Kinetic energy of a velocity field [J].
  [[nodiscard]] double kinetic_energy(const Eigen::VectorXd& v) const;
  /// Adds an impact or locking loss [J].
  void add_impact_loss(double loss) { balance_.impact_loss += loss; }

  [[nodiscard]] const EnergyBalance& balance() const { return balance_; }
  /// The energy each gap element's law has dissipated since start() (its dashpot or damping part,
  /// the impact law's plastic work
  /// and a relaxing free end's release; impact losses are the instant's, E_impact) [J], by
  /// element; they sum to the balance's gap_damping. Nothing when a segment was integrated
  /// elsewhere (step_with: the exact integrator's closed forms are per quadratic form, not per
  /// element).
  [[nodiscard]] std::optional<std::span<const double>> element_dissipation() const {
    if (!per_element_) return std::nullopt;
    return std::span<const double>(element_dissipation_);
  }
  /// The hysteretic energy of each storey since start() [J], by the DOF of the floor above it
  /// (0 for a storey whose law does not yield); they sum to the balance's storey_hysteretic.
  [[nodiscard]] std::span<const double> storey_hysteretic() const { return storey_hysteretic_; }
  /// |residual| / scale, with the scale the largest energy (either side of the balance) so far.
  [[nodiscard]] double relative_residual() const;
  /// The largest |residual| over the run so far, relative to the same scale.
  [[nodiscard]] double max_relative_residual() const {
    return scale_ > 0.0 ? max_residual_ / scale_ : 0.0;
  }

 private:
  void update_stored(const KinematicState& x, const ContactConfiguration& config,
                     const LinkStates& states);
  void add_relaxation(const KinematicState& x0, const KinematicState& x1,
                      const ContactConfiguration& config, const LinkStates& states);
  /// The plastic work of the yielding laws from x0 to x1 in one mode (exact from the ends).
  void add_plastic_work(const KinematicState& x0, const KinematicState& x1,
                        const ContactConfiguration& config, const LinkStates& states);
  void finish_step(const KinematicState& x1, const ContactConfiguration& config,
                   const LinkStates& states);
  /// The scale and the largest residual so far, once the terms are at the step's end.
  void track_residual();

  /// The links by law: every sum below asks each link's law (in link order within each law).
  LinkTable links_;
  /// Each frame's damping besides its storey dashpots (frame_damping_matrix), on its floors'
  /// DOFs: its power u̇ᵀ C u̇ is storey damping.
  struct FrameDashpots {
    std::vector<int> dofs;
    Eigen::MatrixXd damping;
  };
  std::vector<FrameDashpots> frame_dashpots_;
  mutable Eigen::VectorXd frame_velocity_, frame_force_;  ///< scratch, sized to the tallest frame
  /// Σ over frames of ū̇ᵀ C ū̇ with ū̇ = (v0 + v1)/2 [W]. Allocation-free.
  [[nodiscard]] double frame_damping_power(const Eigen::VectorXd& v0, const Eigen::VectorXd& v1) const;
  Eigen::VectorXd mass_;
  EnergyBalance balance_;
  std::vector<double> element_dissipation_;  ///< by gap element [J]
  std::vector<double> storey_hysteretic_;    ///< by storey (the DOF above it) [J]
  bool has_plastic_work_ = false;            ///< some storey's law yields
  bool per_element_ = true;
  double scale_ = 0.0;
  double max_residual_ = 0.0;  ///< [J]
};

}  // namespace poundsim
