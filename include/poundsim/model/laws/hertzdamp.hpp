#pragma once
/// @file
/// The Hertzdamp contact of Muthukumar & DesRoches (2006), "A Hertz contact model with non-linear
/// damping for pounding simulation", Earthquake Eng. Struct. Dyn. 35(7), 811–828: a Hertz-type
/// spring with a damping term proportional to it,
///
///     F = k_h sⁿ (1 + ξ̄ ṡ / v₀)                                                    [N]
///
/// with v₀ the closing speed ṡ at the contact's onset and ξ̄ from the restitution e it is meant to
/// give, by one of two derivations (damping_model):
///
///     lankarani_nikravesh   ξ̄ = 3 (1 − e²) / 4      Lankarani & Nikravesh (1990), J. Mech.
///                                                   Des. 112(3), 369–376: accurate for e near 1
///     ye_li_zhu             ξ̄ = 8 (1 − e) / (5 e)   Ye, Li & Zhu (2009), Earthquake Eng. Struct.
///                                                   Dyn. 38(9), 1109–1116: e > 0
///
/// Where the formula would pull (ṡ < −v₀/ξ̄, which ye_li_zhu reaches for small e) the force is held
/// at 0: the floors cannot pull on each other. docs/model.md tabulates the restitution each
/// achieves against its target. A grazing contact (v₀ → 0) would make the damping infinite: v₀ is
/// taken at least minimum_closing_speed, which is also the v₀ of a contact present from the start.

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <optional>
#include <string_view>
#include <tuple>
#include <utility>

#include "poundsim/fields.hpp"
#include "poundsim/model/laws/smooth_contact.hpp"

namespace poundsim {

/// How Hertzdamp's ξ̄ follows from the restitution e.
enum class HertzdampDamping : std::uint8_t { lankarani_nikravesh, ye_li_zhu };

struct HertzdampForce {
  struct Parameters {
    double stiffness = 0.0;    ///< k_h [N/mⁿ], > 0.
    double gap = 0.0;          ///< δ [m], ≥ 0.
    double exponent = 1.5;     ///< n ≥ 1 (3/2: Hertz).
    double restitution = 1.0;  ///< e ∈ [0, 1] (> 0 for ye_li_zhu): the restitution ξ̄ is set for.
    HertzdampDamping damping_model = HertzdampDamping::lankarani_nikravesh;
    double minimum_closing_speed = 1e-3;  ///< [m/s] > 0: the least v₀ (grazing contacts).

    static constexpr auto fields() {
      using P = Parameters;
      return std::tuple{
          NumberField{"stiffness", &P::stiffness, "N/m^n", positive, "k_h of F = k_h sⁿ (1 + ξ̄ ṡ/v₀)", true},
          NumberField{"gap", &P::gap, "m", non_negative, "δ, the clear distance at rest", true},
          // n < 1 would give the spring an infinite tangent n k_h sⁿ⁻¹ at first touch, where
          // Newton's iterations cannot converge; measured pounding exponents are 1 … 2.
          NumberField{"exponent", &P::exponent, "", Interval{.lo = 1.0}, "n (3/2: Hertz)"},
          NumberField{"restitution", &P::restitution, "", unit_interval, "e, which sets ξ̄", true},
          ChoiceField{"damping_model", &P::damping_model,
                      std::array{std::pair<std::string_view, HertzdampDamping>{
                                     "lankarani_nikravesh", HertzdampDamping::lankarani_nikravesh},
                                 std::pair<std::string_view, HertzdampDamping>{"ye_li_zhu",
                                                                               HertzdampDamping::ye_li_zhu}},
                      "ξ̄ = 3(1 − e²)/4 (Lankarani & Nikravesh) or 8(1 − e)/(5e) (Ye, Li & Zhu)"},
          NumberField{"minimum_closing_speed", &P::minimum_closing_speed, "m/s", positive,
                      "the least v₀: a grazing contact's damping stays finite"},
      };
    }
    [[nodiscard]] std::optional<FieldRule> rule_violation() const {
      if (damping_model == HertzdampDamping::ye_li_zhu && !(restitution > 0)) {
        return FieldRule{{"restitution", "damping_model"},
                         "must be > 0 with damping_model = \"ye_li_zhu\" (ξ̄ = 8(1 − e)/(5e))"};
      }
      return std::nullopt;
    }
    [[nodiscard]] bool operator==(const Parameters&) const = default;
  };
  /// The closing speed v₀ of the current contact [m/s].
  struct State {
    double closing_speed = 0.0;
    void shift_clock(double /*origin*/) {}
    [[nodiscard]] bool operator==(const State&) const = default;
  };
  static constexpr std::string_view key = "hertzdamp";
  static constexpr const char* name = "the Hertzdamp contact";

  /// sⁿ; s^{3/2} (the default n) as s√s, six times faster than std::pow: a step evaluates it
  /// dozens of times per contact (Newton's iterates, energy, guards, peaks).
  [[nodiscard]] static double power(double s, double n) { return n == 1.5 ? s * std::sqrt(s) : std::pow(s, n); }
  /// ξ̄ of the damping model for restitution e.
  [[nodiscard]] static double damping_factor(const Parameters& p) {
    const double e = p.restitution;
    return p.damping_model == HertzdampDamping::lankarani_nikravesh ? 0.75 * (1.0 - e * e)
                                                                     : 8.0 * (1.0 - e) / (5.0 * e);
  }
  [[nodiscard]] static ForceTangent force(const Parameters& p, double /*reduced_mass*/, double s, double rate,
                                          const State& state) {
    const double spring = p.stiffness * power(s, p.exponent);
    // A contact present from the start has no onset: v₀ is then the least, as for a grazing one.
    const double per_speed = damping_factor(p) / std::max(state.closing_speed, p.minimum_closing_speed);
    const double factor = 1.0 + per_speed * rate;
    if (!(factor > 0)) return {};  // it would pull: held at 0
    return {.force = spring * factor,
            .stiffness = p.exponent * spring / s * factor,
            .damping = spring * per_speed};
  }
  [[nodiscard]] static double elastic_force(const Parameters& p, double s) { return p.stiffness * power(s, p.exponent); }
  /// k_h s^{n+1} / (n + 1).
  [[nodiscard]] static double elastic_energy(const Parameters& p, double s) {
    return p.stiffness * s * power(s, p.exponent) / (p.exponent + 1.0);
  }
  [[nodiscard]] static State on_contact(const Parameters& p, double closing_speed) {
    return {std::max(closing_speed, p.minimum_closing_speed)};
  }
};

/// The Hertzdamp contact law.
using Hertzdamp = SmoothContactLaw<HertzdampForce>;
static_assert(ContactLaw<Hertzdamp>);

}  // namespace poundsim
