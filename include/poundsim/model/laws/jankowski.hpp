#pragma once
/// @file
/// The nonlinear viscoelastic contact of Jankowski (2005), "Non-linear viscoelastic modelling of
/// earthquake-induced structural pounding", Earthquake Eng. Struct. Dyn. 34(6), 595–611:
///
///     F = β s^{3/2} + c ṡ   while approaching (ṡ > 0)
///     F = β s^{3/2}         while restoring (ṡ ≤ 0)
///     c = 2 ξ √(β √s m̄),   ξ = 9√5 (1 − e²) / (2e (e (9π − 16) + 16))
///
/// with m̄ = m_a m_b / (m_a + m_b) of the two floors (bound by make_links). The dashpot acts on
/// approach only, so the force never pulls; it is continuous at ṡ = 0, with a kink. e ∈ (0, 1].

#include <cmath>
#include <numbers>
#include <optional>
#include <string_view>
#include <tuple>

#include "poundsim/fields.hpp"
#include "poundsim/model/laws/smooth_contact.hpp"

namespace poundsim {

struct JankowskiForce {
  struct Parameters {
    double stiffness = 0.0;    ///< β [N/m^{3/2}], > 0.
    double gap = 0.0;          ///< δ [m], ≥ 0.
    double restitution = 1.0;  ///< e ∈ (0, 1]: sets ξ.

    static constexpr auto fields() {
      using P = Parameters;
      return std::tuple{
          NumberField{"stiffness", &P::stiffness, "N/m^1.5", positive, "β of F = β s^{3/2} + c ṡ", true},
          NumberField{"gap", &P::gap, "m", non_negative, "δ, the clear distance at rest", true},
          NumberField{"restitution", &P::restitution, "", Interval{.lo = 0.0, .hi = 1.0, .lo_open = true},
                      "e, which sets ξ", true},
      };
    }
    [[nodiscard]] std::optional<FieldRule> rule_violation() const { return std::nullopt; }
    [[nodiscard]] bool operator==(const Parameters&) const = default;
  };
  using State = NoState;
  static constexpr std::string_view key = "jankowski";
  static constexpr const char* name = "Jankowski's contact";

  /// ξ = 9√5 (1 − e²) / (2e (e (9π − 16) + 16)).
  [[nodiscard]] static double damping_ratio(double e) {
    return 9.0 * std::sqrt(5.0) * (1.0 - e * e) / (2.0 * e * (e * (9.0 * std::numbers::pi - 16.0) + 16.0));
  }
  [[nodiscard]] static ForceTangent force(const Parameters& p, double reduced_mass, double s, double rate,
                                          const State& /*state*/) {
    const double root = std::sqrt(s);
    ForceTangent f{.force = p.stiffness * s * root, .stiffness = 1.5 * p.stiffness * root};
    if (rate > 0) {
      // c = 2ξ√(β m̄) s^{1/4}: ∂(c ṡ)/∂s = c ṡ / (4 s).
      const double c = 2.0 * damping_ratio(p.restitution) * std::sqrt(p.stiffness * reduced_mass * root);
      f.force += c * rate;
      f.stiffness += 0.25 * c * rate / s;
      f.damping = c;
    }
    return f;
  }
  [[nodiscard]] static double elastic_force(const Parameters& p, double s) { return p.stiffness * s * std::sqrt(s); }
  [[nodiscard]] static double elastic_energy(const Parameters& p, double s) {
    return 0.4 * p.stiffness * s * s * std::sqrt(s);
  }
  [[nodiscard]] static State on_contact(const Parameters& /*p*/, double /*closing_speed*/) { return {}; }
};

/// Jankowski's contact law.
using Jankowski = SmoothContactLaw<JankowskiForce>;
static_assert(ContactLaw<Jankowski>);

}  // namespace poundsim
