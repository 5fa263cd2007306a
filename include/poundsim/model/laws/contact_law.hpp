#pragma once
/// @file
/// What a contact law (a law between the floors of neighbouring buildings, with modes and events)
/// declares to the simulator, besides LawTraits and its linear form: its guards (witness
/// functions whose crossing of zero from below is an event), their affine form for the exact
/// integrator, and what happens at each event. The system keeps the algorithms that act on
/// several links at once — the stop reactions of rigid links, impacts with restitution and the
/// locking of pairs pressed together — and asks the laws for their part (stop guard,
/// restitution, the mode a lock leads to); a law whose traits say has_stop = false never has an
/// active stop guard.
///
/// The law's state is its mode (in the contact configuration, which selects the phase) and its
/// own `State` (law_traits.hpp's LawState: the paper's element keeps the free end of a spring
/// and dashpot that separated compressed), which only its events change. The guard hysteresis after an impact (the simulator's impact bias, which keeps a
/// pair released a hair past its stop from firing again) is not the law's: the simulator
/// subtracts it from the guards the law marks `hysteresis`.

#include <concepts>
#include <cstdint>
#include <optional>
#include <span>
#include <string_view>
#include <type_traits>

#include "poundsim/fields.hpp"
#include "poundsim/model/contact_state.hpp"
#include "poundsim/model/laws/law_traits.hpp"

namespace poundsim {

/// The two floors of a link at a state: displacements [m], velocities [m/s], accelerations
/// [m/s²], all relative to the ground, and the time [s].
struct LinkKinematics {
  double ua = 0.0, ub = 0.0;
  double va = 0.0, vb = 0.0;
  double aa = 0.0, ab = 0.0;
  double t = 0.0;
};

/// m̄ = m_a m_b / (m_a + m_b) [kg]: the reduced mass of two floors, to which the contact laws with
/// a tuned dashpot bind it (make_links calls their bind_masses).
[[nodiscard]] inline double reduced_mass(double mass_a, double mass_b) { return mass_a * mass_b / (mass_a + mass_b); }

/// What the system supplies to the guards.
struct GuardContext {
  SeparationCriterion separation = SeparationCriterion::displacement;
  double reaction = 0.0;        ///< λ of a rigid link (the stop reaction, compression positive) [N]
  double reaction_noise = 0.0;  ///< its round-off level [N]
};

/// One guard at a state: it fires when value − hysteresis − noise > 0.
struct GuardValue {
  bool active = false;
  double value = 0.0;  ///< in the guard's unit (m or N)
  double rate = 0.0;   ///< its time derivative (NaN when unknown: event location bisects)
  double noise = 0.0;  ///< its round-off level: within it, the guard is zero
  bool hysteresis = false;  ///< the simulator subtracts the element's impact hysteresis
};

/// A guard as an affine function of the link, for the exact integrator:
/// g = d_coefficient·d + rate_coefficient·ḋ + constant (the constant is taken from the guard's
/// value at the start of each segment), or −λ with λ the stop reaction of the rigid link
/// (reaction: an unlock guard), or inactive.
struct GuardForm {
  enum class Kind : std::uint8_t { inactive, affine, reaction } kind = Kind::inactive;
  double d_coefficient = 0.0;
  double rate_coefficient = 0.0;
};

/// A relaxing free end in a guard, g = … − amplitude·exp(−rate (t − t₀)), for the exact integrator.
struct Relaxation {
  double amplitude = 0.0;  ///< [m] at the segment's start
  double rate = 0.0;       ///< [1/s]
};

/// What a fired guard does to its link.
enum class Transition : std::uint8_t {
  contact,     ///< the mode changed to contact (event "contact")
  separation,  ///< the mode changed to open (event "separation")
  unlock,      ///< a rigid link released (event "unlock")
  impact,      ///< the stop was reached: the system resolves the impact
  yield,       ///< a storey began to yield (event "yield")
  unload,      ///< a yielding storey turned back: elastic again, with a new plastic drift
};

/// A law with modes and events, storey or gap element: its initial mode, its two guards in each
/// mode (witness functions that fire when they rise through zero), their affine forms for the
/// exact integrator, and what each guard does to its mode and State. The system evaluates the
/// guards of every such link and applies their events; a guard that has no meaning in a mode is
/// inactive.
template <class L>
concept EventLaw = LawState<typename L::State> &&
                   requires(const L& law, const LinkKinematics& k, LinkMode mode,
                            const typename L::State& state, const GuardContext& context,
                            std::span<GuardValue, 2> out, LinkMode& mode_out,
                            typename L::State& state_out) {
  { law.initial_mode(0.0) } -> std::same_as<LinkMode>;
  law.guards(k, mode, state, context, out);
  { law.guard_form(0, mode, SeparationCriterion::displacement) } -> std::same_as<GuardForm>;
  { law.relaxation(mode, state, 0.0) } -> std::same_as<Relaxation>;
  { law.on_guard(0, k, mode_out, state_out, SeparationCriterion::displacement) }
      -> std::same_as<Transition>;
  { law.force(k, mode, state) } -> std::same_as<double>;
};

/// The interface the simulator uses for gap elements: an EventLaw with a shortening, a stop and
/// what a model file says of it. PaperGap is the first model of it.
template <class L>
concept ContactLaw = EventLaw<L> &&
                     requires(const L& law, const LinkKinematics& k, LinkMode mode,
                              const typename L::State& state) {
  { law.shortening(k) } -> std::same_as<double>;
  { law.stop_distance(k, mode, state) } -> std::same_as<double>;
  { law.stop_guard_is_active(mode) } -> std::same_as<bool>;
  { law.position_noise(k) } -> std::same_as<double>;
  { law.restitution() } -> std::same_as<double>;
  { law.locked_mode() } -> std::same_as<LinkMode>;
  // What a model file and the model say of the element (io/input.cpp reads `law = "<key>"` and
  // then the declared fields of its Parameters; model.hpp's GapElement carries the law):
  { L::key } -> std::convertible_to<std::string_view>;
  requires std::same_as<std::remove_cvref_t<decltype(law.parameters)>, typename L::Parameters>;
  { law.gap() } -> std::same_as<double>;  ///< δ [m]: the clear distance at rest
  { law.locked_length() } -> std::same_as<double>;  ///< d [m] held by locked_mode()
  { L::locked_length_keys.front() } -> std::convertible_to<std::string_view>;  ///< what it sums
  /// The first rule between the parameters that is broken: the key to blame and why.
  { law.parameters.rule_violation() } -> std::same_as<std::optional<FieldRule>>;
};

}  // namespace poundsim
