#pragma once
/// @file
/// The kinematics of a link's two ends at a state (model/law.hpp): its floors, or a column point
/// between two floors (ColumnPoint), the ground for a first storey's lower end. Every law is
/// asked through these, so that a column point's interpolation is written once.

#include <cstdint>
#include <type_traits>

#include "poundsim/dynamics/state.hpp"
#include "poundsim/model/law.hpp"

namespace poundsim::detail {

/// What a caller reads of the ends: energies need no accelerations (and may be given states
/// without them).
enum class Derivatives : std::uint8_t { velocities, accelerations };

/// Floors a and b at `x` (b = −1: the ground, at rest in the relative frame: a first storey's).
/// Inlined: the loops of every step call it for every link.
template <Derivatives D = Derivatives::accelerations>
[[gnu::always_inline]] inline LinkKinematics kinematics(const KinematicState& x, int a, int b) {
  LinkKinematics k{.ua = x.u(a), .va = x.v(a), .t = x.t};
  if (b >= 0) {
    k.ub = x.u(b);
    k.vb = x.v(b);
  }
  if constexpr (D == Derivatives::accelerations) {
    k.aa = x.a(a);
    if (b >= 0) k.ab = x.a(b);
  }
  return k;
}

/// Moves an end from its floor to its column point: w·(floor) + (1 − w)·(floor below).
template <Derivatives D>
void to_column_point(const KinematicState& x, const ColumnPoint& point, double& u, double& v, double& a) {
  const double w = point.weight, rest = 1.0 - point.weight;
  u *= w;
  v *= w;
  a *= w;
  if (point.below < 0) return;  // the ground
  u += rest * x.u(point.below);
  v += rest * x.v(point.below);
  if constexpr (D == Derivatives::accelerations) a += rest * x.a(point.below);
}

/// The ends of a link with a column point (the rare case, kept out of line).
template <Derivatives D>
[[gnu::noinline]] LinkKinematics column_kinematics(const KinematicState& x, int a, int b, const ColumnPoint& a_column,
                                                   const ColumnPoint& b_column) {
  LinkKinematics k = kinematics<D>(x, a, b);
  if (!a_column.at_floor()) to_column_point<D>(x, a_column, k.ua, k.va, k.aa);
  if (!b_column.at_floor()) to_column_point<D>(x, b_column, k.ub, k.vb, k.ab);
  return k;
}

/// The two ends of a link (Link or TypedLink) at `x`.
template <Derivatives D = Derivatives::accelerations, class LinkLike>
[[gnu::always_inline]] inline LinkKinematics kinematics(const KinematicState& x, const LinkLike& link) {
  // A storey joins its floors (only gap elements strike columns): no test on its hot path.
  if constexpr (requires { typename std::decay_t<decltype(link.law)>::State; }) {
    if constexpr (!ContactLaw<std::decay_t<decltype(link.law)>>) return kinematics<D>(x, link.a, link.b);
  }
  if (link.joins_floors()) [[likely]] return kinematics<D>(x, link.a, link.b);
  if constexpr (std::is_same_v<std::decay_t<decltype(link.a_column)>, ColumnPoint>) {
    return column_kinematics<D>(x, link.a, link.b, link.a_column, link.b_column);
  } else {
    return kinematics<D>(x, link.a, link.b);  // not reached: such a link joins its floors
  }
}

}  // namespace poundsim::detail
