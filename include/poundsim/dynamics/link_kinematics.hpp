#pragma once
/// @file
/// The kinematics of a link's two ends at a state (model/law.hpp): its floors, or a column point
/// between two floors (ColumnPoint), the ground for a first storey's lower end. Every law is
/// asked through these, so that a column point's interpolation is written once.

#include <cstdint>

#include "poundsim/dynamics/state.hpp"
#include "poundsim/model/law.hpp"

namespace poundsim::detail {

/// What a caller reads of the ends: energies need no accelerations (and may be given states
/// without them).
enum class Derivatives : std::uint8_t { velocities, accelerations };

/// Floors a and b at `x` (b = −1: the ground, at rest in the relative frame: a first storey's).
template <Derivatives D = Derivatives::accelerations>
LinkKinematics kinematics(const KinematicState& x, int a, int b) {
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

/// The two ends of a link (Link or TypedLink) at `x`.
template <Derivatives D = Derivatives::accelerations, class LinkLike>
LinkKinematics kinematics(const KinematicState& x, const LinkLike& link) {
  LinkKinematics k = kinematics<D>(x, link.a, link.b);
  if (link.joins_floors()) return k;
  if (!link.a_column.at_floor()) to_column_point<D>(x, link.a_column, k.ua, k.va, k.aa);
  if (!link.b_column.at_floor()) to_column_point<D>(x, link.b_column, k.ub, k.vb, k.ab);
  return k;
}

}  // namespace poundsim::detail
