#pragma once
/// @file
/// What the smooth contact laws (Hertz, Hertzdamp, Jankowski: hertz.hpp, hertzdamp.hpp,
/// jankowski.hpp) share: two modes, open and contact, a force that is a smooth function of the
/// shortening s = d − δ and its rate while s > 0, and the consistent tangent Newton's method needs.
///
/// Contact begins when s rises through 0 and ends when s returns to 0, under either separation
/// criterion: these laws' forces never pull (Hertz and Jankowski cannot; Hertzdamp's is held at
/// 0 where its formula would), so "the force would become tensile" never ends a contact first,
/// and there is no free end to relax. They have no stop (no impacts, no locking) and no linear
/// form: Newmark solves their forces by Newton iterations; the exact integrator refuses them.

#include <algorithm>
#include <array>
#include <concepts>
#include <cmath>
#include <optional>
#include <span>
#include <string_view>

#include "poundsim/model/contact_state.hpp"
#include "poundsim/model/laws/contact_law.hpp"
#include "poundsim/model/laws/law_traits.hpp"
#include "poundsim/model/laws/spring_dashpot.hpp"

namespace poundsim {

/// A smooth law's force F [N] and its consistent tangent ∂F/∂d [N/m] and ∂F/∂ḋ [N·s/m].
struct ForceTangent {
  double force = 0.0;
  double stiffness = 0.0;
  double damping = 0.0;
};

/// What a smooth contact force model declares (HertzForce, HertzdampForce, JankowskiForce):
/// its parameters (δ among them, as `gap`), its file key and name, the State it keeps from the
/// contact's onset, and — for s > 0 — its force with the consistent tangent, its elastic part and
/// that part's energy.
template <class M>
concept SmoothForceModel = LawState<typename M::State> &&
    requires(const typename M::Parameters& p, const typename M::State& state, double x) {
      { M::key } -> std::convertible_to<std::string_view>;
      { M::name } -> std::convertible_to<const char*>;
      { p.gap } -> std::convertible_to<double>;
      { M::force(p, x, x, x, state) } -> std::same_as<ForceTangent>;  // (p, m̄, s, ṡ, state)
      { M::elastic_force(p, x) } -> std::same_as<double>;
      { M::elastic_energy(p, x) } -> std::same_as<double>;
      { M::on_contact(p, x) } -> std::same_as<typename M::State>;  // (p, closing speed ṡ₀)
    };

/// The modes, guards and events the smooth contact laws share.
struct SmoothContact {
  enum class Mode : LinkMode { open, contact };

  [[nodiscard]] static bool in_contact(LinkMode mode) { return mode == static_cast<LinkMode>(Mode::contact); }
  /// In contact when the floors start overlapping, s > 0.
  [[nodiscard]] static LinkMode initial_mode(double s) {
    return static_cast<LinkMode>(s > 0 ? Mode::contact : Mode::open);
  }
  /// Guard 0, of an open element: s (contact); guard 1, in contact: −s (separation).
  static void guards(const LinkKinematics& k, double s, double noise, LinkMode mode, std::span<GuardValue, 2> out) {
    const double rate = k.va - k.vb;
    if (in_contact(mode)) {
      out[0] = {};
      out[1] = {.active = true, .value = -s, .rate = -rate, .noise = noise};
    } else {
      out[0] = {.active = true, .value = s, .rate = rate, .noise = noise, .hysteresis = true};
      out[1] = {};
    }
  }
  /// The affine forms of the guards (the exact integrator refuses these laws; the forms are
  /// those of s all the same).
  [[nodiscard]] static GuardForm guard_form(int guard, LinkMode mode) {
    const bool contact = in_contact(mode);
    if (guard == 0 && !contact) return {.kind = GuardForm::Kind::affine, .d_coefficient = 1.0};
    if (guard == 1 && contact) return {.kind = GuardForm::Kind::affine, .d_coefficient = -1.0};
    return {};
  }
  /// Guard 1 separates, guard 0 touches.
  [[nodiscard]] static Transition on_guard(int guard, LinkMode& mode) {
    mode = static_cast<LinkMode>(guard == 1 ? Mode::open : Mode::contact);
    return guard == 1 ? Transition::separation : Transition::contact;
  }
  /// The work of a force F = F_e(s) + F_d over a Newmark step from k0 to k1, split: the elastic
  /// part is stored (its energy function), the rest F_d is dissipated, by the trapezoidal rule
  /// Newmark's average acceleration obeys — ½(F_d0 + F_d1)(d₁ − d₀) — returned as a mean power
  /// over the step [W] (the energy meter multiplies by its length).
  [[nodiscard]] static double trapezoidal_power(double dissipative0, double dissipative1, const LinkKinematics& k0,
                                                const LinkKinematics& k1) {
    const double h = k1.t - k0.t;
    if (!(h > 0)) return 0.0;
    const double stretch = (k1.ua - k1.ub) - (k0.ua - k0.ub);
    return 0.5 * (dissipative0 + dissipative1) * stretch / h;
  }
};

/// A contact law from a smooth force model: the link's law (model/law.hpp) with the modes and
/// guards of SmoothContact and the force, energy and dissipation of M. m̄ of the two floors is
/// bound by make_links (bind_masses) for the models whose force needs it (Jankowski).
template <SmoothForceModel M>
struct SmoothContactLaw {
  using Parameters = typename M::Parameters;
  using State = typename M::State;
  using Mode = SmoothContact::Mode;
  static constexpr std::string_view key = M::key;
  static constexpr std::array<std::string_view, 1> locked_length_keys{"gap"};
  static constexpr LawTraits traits{
      .piecewise_linear = false, .newton = true, .has_stop = false, .energy = EnergyGroup::gap_element, .name = M::name};

  Parameters parameters;
  double reduced_mass = 0.0;  ///< m̄ = m_a m_b / (m_a + m_b) [kg]; 0 until bound.

  [[nodiscard]] bool operator==(const SmoothContactLaw&) const = default;
  void bind_masses(double mass_a, double mass_b) { reduced_mass = poundsim::reduced_mass(mass_a, mass_b); }

  [[nodiscard]] double gap() const { return parameters.gap; }
  [[nodiscard]] double locked_length() const { return parameters.gap; }
  [[nodiscard]] static std::optional<LinearForm> linear_form(LinkMode /*mode*/) { return std::nullopt; }
  [[nodiscard]] static bool carries_force(LinkMode mode) { return SmoothContact::in_contact(mode); }
  [[nodiscard]] double shortening(const LinkKinematics& k) const { return k.ua - k.ub - parameters.gap; }

  /// F and its tangent; 0 when open or not overlapping.
  [[nodiscard]] ForceTangent force_tangent(const LinkKinematics& k, LinkMode mode, const State& state) const {
    const double s = shortening(k);
    if (!carries_force(mode) || !(s > 0)) return {};
    return M::force(parameters, reduced_mass, s, k.va - k.vb, state);
  }
  [[nodiscard]] double force(const LinkKinematics& k, LinkMode mode, const State& state) const {
    return force_tangent(k, mode, state).force;
  }
  /// The energy of the elastic part of F [J].
  [[nodiscard]] double stored_energy(const LinkKinematics& k, LinkMode mode, const State& /*state*/) const {
    const double s = shortening(k);
    return carries_force(mode) && s > 0 ? M::elastic_energy(parameters, s) : 0.0;
  }
  /// (F − F_e) ṡ [W]: what is not elastic is dissipated (when Hertzdamp's force is held at 0,
  /// the elastic energy it does not return).
  [[nodiscard]] double dissipated_power(const LinkKinematics& k, LinkMode mode, const State& state) const {
    return dissipative_force(k, mode, state) * (k.va - k.vb);
  }
  [[nodiscard]] double trapezoidal_power(const LinkKinematics& k0, const LinkKinematics& k1, LinkMode mode,
                                         const State& state) const {
    if (!carries_force(mode)) return 0.0;
    return SmoothContact::trapezoidal_power(dissipative_force(k0, mode, state), dissipative_force(k1, mode, state),
                                            k0, k1);
  }
  [[nodiscard]] static double relaxation_release(LinkMode /*mode*/, const State& /*state*/, double /*t0*/,
                                                 double /*t1*/) {
    return 0.0;
  }

  // The contact law (contact_law.hpp).
  [[nodiscard]] LinkMode initial_mode(double d) const { return SmoothContact::initial_mode(d - parameters.gap); }
  void guards(const LinkKinematics& k, LinkMode mode, const State& /*state*/, const GuardContext& /*context*/,
              std::span<GuardValue, 2> out) const {
    SmoothContact::guards(k, shortening(k), position_noise(k), mode, out);
  }
  [[nodiscard]] static GuardForm guard_form(int guard, LinkMode mode, SeparationCriterion /*separation*/) {
    return SmoothContact::guard_form(guard, mode);
  }
  [[nodiscard]] static Relaxation relaxation(LinkMode /*mode*/, const State& /*state*/, double /*t*/) { return {}; }
  /// At contact the model keeps what it needs of the onset (Hertzdamp: the closing speed v₀).
  [[nodiscard]] Transition on_guard(int guard, const LinkKinematics& k, LinkMode& mode, State& state,
                                    SeparationCriterion /*separation*/) const {
    const Transition t = SmoothContact::on_guard(guard, mode);
    state = t == Transition::contact ? M::on_contact(parameters, k.va - k.vb) : State{};
    return t;
  }
  [[nodiscard]] double stop_distance(const LinkKinematics& k, LinkMode /*mode*/, const State& /*state*/) const {
    return shortening(k);
  }
  [[nodiscard]] static bool stop_guard_is_active(LinkMode /*mode*/) { return false; }
  [[nodiscard]] double position_noise(const LinkKinematics& k) const {
    return SpringDashpot::position_noise(k, parameters.gap);
  }
  /// Never used (no stop): the restitution of impacts, which these laws do not have.
  [[nodiscard]] static double restitution() { return 1.0; }
  [[nodiscard]] static LinkMode locked_mode() { return static_cast<LinkMode>(Mode::contact); }

 private:
  [[nodiscard]] double dissipative_force(const LinkKinematics& k, LinkMode mode, const State& state) const {
    const double s = shortening(k);
    if (!carries_force(mode) || !(s > 0)) return 0.0;
    return M::force(parameters, reduced_mass, s, k.va - k.vb, state).force - M::elastic_force(parameters, s);
  }
};

}  // namespace poundsim
