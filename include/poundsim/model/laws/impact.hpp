#pragma once
/// @file
/// The bilinear impact law of Muthukumar & DesRoches (2006), "A Hertz contact model with
/// non-linear damping for pounding simulation", Earthquake Engng Struct. Dyn. 35:811–828, as
/// OpenSees' ImpactMaterial (uniaxialMaterial ImpactMaterial K1 K2 δ_y gap) defines it. With the
/// penetration s = d − δ > 0 the force lies between two lines,
///
///     K2 s  ≤  F  ≤  K2 s + (K1 − K2) δ_y                                         [N]
///
/// and moves on K1 between them: a spring K2 in parallel with an elastic–plastic spring
/// K1 − K2 whose force F_h = (K1 − K2)(s − s_p) stays in [0, (K1 − K2) δ_y] (s_p its plastic
/// penetration, the State). A first contact loads on K1 to δ_y, then on K2 (the upper line);
/// unloading runs on K1 down to the lower line K2 s, then on it to s = 0, where the floors part
/// (F ≥ 0 throughout: the law never pulls). OpenSees decides loading or unloading from the sign of
/// each step's strain increment and starts a contact from the committed force of the step before,
/// so its step into contact adds K1 times that step's open travel; here contact is an event at
/// s = 0, which is the limit of OpenSees' law as the step shrinks.
///
/// Modes and guards (F_h = (K1 − K2)(s − s_p) while elastic):
///
///     open      F = 0                          guard: s                 (contact; s_p = 0)
///     elastic   F = K1 s − (K1 − K2) s_p       guards: s − s_p − δ_y    (upper line)
///                                                     −(s − s_p)       (lower line, or open at s_p = 0)
///     upper     F = K2 s + (K1 − K2) δ_y       guard: −ṡ                (elastic; s_p = s − δ_y)
///     lower     F = K2 s                       guards: ṡ (elastic; s_p = s), −s (open)
///
/// Energy: ½ K2 s² + ½ F_h²/(K1 − K2) is stored; the plastic spring dissipates
/// (K1 − K2) δ_y |Δs| on the upper line (plastic_work, counted as the element's dissipation), so
/// one impact reaching s_m ≥ δ_y dissipates (K1 − K2) δ_y (s_m − δ_y).
///
/// Parameters: OpenSees' K1, K2, δ_y and the gap, or Muthukumar's derivation from a Hertz
/// stiffness k_h, the expected maximum penetration δ_m, a restitution e and a = δ_y/δ_m (n = 3/2):
///
///     ΔE = k_h δ_m^{n+1} (1 − e²)/(n + 1),   K_eff = k_h √δ_m,   δ_y = a δ_m,
///     K1 = K_eff + ΔE/(a δ_m²),   K2 = K_eff − ΔE/((1 − a) δ_m²)
///
/// so that an impact reaching δ_m dissipates ΔE.

#include <array>
#include <cmath>
#include <limits>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <tuple>

#include "poundsim/fields.hpp"
#include "poundsim/model/contact_state.hpp"
#include "poundsim/model/laws/contact_law.hpp"
#include "poundsim/model/laws/law_traits.hpp"
#include "poundsim/model/laws/spring_dashpot.hpp"

namespace poundsim {

struct Impact {
  /// The exponent n of the Hertz law Muthukumar's derivation approximates.
  static constexpr double hertz_exponent = 1.5;

  struct Parameters {
    double k1 = 0.0;                 ///< K1 [N/m]; 0 when derived from stiffness.
    double k2 = 0.0;                 ///< K2 [N/m]; 0 when derived from stiffness.
    double yield_penetration = 0.0;  ///< δ_y [m]; 0 when derived from stiffness.
    double gap = 0.0;                ///< δ [m], ≥ 0.
    double stiffness = 0.0;          ///< k_h [N/m^1.5]; 0 when K1, K2, δ_y are given.
    double max_penetration = 0.0;    ///< δ_m [m], with stiffness.
    double restitution = 1.0;        ///< e ∈ [0, 1), with stiffness.
    double yield_ratio = 0.1;        ///< a = δ_y/δ_m ∈ (0, 1), with stiffness.

    static constexpr auto fields() {
      using P = Parameters;
      return std::tuple{
          NumberField{"k1", &P::k1, "N/m", non_negative, "K1, the stiffness of loading to δ_y and of unloading"},
          NumberField{"k2", &P::k2, "N/m", non_negative, "K2 < K1, the stiffness beyond δ_y"},
          NumberField{"yield_penetration", &P::yield_penetration, "m", non_negative,
                      "δ_y, the penetration at which loading turns from K1 to K2"},
          NumberField{"gap", &P::gap, "m", non_negative, "δ, the clear distance at rest", true},
          NumberField{"stiffness", &P::stiffness, "N/m^1.5", non_negative,
                      "k_h, the Hertz stiffness K1, K2, δ_y are derived from (instead of k1, k2, yield_penetration)"},
          NumberField{"max_penetration", &P::max_penetration, "m", non_negative,
                      "δ_m, the expected maximum penetration (with stiffness)"},
          NumberField{"restitution", &P::restitution, "", unit_interval,
                      "e < 1, the restitution an impact reaching δ_m has (with stiffness)"},
          NumberField{"yield_ratio", &P::yield_ratio, "", below_one, "a = δ_y/δ_m (with stiffness)"},
      };
    }
    /// OpenSees' K1, K2, δ_y or Muthukumar's k_h, δ_m, e, a: one set, whole and admissible.
    [[nodiscard]] std::optional<FieldRule> rule_violation() const {
      return stiffness > 0.0 ? derivation_violation() : direct_violation();
    }
    [[nodiscard]] bool operator==(const Parameters&) const = default;

    /// ΔE = k_h δ_m^{n+1} (1 − e²)/(n + 1) [J].
    [[nodiscard]] double target_dissipation() const {
      const double n = hertz_exponent;
      return stiffness * std::pow(max_penetration, n + 1.0) * (1.0 - restitution * restitution) / (n + 1.0);
    }
    /// K_eff = k_h √δ_m [N/m].
    [[nodiscard]] double effective_stiffness() const { return stiffness * std::sqrt(max_penetration); }
    /// K1, K2 and δ_y, given or derived.
    [[nodiscard]] double loading_stiffness() const {
      if (stiffness <= 0.0) return k1;
      return effective_stiffness() + target_dissipation() / (yield_ratio * max_penetration * max_penetration);
    }
    [[nodiscard]] double yielded_stiffness() const {
      if (stiffness <= 0.0) return k2;
      return effective_stiffness() -
             target_dissipation() / ((1.0 - yield_ratio) * max_penetration * max_penetration);
    }
    [[nodiscard]] double yield_at() const { return stiffness > 0.0 ? yield_ratio * max_penetration : yield_penetration; }

   private:
    [[nodiscard]] std::optional<FieldRule> direct_violation() const {
      if (k1 <= 0.0) return FieldRule{{"k1"}, "k1 must be > 0 (or give stiffness, max_penetration, restitution)"};
      if (yield_penetration <= 0.0) return FieldRule{{"yield_penetration"}, "yield_penetration must be > 0"};
      if (k2 >= k1) return FieldRule{{"k2"}, "k2 must be below k1: the law yields from K1 to K2"};
      if (max_penetration > 0.0 || restitution != 1.0) {
        return FieldRule{{max_penetration > 0.0 ? "max_penetration" : "restitution"},
                         "max_penetration and restitution derive K1, K2, δ_y from stiffness, which is not given"};
      }
      return std::nullopt;
    }
    [[nodiscard]] std::optional<FieldRule> derivation_violation() const {
      if (k1 > 0.0 || k2 > 0.0 || yield_penetration > 0.0) {
        return FieldRule{{k1 > 0.0 ? "k1" : k2 > 0.0 ? "k2" : "yield_penetration"},
                         "give k1, k2, yield_penetration or stiffness, max_penetration, restitution, not both"};
      }
      if (max_penetration <= 0.0) return FieldRule{{"max_penetration"}, "max_penetration must be > 0 with stiffness"};
      if (restitution >= 1.0) {
        return FieldRule{{"restitution"}, "restitution must be given and below 1 with stiffness (e = 1 dissipates nothing)"};
      }
      if (yield_ratio <= 0.0) return FieldRule{{"yield_ratio"}, "yield_ratio must be > 0"};
      if (yielded_stiffness() < 0.0) {
        return FieldRule{{"yield_ratio"}, "yield_ratio makes the derived K2 negative (the law would pull)"};
      }
      return std::nullopt;
    }
  };
  /// Its name in a model file: `law = "impact"`.
  static constexpr std::string_view key = "impact";
  static constexpr std::array<std::string_view, 1> locked_length_keys{"gap"};

  enum class Mode : LinkMode { open, elastic, upper, lower };
  /// The plastic penetration s_p of the elastic–plastic spring [m].
  struct State {
    double plastic_penetration = 0.0;
    void shift_clock(double /*origin*/) {}
    [[nodiscard]] bool operator==(const State&) const = default;
  };

  Parameters parameters;

  static constexpr LawTraits traits{
      .piecewise_linear = true, .has_stop = false, .energy = EnergyGroup::gap_element, .name = "the impact law"};

  [[nodiscard]] bool operator==(const Impact&) const = default;

  [[nodiscard]] static Mode mode(LinkMode m) { return static_cast<Mode>(m); }
  [[nodiscard]] static LinkMode as_mode(Mode m) { return static_cast<LinkMode>(m); }
  [[nodiscard]] double k1() const { return parameters.loading_stiffness(); }
  [[nodiscard]] double k2() const { return parameters.yielded_stiffness(); }
  [[nodiscard]] double yield_penetration() const { return parameters.yield_at(); }
  /// K1 − K2 [N/m]: the elastic–plastic spring.
  [[nodiscard]] double plastic_spring() const { return k1() - k2(); }
  /// (K1 − K2) δ_y [N]: its force on the upper line.
  [[nodiscard]] double plastic_spring_yield() const { return plastic_spring() * yield_penetration(); }

  /// The linear form in `mode` with s_p = 0; state_force adds the part s_p sets.
  [[nodiscard]] std::optional<LinearForm> linear_form(LinkMode m) const {
    const double gap = parameters.gap;
    switch (mode(m)) {
      case Mode::open: return std::nullopt;
      case Mode::elastic: return LinearForm{.stiffness = k1(), .force_at_zero = -k1() * gap};
      case Mode::upper: return LinearForm{.stiffness = k2(), .force_at_zero = -k2() * gap + plastic_spring_yield()};
      case Mode::lower: return LinearForm{.stiffness = k2(), .force_at_zero = -k2() * gap};
    }
    return std::nullopt;
  }
  /// The part of f₀ its State sets: −(K1 − K2) s_p while elastic [N].
  [[nodiscard]] double state_force(LinkMode m, const State& state) const {
    return mode(m) == Mode::elastic ? -plastic_spring() * state.plastic_penetration : 0.0;
  }
  /// F_h, the elastic–plastic spring's force at penetration s [N].
  [[nodiscard]] double hysteretic_force(double s, LinkMode m, const State& state) const {
    switch (mode(m)) {
      case Mode::elastic: return plastic_spring() * (s - state.plastic_penetration);
      case Mode::upper: return plastic_spring_yield();
      case Mode::open:
      case Mode::lower: return 0.0;
    }
    return 0.0;
  }
  [[nodiscard]] double force(const LinkKinematics& k, LinkMode m, const State& state) const {
    if (mode(m) == Mode::open) return 0.0;
    const double s = shortening(k);
    return k2() * s + hysteretic_force(s, m, state);
  }

  // Energy (dynamics/energy.hpp).
  [[nodiscard]] double stored_energy(const LinkKinematics& k, LinkMode m, const State& state) const {
    if (mode(m) == Mode::open) return 0.0;
    const double s = shortening(k), fh = hysteretic_force(s, m, state);
    return 0.5 * k2() * s * s + 0.5 * fh * fh / plastic_spring();
  }
  [[nodiscard]] static double dissipated_power(const LinkKinematics& /*k*/, LinkMode /*m*/, const State& /*s*/) {
    return 0.0;
  }
  [[nodiscard]] static double trapezoidal_power(const LinkKinematics& /*k0*/, const LinkKinematics& /*k1*/,
                                                LinkMode /*m*/, const State& /*s*/) {
    return 0.0;
  }
  [[nodiscard]] static double relaxation_release(LinkMode /*m*/, const State& /*s*/, double /*t0*/, double /*t1*/) {
    return 0.0;
  }
  /// (K1 − K2) δ_y Δs on the upper line, 0 elsewhere [J].
  [[nodiscard]] double plastic_work(const LinkKinematics& k0, const LinkKinematics& k1_, LinkMode m,
                                    const State& /*state*/) const {
    if (mode(m) != Mode::upper) return 0.0;
    return (shortening(k1_) - shortening(k0)) * plastic_spring_yield();
  }

  // Modes and events (contact_law.hpp).
  [[nodiscard]] LinkMode initial_mode(double d) const {
    return as_mode(d - parameters.gap > 0 ? Mode::elastic : Mode::open);
  }
  void guards(const LinkKinematics& k, LinkMode m, const State& state, const GuardContext& /*context*/,
              std::span<GuardValue, 2> out) const {
    const double s = shortening(k), rate = k.va - k.vb;
    const double s_noise = position_noise(k) + kNoise * std::abs(state.plastic_penetration);
    const double rate_noise = kNoise * (std::abs(k.va) + std::abs(k.vb));
    out[0] = {};
    out[1] = {};
    switch (mode(m)) {
      case Mode::open:
        out[0] = {.active = true, .value = s, .rate = rate, .noise = s_noise, .hysteresis = true};
        return;
      case Mode::elastic: {
        const double elastic = s - state.plastic_penetration;
        out[0] = {.active = true, .value = elastic - yield_penetration(), .rate = rate, .noise = s_noise};
        out[1] = {.active = true, .value = -elastic, .rate = -rate, .noise = s_noise};
        return;
      }
      case Mode::upper:
        out[0] = {.active = true, .value = -rate, .rate = -(k.aa - k.ab), .noise = rate_noise};
        return;
      case Mode::lower:
        out[0] = {.active = true, .value = rate, .rate = k.aa - k.ab, .noise = rate_noise};
        out[1] = {.active = true, .value = -s, .rate = -rate, .noise = s_noise};
        return;
    }
  }
  [[nodiscard]] GuardForm guard_form(int guard, LinkMode m, SeparationCriterion /*separation*/) const {
    constexpr auto affine = GuardForm::Kind::affine;
    switch (mode(m)) {
      case Mode::open: return guard == 0 ? GuardForm{.kind = affine, .d_coefficient = 1.0} : GuardForm{};
      case Mode::elastic: return {.kind = affine, .d_coefficient = guard == 0 ? 1.0 : -1.0};
      case Mode::upper: return guard == 0 ? GuardForm{.kind = affine, .rate_coefficient = -1.0} : GuardForm{};
      case Mode::lower:
        return guard == 0 ? GuardForm{.kind = affine, .rate_coefficient = 1.0}
                          : GuardForm{.kind = affine, .d_coefficient = -1.0};
    }
    return {};
  }
  [[nodiscard]] static Relaxation relaxation(LinkMode /*m*/, const State& /*s*/, double /*t*/) { return {}; }
  [[nodiscard]] Transition on_guard(int guard, const LinkKinematics& k, LinkMode& m, State& state,
                                    SeparationCriterion /*separation*/) const {
    const double s = shortening(k);
    switch (mode(m)) {
      case Mode::open:
        return enter(m, state, Mode::elastic, 0.0, Transition::contact);
      case Mode::elastic:
        if (guard == 0) return enter(m, state, Mode::upper, state.plastic_penetration, Transition::yield);
        // Unloaded to the lower line where it meets s = 0: the floors part.
        if (state.plastic_penetration <= position_noise(k)) return enter(m, state, Mode::open, 0.0, Transition::separation);
        return enter(m, state, Mode::lower, state.plastic_penetration, Transition::unload);
      case Mode::upper:
        return enter(m, state, Mode::elastic, s - yield_penetration(), Transition::unload);
      case Mode::lower:
        if (guard == 1) return enter(m, state, Mode::open, 0.0, Transition::separation);
        return enter(m, state, Mode::elastic, s, Transition::unload);
    }
    return Transition::unload;
  }

  // The contact law (contact_law.hpp).
  [[nodiscard]] double gap() const { return parameters.gap; }
  [[nodiscard]] double locked_length() const { return parameters.gap; }
  [[nodiscard]] double shortening(const LinkKinematics& k) const { return k.ua - k.ub - parameters.gap; }
  /// It has no stop: s itself.
  [[nodiscard]] double stop_distance(const LinkKinematics& k, LinkMode /*m*/, const State& /*s*/) const {
    return shortening(k);
  }
  [[nodiscard]] static bool stop_guard_is_active(LinkMode /*m*/) { return false; }
  [[nodiscard]] double position_noise(const LinkKinematics& k) const {
    return SpringDashpot::position_noise(k, parameters.gap);
  }
  /// Muthukumar's e when derived from it; 1 for OpenSees' parameters (whose restitution depends on
  /// the closing speed). Only a rigid stop replacing the law (bare pounding) reads it.
  [[nodiscard]] double restitution() const { return parameters.restitution; }
  /// Never reached (no stop).
  [[nodiscard]] static LinkMode locked_mode() { return as_mode(Mode::elastic); }

 private:
  static constexpr double kNoise = 8 * std::numeric_limits<double>::epsilon();
  static Transition enter(LinkMode& m, State& state, Mode to, double plastic, Transition t) {
    m = as_mode(to);
    state.plastic_penetration = plastic;
    return t;
  }
};

static_assert(ContactLaw<Impact>);

}  // namespace poundsim
