#pragma once
/// @file
/// The Hertz contact: an elastic force F = k_h s^{3/2} while the shortening s = d − δ is positive
/// (H. Hertz (1882), "Über die Berührung fester elastischer Körper", J. reine angew. Math. 92,
/// 156–171; for pounding, Davis (1992) and Chau & Wei (2001)). It dissipates nothing: two free
/// masses part with their closing speed (e = 1), after the largest overlap
/// s_max = (5 m̄ v₀² / (4 k_h))^{2/5} and a contact of 3.2145 (m̄² / (k_h² v₀))^{1/5}
/// (Goldsmith 1960, "Impact", ch. 4). Smooth: Newmark with Newton iterations (smooth_contact.hpp).

#include <cmath>
#include <optional>
#include <string_view>
#include <tuple>

#include "poundsim/fields.hpp"
#include "poundsim/model/laws/smooth_contact.hpp"

namespace poundsim {

struct HertzForce {
  struct Parameters {
    double stiffness = 0.0;  ///< k_h [N/m^{3/2}], > 0.
    double gap = 0.0;        ///< δ [m], ≥ 0.

    static constexpr auto fields() {
      using P = Parameters;
      return std::tuple{
          NumberField{"stiffness", &P::stiffness, "N/m^1.5", positive, "k_h of F = k_h s^{3/2}", true},
          NumberField{"gap", &P::gap, "m", non_negative, "δ, the clear distance at rest", true},
      };
    }
    [[nodiscard]] std::optional<FieldRule> rule_violation() const { return std::nullopt; }
    [[nodiscard]] bool operator==(const Parameters&) const = default;
  };
  using State = NoState;
  static constexpr std::string_view key = "hertz";
  static constexpr const char* name = "the Hertz contact";

  /// F = k_h s^{3/2}, ∂F/∂s = 3/2 k_h s^{1/2}.
  [[nodiscard]] static ForceTangent force(const Parameters& p, double /*reduced_mass*/, double s, double /*rate*/,
                                          const State& /*state*/) {
    const double root = std::sqrt(s);
    return {.force = p.stiffness * s * root, .stiffness = 1.5 * p.stiffness * root};
  }
  [[nodiscard]] static double elastic_force(const Parameters& p, double s) { return p.stiffness * s * std::sqrt(s); }
  /// 2/5 k_h s^{5/2}.
  [[nodiscard]] static double elastic_energy(const Parameters& p, double s) {
    return 0.4 * p.stiffness * s * s * std::sqrt(s);
  }
  [[nodiscard]] static State on_contact(const Parameters& /*p*/, double /*closing_speed*/) { return {}; }
};

/// The Hertz contact law.
using Hertz = SmoothContactLaw<HertzForce>;
static_assert(ContactLaw<Hertz>);

}  // namespace poundsim
