#pragma once
/// @file
/// The pounding system: the frames and gap elements as links with laws (model/law.hpp), the
/// ground motion, and the rules of its events — what does not change while it is integrated.
/// Its changing part, besides the floors' kinematics (KinematicState), is a ContactState: the
/// mode of each gap element's law (the contact configuration), each link law's State, the
/// hysteresis of each element's guard and the length a locked element holds.
///
/// The integrators (integrate/) advance the state between events and ask the system for
/// everything else: its guards (witness functions of the contact laws, positive = fired, with
/// their rates and the stop reactions of locked elements), and what the fired guards do — mode
/// changes, impacts with restitution (simultaneous pairs and chains resolved in sequence), the
/// locking of pairs pressed together. The laws answer for their own links; the system keeps what
/// acts on several links at once (the stop reactions along chains of rigid links, impact
/// resolution, locking). It names no law. See docs/model.md for the event rules and
/// docs/architecture.md for the split between system, integrators and loop.
///
/// The system is const while it is integrated (only set_excitation changes it, between runs):
/// every function takes the contact state it reads or changes. Applying
/// events needs the phase (linear system) of each configuration the events pass through and
/// reports each event; the loop that owns the phases and the monitors provides both as an
/// EventHandler.

#include <limits>
#include <optional>
#include <span>
#include <vector>

#include "poundsim/dynamics/event.hpp"
#include "poundsim/dynamics/link_kinematics.hpp"
#include "poundsim/dynamics/linear_phase.hpp"
#include "poundsim/dynamics/state.hpp"
#include "poundsim/model/contact_state.hpp"
#include "poundsim/model/excitation.hpp"
#include "poundsim/model/law.hpp"
#include "poundsim/model/model.hpp"

namespace poundsim {


/// The rules of the system's events (the event keys of [analysis], docs/input.md). SI units;
/// TimeHistoryOptions validates them.
struct EventRules {
  SeparationCriterion separation = SeparationCriterion::displacement;
  double event_tolerance = 1e-10;  ///< [s] event times are bracketed to this width
  /// [s] a pressed pair whose next flight would be shorter than this locks.
  double lock_time = 1e-6;
  /// An impact closing slower than this fraction of its floors' speeds is plastic (e = 0).
  double rest_velocity_ratio = 1e-4;
};

/// What changes at events, per tracked link (the gap elements in Model::gaps order, then the
/// storeys whose laws have modes: Link::element), and what is derived from it. The impact
/// quantities (bias, link_length, stop reactions) are the gap elements'; a storey's stay 0.
struct ContactState {
  ContactConfiguration config;     ///< The mode of each tracked link's law: the phase's key.
  LinkStates states;               ///< What each link's law keeps between events (its State).
  std::vector<double> bias;        ///< Hysteresis of each element's approach guard [m].
  std::vector<double> link_length; ///< u_L − u_R of each locked element when it locked [m].

  // Derived, kept by the system:
  std::vector<char> transmits;     ///< The law transmits a force in its mode.
  std::vector<char> rigid;         ///< The link is rigid in its mode (a locked element).
  std::vector<double> stop_reaction;  ///< λ of locked elements at the last guard evaluation [N].
  std::vector<double> stop_noise;     ///< Round-off level of each λ [N].

  // Scratch, sized once.
  std::vector<double> link_in;  ///< The chain sweep of stop reactions, per DOF.
  std::vector<int> impacts;     ///< Elements whose stops fired at an instant.
  std::vector<ForceTangent> smooth;  ///< The smooth laws' forces and tangents, by element.
};

/// What applying events needs from the loop that runs the system: the phases, and an ear.
class EventHandler {
 public:
  virtual ~EventHandler() = default;
  /// The configuration of `contact` changed: makes its phase current — factorised, with the
  /// lengths of its locked links — and returns it. The system then refreshes the derived flags.
  virtual LinearPhase& activate(const ContactState& contact) = 0;
  /// An event of tracked link `gap` (Link::element: a gap element below gap_count(), a yielding
  /// storey above) at x.t; the velocities after it are those of `x`. The floors' velocities
  /// before and the impulse of an impact or lock [N·s].
  virtual void on_event(const KinematicState& x, int gap, EventKind kind, double left_before,
                        double right_before, double impulse) = 0;
  /// Impacts and locks at one instant dissipated `loss` [J] of kinetic energy.
  virtual void on_impact_loss(double loss) = 0;
  /// The velocities of floors `left` and `right` and of their groups (`group`, of each floor) were
  /// replaced by the restitution law with `restitution` (impact.hpp): one step of an impact's
  /// resolution, reported for the sensitivities of periodic orbits (the velocity map is linear).
  virtual void on_pair_impact(std::span<const int> /*group*/, int /*left*/, int /*right*/, double /*mass_left*/,
                              double /*mass_right*/, double /*restitution*/) {}
  /// Every floor took its group's centre-of-mass velocity (the plastic merge of a lock).
  virtual void on_merge(std::span<const int> /*group*/, const Eigen::VectorXd& /*floor_mass*/,
                        const Eigen::VectorXd& /*group_mass*/) {}
};

class PoundingSystem {
 public:
  /// The model must be valid (validate(model)); `excitation` too (validate(excitation)).
  PoundingSystem(Model model, Excitation excitation, EventRules rules);

  [[nodiscard]] const Model& model() const { return model_; }
  [[nodiscard]] const DofLayout& layout() const { return layout_; }
  [[nodiscard]] const Excitation& excitation() const { return excitation_; }
  [[nodiscard]] const EventRules& rules() const { return rules_; }
  /// Every link, storeys first (make_links).
  [[nodiscard]] const std::vector<Link>& links() const { return links_; }
  /// The links of the gap elements, in Model::gaps order.
  [[nodiscard]] std::span<const Link> contact_links() const {
    return std::span<const Link>(tracked_links_).first(static_cast<std::size_t>(gaps_));
  }
  [[nodiscard]] int gap_count() const { return gaps_; }
  /// The links the contact configuration tracks, by Link::element: the gap elements, then the
  /// storeys whose laws have modes or smooth forces (yielding storeys).
  [[nodiscard]] std::span<const Link> tracked_links() const { return tracked_links_; }
  [[nodiscard]] int tracked_count() const { return static_cast<int>(tracked_links_.size()); }
  /// The gap elements' links by law, for loops that run at every step (no dispatch per link).
  [[nodiscard]] const LinkTable& contact_table() const { return contact_table_; }
  /// Every tracked link by law.
  [[nodiscard]] const LinkTable& tracked_table() const { return tracked_table_; }
  /// The linear form of a tracked storey or gap element's law in its current mode, with the
  /// force its State sets (a plastic drift) in f₀; nothing when it transmits no linear force.
  [[nodiscard]] std::optional<LinearForm> linear_form(const Link& link, const ContactState& c) const;

  /// Another ground motion (a frequency sweep's next point), in place: the one change a system
  /// takes, between runs; references to its model and links stay valid.
  void set_excitation(Excitation excitation) { excitation_ = std::move(excitation); }

  /// a_g(t) [m/s²]. Inline: every trial step asks it.
  [[nodiscard]] double ground_acceleration(double t) const { return poundsim::ground_acceleration(excitation_, t); }
  /// ½ vᵀ M v [J], summed as the energy meter sums it.
  [[nodiscard]] double kinetic_energy(const Eigen::VectorXd& v) const;

  /// The contact state at x (each law's initial mode and State, nothing locked). Throws
  /// std::invalid_argument naming the element whose law cannot start there.
  [[nodiscard]] ContactState initial_contact(const KinematicState& x) const;
  /// Refreshes the derived flags of every element from its mode (after activate()).
  void refresh_flags(ContactState& c) const;

  /// The two guards of each tracked link at x (2p: approach or stop, or yield up; 2p + 1:
  /// separation or unlock, or yield down; a yielding storey's unload is 2p),
  /// minus their round-off levels (−∞ when inactive), and their rates; computes the stop
  /// reactions of the locked elements into c first.
  void evaluate_guards(const KinematicState& x, const LinearPhase& phase, ContactState& c,
                       std::span<double> g, std::span<double> dg) const;
  /// One guard's entry in g and dg as evaluate_guards writes it: the law's value, less the
  /// element's impact hysteresis `bias` when the guard takes it, less its round-off level; −∞
  /// (never fires) with rate 0 when inactive. The lockstep kernel (integrate/lockstep.hpp) writes
  /// the same entries through it.
  [[gnu::always_inline]] static void guard_entry(const GuardValue& v, double bias, double& g, double& dg) {
    if (!v.active) {
      g = -std::numeric_limits<double>::infinity();
      dg = 0.0;
      return;
    }
    g = (v.hysteresis ? v.value - bias : v.value) - v.noise;
    dg = v.rate;
  }
  /// λ and its round-off level of every locked element at x, into c.
  void compute_stop_reactions(const KinematicState& x, const LinearPhase& phase, ContactState& c) const;

  /// s of element p at x [m].
  [[nodiscard]] double shortening(const KinematicState& x, int p) const;
  /// The force element p transmits at x [N], compression positive, its stop reaction included
  /// (as of the last guard evaluation); 0 when open.
  [[nodiscard]] double gap_force(const KinematicState& x, const ContactState& c, int p) const;
  /// The same for a link of the contact table, whose law is known: the loops that run at every
  /// accepted state call it with no dispatch.
  template <class LinkOfLaw>
    requires requires(const LinkOfLaw& l) { l.law; l.slot; }
  [[nodiscard]] static double gap_force(const KinematicState& x, const ContactState& c, const LinkOfLaw& link) {
    const auto p = static_cast<std::size_t>(link.element);
    const double force = link.law.force(detail::kinematics(x, link), c.config[p], c.states.at(link));
    return c.rigid[p] != 0 ? force + c.stop_reaction[p] : force;
  }

  /// Applies the events whose guards `fired` (> 0) at x — mode changes, impacts, locks — and
  /// then sets the accelerations, the guards g, dg at the new state and the impact hysteresis.
  /// Events may trigger others at the same instant: the caller applies again while g fires.
  /// Returns the phase current at the end.
  LinearPhase& apply_events(std::span<const double> fired, KinematicState& x, ContactState& c,
                            LinearPhase& phase, std::span<double> g, std::span<double> dg,
                            EventHandler& handler) const;
  /// Sets ü from the equation of motion of `phase` at x.t (after the velocities or the phase
  /// changed), with the forces of the smooth laws at x (c.smooth is its scratch).
  void equilibrate(LinearPhase& phase, KinematicState& x, ContactState& c) const;
  /// Whether some link's law commits its State at every accepted state (CommittingLaw).
  [[nodiscard]] bool has_committing_laws() const { return has_committing_laws_; }
  /// Commits those States at the accepted state x (trial becomes committed).
  void commit_states(const KinematicState& x, ContactState& c) const;
  /// The force and tangent of every element whose law is smooth (SmoothLaw), at x, into
  /// `by_element` (others untouched). No dispatch per link; allocation-free.
  void smooth_forces(const KinematicState& x, const ContactState& c, std::span<ForceTangent> by_element) const;

 private:
  void refresh_flags(ContactState& c, std::size_t p) const;
  LinearPhase& activate(ContactState& c, EventHandler& handler) const;
  /// Applies the impacts of the elements in c.impacts with the neighbours they drive into their
  /// stops, then locks the pairs left pressed together.
  LinearPhase& resolve_impacts(KinematicState& x, ContactState& c, LinearPhase& phase,
                               EventHandler& handler) const;
  struct ImpactScratch;
  /// resolve_impacts' first step: pairwise restitution of the involved pairs, the most closing
  /// first, until none approaches.
  void restitution_sweeps(ImpactScratch& s, Eigen::VectorXd& v, const ContactState& c, const LinearPhase& phase,
                          EventHandler& handler) const;
  /// Involves the pairs at their stops that the impulses drive into them; true if any joined.
  bool join_pairs_at_stops(ImpactScratch& s, const KinematicState& x, const ContactState& c,
                           std::span<const int> group) const;
  /// The involved pairs pressed together that would bounce for less than lock_time.
  std::vector<int> pairs_to_lock(ImpactScratch& s, const KinematicState& x, const ContactState& c,
                                 const LinearPhase& phase) const;
  /// Locks `locking` and merges each new group plastically; returns the new phase.
  LinearPhase& lock_and_merge(std::span<const int> locking, KinematicState& x, ContactState& c,
                              EventHandler& handler) const;
  /// s minus the stop of element p (ε in contact, the free end when open), minus its bias [m].
  [[nodiscard]] double stop_guard(const KinematicState& x, const ContactState& c, std::size_t p) const;
  [[nodiscard]] bool stop_guard_is_active(const ContactState& c, std::size_t p) const;
  void set_impact_biases(const KinematicState& x, ContactState& c, std::span<double> g) const;

  Model model_;
  DofLayout layout_;
  Excitation excitation_;
  EventRules rules_;
  std::vector<Link> links_;
  int gaps_ = 0;
  std::vector<Link> tracked_links_;  ///< By Link::element: the gap elements first.
  LinkTable contact_table_;  ///< The contact links by law, for the loops of every step.
  LinkTable tracked_table_;
  bool has_committing_laws_ = false;
  Eigen::VectorXd mass_;     ///< Floor masses in DOF order [kg].
};

}  // namespace poundsim
