#pragma once
/// @file
/// The unilateral visco-elastic gap element (Pasquino, Santini & Caliò, eqs. 2–4).
///
/// An element joins floor i of frame L (on the left) to floor i of frame R = L+1 (on the right).
/// Its shortening is
///
///     s = u_L − u_R − δ                                         [m]
///
/// where u are floor displacements relative to the ground (positive to the right) and δ ≥ 0 is
/// the gap. The element is open while s ≤ 0. While 0 < s < ε the spring k and the dashpot c act
/// in parallel and push the floors apart with
///
///     F = c ṡ + k s                                             [N], F > 0 is compression
///
/// (−F on the left floor, +F on the right one). When s reaches the allowable shortening ε the
/// spring is fully compressed and the floors collide: their velocities jump by the restitution
/// law (see impact.hpp). k = c = ε = 0 is bare pounding: the floors collide as soon as the gap
/// closes.

#include <optional>
#include <string>

#include "poundsim/fields.hpp"

namespace poundsim {

/// Mechanical properties of one gap element. SI units.
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

/// Throws std::invalid_argument naming `what` and the field when a property is out of range or
/// breaks the rule between them.
void validate(const GapProperties& p, const std::string& what);

}  // namespace poundsim
