#pragma once
// The simulator's access to the contact laws of the gap elements' links (contact_law.hpp).

#include <stdexcept>
#include <type_traits>
#include <variant>

#include "poundsim/dynamics/state.hpp"
#include "poundsim/model/law.hpp"

namespace poundsim::detail {

/// Calls `f` with the contact law of `link` (links of gap elements carry one, contact_law.hpp).
template <class R, class F>
R with_contact_law(const Link& link, F&& f) {
  return std::visit<R>(
      [&](const auto& law) -> R {
        if constexpr (ContactLaw<std::decay_t<decltype(law)>>) {
          return f(law);
        } else {
          throw std::logic_error("a storey link has no contact law");
        }
      },
      link.law);
}

/// The link's two floors at `x`.
inline LinkKinematics kinematics(const KinematicState& x, const Link& link) {
  return {.ua = x.u(link.a), .ub = x.u(link.b), .va = x.v(link.a), .vb = x.v(link.b),
          .aa = x.a(link.a), .ab = x.a(link.b), .t = x.t};
}

}  // namespace poundsim::detail
