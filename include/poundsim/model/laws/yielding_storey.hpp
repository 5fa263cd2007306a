#pragma once
/// @file
/// What the yielding storey laws share (bilinear_storey.hpp, bouc_wen.hpp): a yield given as a
/// force or as a drift, and the storey's dashpot C alongside the hysteretic springs.

#include <optional>

#include "poundsim/fields.hpp"
#include "poundsim/model/laws/contact_law.hpp"

namespace poundsim::yielding_storey {

/// Exactly one of the yield force F_y and the yield drift u_y is given (> 0).
[[nodiscard]] inline std::optional<FieldRule> yield_rule(double yield_force, double yield_drift) {
  if ((yield_force > 0) == (yield_drift > 0)) {
    return FieldRule{{"yield_force", "yield_drift"},
                     "give either yield_force (F_y) or yield_drift (u_y = F_y / K), one of them > 0"};
  }
  return std::nullopt;
}

/// F_y [N] of a storey of stiffness K given F_y or u_y.
[[nodiscard]] inline double yield_force(double stiffness, double yield_force, double yield_drift) {
  return yield_force > 0 ? yield_force : stiffness * yield_drift;
}

/// C ḋ² [W] of the storey's dashpot at k.
[[nodiscard]] inline double dashpot_power(double damping, const LinkKinematics& k) {
  const double rate = k.va - k.vb;
  return damping * rate * rate;
}

/// C ḋ̄² with ḋ̄ the mean rate of a step (the trapezoidal rule Newmark satisfies) [W].
[[nodiscard]] inline double trapezoidal_dashpot_power(double damping, const LinkKinematics& k0,
                                                      const LinkKinematics& k1) {
  const double rate = 0.5 * (k0.va + k1.va - (k0.vb + k1.vb));
  return damping * rate * rate;
}

}  // namespace poundsim::yielding_storey
