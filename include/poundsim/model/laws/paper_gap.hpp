#pragma once
/// @file
/// The paper's unilateral visco-elastic gap element (Pasquino, Santini & Caliò, eqs. 2–4) as a
/// law of the link from the left floor to the right one (d = u_L − u_R, F > 0 compression).
///
/// Parameters: GapProperties (k, c, δ, ε, e; below). Modes (GapMode, below):
///
///     open     F = 0                                  (s = d − δ ≤ 0, or relaxing after a
///                                                      force separation: s_e(t), PaperGap::State)
///     contact  F = k s + c ṡ = k d + c ḋ − k δ          (0 < s < ε)
///     locked   the link is rigid at s = ε: d is held; the stop adds its reaction λ ≥ 0
///
/// Events (the simulator applies them; docs/model.md): contact when s reaches 0 (or the free end
/// s_e), impact with restitution e when s reaches ε (at once when ε = 0: a rigid stop),
/// separation when s or F returns to 0, locking of a pair pressed together, unlocking when λ
/// returns to 0. Stored energy ½ k s² (½ k s_e² while relaxing), dissipated power c ṡ² in
/// contact and locked, and the relaxation's release; impact losses are booked at the impact.

#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <optional>
#include <span>
#include <string>
#include <string_view>

#include "poundsim/fields.hpp"
#include "poundsim/model/contact_state.hpp"
#include "poundsim/model/laws/contact_law.hpp"
#include "poundsim/model/laws/law_traits.hpp"
#include "poundsim/model/laws/spring_dashpot.hpp"

namespace poundsim {

// The element as the paper states it (eqs. 2–4).
//
// An element joins floor i of frame L (on the left) to floor i of frame R = L+1 (on the right).
// Its shortening is
//
//     s = u_L − u_R − δ                                         [m]
//
// where u are floor displacements relative to the ground (positive to the right) and δ ≥ 0 is
// the gap. The element is open while s ≤ 0. While 0 < s < ε the spring k and the dashpot c act
// in parallel and push the floors apart with
//
//     F = c ṡ + k s                                             [N], F > 0 is compression
//
// (−F on the left floor, +F on the right one). When s reaches the allowable shortening ε the
// spring is fully compressed and the floors collide: their velocities jump by the restitution
// law (see impact.hpp). k = c = ε = 0 is bare pounding: the floors collide as soon as the gap
// closes.

/// The paper's element's properties (the law's Parameters). SI units.
struct GapProperties {
  double stiffness = 0.0;    ///< k [N/m], ≥ 0.
  double damping = 0.0;      ///< c [N·s/m], ≥ 0.
  double gap = 0.0;          ///< δ [m], ≥ 0: the clear distance at rest.
  double shortening = 0.0;   ///< ε [m], ≥ 0: the allowable spring shortening before impact.
  double restitution = 1.0;  ///< e ∈ [0, 1]: the coefficient of restitution of the impacts.

  /// The fields a model file sets ([gap_elements] and its overrides): fields.hpp. The gap and
  /// the restitution have no default in a file. In the members' order, which the study's
  /// fingerprint and summary.json keep.
  static constexpr auto fields() {
    using P = GapProperties;
    return std::tuple{
        NumberField{"stiffness", &P::stiffness, "N/m", non_negative, "k, the spring"},
        NumberField{"damping", &P::damping, "N·s/m", non_negative, "c, the dashpot"},
        NumberField{"gap", &P::gap, "m", non_negative, "δ, the clear distance at rest", true},
        NumberField{"shortening", &P::shortening, "m", non_negative,
                    "ε, the allowable spring shortening before impact"},
        NumberField{"restitution", &P::restitution, "", unit_interval,
                    "e, the coefficient of restitution of the impacts", true},
    };
  }

  [[nodiscard]] bool operator==(const GapProperties&) const = default;

  /// True for bare pounding: the element has no stroke, contact is an impact at once.
  [[nodiscard]] bool is_rigid_stop() const { return shortening <= 0.0; }

  /// A spring or dashpot on an element without stroke (ε = 0) would never act: refused.
  [[nodiscard]] std::optional<FieldRule> rule_violation() const;
};

/// s = u_L − u_R − δ [m]: positive when the element is compressed.
[[nodiscard]] inline double shortening(const GapProperties& p, double u_left, double u_right) {
  return u_left - u_right - p.gap;
}

/// F = c ṡ + k s [N]: the force of the spring and dashpot while in contact, compression positive.
[[nodiscard]] inline double contact_force(const GapProperties& p, double s, double s_rate) {
  return p.damping * s_rate + p.stiffness * s;
}


/// The element's modes and the events that change them (see docs/model.md for the reasoning):
///
///     open ──contact (s ↑ 0)──▶ contact ──impact (s ↑ ε)──▶ contact (velocities jump)
///       ▲                         │   │                      or locked (chatter suppressed)
///       └──separation (s ↓ 0 or F ↓ 0)┘   └◀──unlock (stop reaction λ ↓ 0)── locked
///
/// For a rigid stop (ε = 0) there is no contact phase: open ──impact──▶ open or locked, and
/// unlock returns to open.
enum class GapMode : std::uint8_t {
  open,     ///< s ≤ 0 (or the element separated and has not touched again): no force.
  contact,  ///< 0 < s < ε: spring and dashpot act, F = c ṡ + k s.
  locked,   ///< s = ε held by the stop: the floors move together; the stop reaction λ ≥ 0.
};

[[nodiscard]] std::string_view to_string(GapMode mode);

struct PaperGap {
  using Parameters = GapProperties;
  /// Its name in a model file: `law = "paper"` (the default of [gap_elements]).
  static constexpr std::string_view key = "paper";

  Parameters parameters;

  /// What the element keeps between events: the free end that relaxes after a separation with
  /// its spring compressed (the force criterion), SpringDashpot::FreeEnd.
  using State = SpringDashpot::FreeEnd;
  /// Its spring and dashpot, which act while 0 < s (spring_dashpot.hpp).
  [[nodiscard]] SpringDashpot spring_dashpot() const { return {parameters.stiffness, parameters.damping}; }

  PaperGap() = default;
  // Implicit: a GapLaw (model.hpp) is made from the paper's properties as before there were laws.
  PaperGap(const Parameters& p) : parameters(p) {}  // NOLINT(google-explicit-constructor)

  [[nodiscard]] bool operator==(const PaperGap&) const = default;
  [[nodiscard]] double gap() const { return parameters.gap; }
  /// d = δ + ε: where the locked mode holds the link (s = ε).
  [[nodiscard]] double locked_length() const { return parameters.gap + parameters.shortening; }
  /// The parameters locked_length() sums (a joint narrower than it is blamed on them).
  static constexpr std::array<std::string_view, 2> locked_length_keys{"gap", "shortening"};

  static constexpr LawTraits traits{
      .piecewise_linear = true,
      .has_stop = true,
      .energy = EnergyGroup::gap_element,
      .name = "the paper's gap element"};

  [[nodiscard]] static GapMode gap_mode(LinkMode mode) { return static_cast<GapMode>(mode); }
  [[nodiscard]] static LinkMode link_mode(GapMode mode) { return static_cast<LinkMode>(mode); }

  /// Nothing while open: the element transmits no force.
  [[nodiscard]] std::optional<LinearForm> linear_form(LinkMode mode) const {
    if (gap_mode(mode) == GapMode::open) return std::nullopt;
    // Locked keeps the spring and dashpot: they act inside the rigid group and their constant
    // force enters through the link's length (linear_phase.hpp).
    return LinearForm{.stiffness = parameters.stiffness,
            .damping = parameters.damping,
            .force_at_zero = -(parameters.stiffness * parameters.gap),
            .rigid = gap_mode(mode) == GapMode::locked};
  }
  // The energy interface every law has (dynamics/energy.hpp asks it).

  /// ½ k s² (contact, locked) or ½ k s_e(t)² (open, relaxing) [J].
  [[nodiscard]] double stored_energy(const LinkKinematics& k, LinkMode mode,
                                     const State& state) const {
    const double s = gap_mode(mode) == GapMode::open ? spring_dashpot().free_end(state, k.t)
                                                     : poundsim::shortening(parameters, k.ua, k.ub);
    return 0.5 * (parameters.stiffness * s * s);
  }
  /// c ṡ² in contact and locked, 0 open [W] (the relaxation is booked apart).
  [[nodiscard]] double dissipated_power(const LinkKinematics& k, LinkMode mode, const State& /*state*/) const {
    const double rate = k.va - k.vb;
    return dashpot(mode) * rate * rate;
  }
  /// c ṡ̄² with ṡ̄ the mean of the rates at both ends of a step (the trapezoidal rule).
  [[nodiscard]] double trapezoidal_power(const LinkKinematics& k0, const LinkKinematics& k1, LinkMode mode,
                                         const State& /*state*/) const {
    const double rate = 0.5 * (k0.va + k1.va - k0.vb - k1.vb);
    return dashpot(mode) * rate * rate;
  }
  /// What a relaxing free end's spring releases into its dashpot from t0 to t1, ½ k (s_e0² − s_e1²)
  /// [J]; 0 when not relaxing.
  [[nodiscard]] double relaxation_release(LinkMode mode, const State& state, double t0,
                                          double t1) const {
    if (gap_mode(mode) != GapMode::open) return 0.0;
    return spring_dashpot().relaxation_release(state, t0, t1);
  }
  /// The dashpot c acting in `mode` [N·s/m]: 0 open.
  [[nodiscard]] double dashpot(LinkMode mode) const {
    return gap_mode(mode) == GapMode::open ? 0.0 : parameters.damping;
  }

  // The contact law (contact_law.hpp). Guard 0 is the approach guard: contact (open, s reaches
  // the free end s_e), impact (contact, s reaches ε; open with ε = 0) or unlock (locked, λ
  // returns to 0). Guard 1 is separation in contact: s or F returns to 0.

  /// The mode at rest with d = u_L − u_R: open, or contact when 0 < s < ε. Throws
  /// std::invalid_argument ("by … m, beyond its allowable shortening … m") when s ≥ ε.
  [[nodiscard]] LinkMode initial_mode(double d) const;
  /// Evaluated at every step and trial: inline.
  void guards(const LinkKinematics& k, LinkMode mode, const State& state,
              const GuardContext& context, std::span<GuardValue, 2> out) const;
  [[nodiscard]] GuardForm guard_form(int guard, LinkMode mode, SeparationCriterion separation) const;
  [[nodiscard]] Relaxation relaxation(LinkMode mode, const State& state, double t) const;
  /// Applies guard `guard` fired at `k`: changes the mode and the state, or asks for an impact.
  [[nodiscard]] Transition on_guard(int guard, const LinkKinematics& k, LinkMode& mode,
                                    State& state, SeparationCriterion separation) const;
  /// F = c ṡ + k s in contact and locked (without the stop reaction), 0 open [N].
  [[nodiscard]] double force(const LinkKinematics& k, LinkMode mode, const State& /*state*/) const {
    if (gap_mode(mode) == GapMode::open) return 0.0;
    return spring_dashpot().force(k.ua - k.ub - parameters.gap, k.va - k.vb);
  }
  /// s = u_L − u_R − δ [m].
  [[nodiscard]] double shortening(const LinkKinematics& k) const {
    return k.ua - k.ub - parameters.gap;
  }
  /// The approach guard's value without hysteresis: s − ε in contact, s − s_e open [m].
  [[nodiscard]] double stop_distance(const LinkKinematics& k, LinkMode mode,
                                     const State& state) const;
  /// True when guard 0 is the stop (an impact when it fires): in contact, or open with ε = 0.
  [[nodiscard]] bool stop_guard_is_active(LinkMode mode) const {
    return gap_mode(mode) == GapMode::contact ||
           (gap_mode(mode) == GapMode::open && parameters.is_rigid_stop());
  }
  /// Round-off level of s [m].
  [[nodiscard]] double position_noise(const LinkKinematics& k) const {
    return kNoise * (std::abs(k.ua) + std::abs(k.ub) + parameters.gap + parameters.shortening);
  }
  static constexpr double kNoise = SpringDashpot::kNoise;
  [[nodiscard]] double restitution() const { return parameters.restitution; }
  [[nodiscard]] static LinkMode locked_mode() { return link_mode(GapMode::locked); }
};

inline void PaperGap::guards(const LinkKinematics& k, LinkMode mode, const State& state,
                             const GuardContext& context, std::span<GuardValue, 2> out) const {
  const double s = shortening(k);
  const double s_noise = position_noise(k);
  switch (gap_mode(mode)) {
    case GapMode::open:
      out[0] = spring_dashpot().approach_guard(k, s, s_noise, state);
      out[1] = {};
      return;
    case GapMode::contact:
      out[0] = {.active = true, .value = s - parameters.shortening, .rate = k.va - k.vb, .noise = s_noise,
                .hysteresis = true};
      out[1] = spring_dashpot().separation_guard(k, s, s_noise, context.separation);
      return;
    case GapMode::locked:
      out[0] = {.active = true, .value = -context.reaction,
                .rate = std::numeric_limits<double>::quiet_NaN(), .noise = context.reaction_noise};
      out[1] = {};
      return;
  }
}

static_assert(ContactLaw<PaperGap>);

}  // namespace poundsim
