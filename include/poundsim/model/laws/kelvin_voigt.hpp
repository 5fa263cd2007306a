#pragma once
/// @file
/// The linear viscoelastic (Kelvin–Voigt) contact of Anagnostopoulos (1988), "Pounding of
/// buildings in series during earthquakes", Earthquake Eng. Struct. Dyn. 16(3), 443–456: a
/// spring and a dashpot in parallel that act while the shortening s = d − δ is positive,
///
///     F = k s + c ṡ,   c = 2 ξ √(k m̄),   ξ = −ln e / √(π² + ln² e)              [N]
///
/// with m̄ = m_a m_b / (m_a + m_b) of the two floors it joins. ξ is chosen so that two free masses
/// separating where s returns to 0 (the displacement criterion) part with exactly e times their
/// closing speed after a contact of π/ω_d, ω_d = √(k/m̄) √(1 − ξ²). It has no stop: no impacts,
/// no locking (traits.has_stop = false). Under the force criterion (analysis.separation =
/// "force") it separates where F would pull, and its free end relaxes like the paper's element's
/// (spring_dashpot.hpp); the achieved restitution is then below e.
///
/// Modes: open (F = 0), contact (F = k s + c ṡ). Its parameters are k, δ and e; c follows from
/// the masses, which make_links binds (bind_masses).

#include <array>
#include <cmath>
#include <numbers>
#include <optional>
#include <span>
#include <string_view>
#include <tuple>

#include "poundsim/fields.hpp"
#include "poundsim/model/contact_state.hpp"
#include "poundsim/model/laws/contact_law.hpp"
#include "poundsim/model/laws/law_traits.hpp"
#include "poundsim/model/laws/spring_dashpot.hpp"

namespace poundsim {

struct KelvinVoigt {
  struct Parameters {
    double stiffness = 0.0;    ///< k [N/m], > 0.
    double gap = 0.0;          ///< δ [m], ≥ 0: the clear distance at rest.
    double restitution = 1.0;  ///< e ∈ [0, 1]: the restitution the dashpot is tuned to.

    static constexpr auto fields() {
      using P = Parameters;
      return std::tuple{
          NumberField{"stiffness", &P::stiffness, "N/m", positive, "k, the spring", true},
          NumberField{"gap", &P::gap, "m", non_negative, "δ, the clear distance at rest", true},
          NumberField{"restitution", &P::restitution, "", unit_interval,
                      "e, which sets the dashpot c = 2ξ√(k m̄)", true},
      };
    }
    [[nodiscard]] std::optional<FieldRule> rule_violation() const { return std::nullopt; }
    [[nodiscard]] bool operator==(const Parameters&) const = default;
  };
  /// Its name in a model file: `law = "kelvin_voigt"`.
  static constexpr std::string_view key = "kelvin_voigt";
  static constexpr std::array<std::string_view, 1> locked_length_keys{"gap"};

  enum class Mode : LinkMode { open, contact };
  using State = SpringDashpot::FreeEnd;

  Parameters parameters;
  /// c [N·s/m], from e and the masses of the two floors (bind_masses); 0 until bound.
  double damping = 0.0;

  static constexpr LawTraits traits{
      .piecewise_linear = true,
      .has_stop = false,
      .energy = EnergyGroup::gap_element,
      .name = "the Kelvin–Voigt contact"};

  [[nodiscard]] bool operator==(const KelvinVoigt&) const = default;

  /// ξ = −ln e / √(π² + ln² e): 1 (critical) for e = 0, 0 for e = 1.
  [[nodiscard]] static double damping_ratio(double e);
  /// Sets c = 2 ξ √(k m̄) for floors of masses m_a and m_b [kg].
  void bind_masses(double mass_a, double mass_b);

  [[nodiscard]] double gap() const { return parameters.gap; }
  /// It never locks; the element needs the gap only.
  [[nodiscard]] double locked_length() const { return parameters.gap; }
  [[nodiscard]] SpringDashpot spring_dashpot() const { return {parameters.stiffness, damping}; }
  [[nodiscard]] static bool in_contact(LinkMode mode) { return mode == static_cast<LinkMode>(Mode::contact); }

  [[nodiscard]] std::optional<LinearForm> linear_form(LinkMode mode) const {
    if (!in_contact(mode)) return std::nullopt;
    return LinearForm{.stiffness = parameters.stiffness, .damping = damping,
                      .force_at_zero = -(parameters.stiffness * parameters.gap)};
  }

  // The energy interface every law has.
  /// ½ k s² in contact, ½ k s_e² of a relaxing free end [J].
  [[nodiscard]] double stored_energy(const LinkKinematics& k, LinkMode mode, const State& state) const {
    const double s = in_contact(mode) ? shortening(k) : spring_dashpot().free_end(state, k.t);
    return 0.5 * (parameters.stiffness * s * s);
  }
  [[nodiscard]] double dissipated_power(const LinkKinematics& k, LinkMode mode, const State& /*state*/) const {
    const double rate = k.va - k.vb;
    return in_contact(mode) ? damping * rate * rate : 0.0;
  }
  [[nodiscard]] double trapezoidal_power(const LinkKinematics& k0, const LinkKinematics& k1, LinkMode mode,
                                         const State& /*state*/) const {
    const double rate = 0.5 * (k0.va + k1.va - k0.vb - k1.vb);
    return in_contact(mode) ? damping * rate * rate : 0.0;
  }
  [[nodiscard]] double relaxation_release(LinkMode mode, const State& state, double t0, double t1) const {
    return in_contact(mode) ? 0.0 : spring_dashpot().relaxation_release(state, t0, t1);
  }

  // The contact law (contact_law.hpp): guard 0 is the approach of an open element, guard 1 the
  // separation in contact.
  /// Open, or in contact when s > 0 at rest.
  [[nodiscard]] LinkMode initial_mode(double d) const {
    return static_cast<LinkMode>(d - parameters.gap > 0 ? Mode::contact : Mode::open);
  }
  void guards(const LinkKinematics& k, LinkMode mode, const State& state, const GuardContext& context,
              std::span<GuardValue, 2> out) const {
    const double s = shortening(k);
    if (in_contact(mode)) {
      out[0] = {};
      out[1] = spring_dashpot().separation_guard(k, s, position_noise(k), context.separation);
    } else {
      out[0] = spring_dashpot().approach_guard(k, s, position_noise(k), state);
      out[1] = {};
    }
  }
  [[nodiscard]] GuardForm guard_form(int guard, LinkMode mode, SeparationCriterion separation) const;
  [[nodiscard]] Relaxation relaxation(LinkMode mode, const State& state, double t) const {
    return in_contact(mode) ? Relaxation{} : spring_dashpot().relaxation(state, t);
  }
  [[nodiscard]] Transition on_guard(int guard, const LinkKinematics& k, LinkMode& mode, State& state,
                                    SeparationCriterion separation) const;
  [[nodiscard]] double force(const LinkKinematics& k, LinkMode mode, const State& /*state*/) const {
    return in_contact(mode) ? spring_dashpot().force(shortening(k), k.va - k.vb) : 0.0;
  }
  [[nodiscard]] double shortening(const LinkKinematics& k) const { return k.ua - k.ub - parameters.gap; }
  /// s − s_e: how far the floors are past the free end (it has no stop).
  [[nodiscard]] double stop_distance(const LinkKinematics& k, LinkMode /*mode*/, const State& state) const {
    return shortening(k) - spring_dashpot().free_end(state, k.t);
  }
  [[nodiscard]] static bool stop_guard_is_active(LinkMode /*mode*/) { return false; }
  /// Round-off level of s [m].
  [[nodiscard]] double position_noise(const LinkKinematics& k) const {
    return SpringDashpot::position_noise(k, parameters.gap);
  }
  [[nodiscard]] double restitution() const { return parameters.restitution; }
  /// Never reached (no stop): contact.
  [[nodiscard]] static LinkMode locked_mode() { return static_cast<LinkMode>(Mode::contact); }
};

static_assert(ContactLaw<KelvinVoigt>);

}  // namespace poundsim
