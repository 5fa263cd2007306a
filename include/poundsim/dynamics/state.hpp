#pragma once
/// @file
/// The kinematic state of the floors that integrators advance and everything else reads.

#include <utility>

#include <Eigen/Core>

namespace poundsim {

/// Displacements [m], velocities [m/s] and accelerations [m/s²] of every floor relative to the
/// ground, in the DofLayout numbering, at time t [s].
struct KinematicState {
  double t = 0.0;
  double ground = 0.0;  ///< a_g(t) [m/s²] that the accelerations balance.
  Eigen::VectorXd u, v, a;

  void resize(Eigen::Index n) {
    u.setZero(n);
    v.setZero(n);
    a.setZero(n);
  }
  /// Exchanges the buffers (std::swap would move through a temporary and free its empty vectors:
  /// three calls to free at every accepted step).
  friend void swap(KinematicState& x, KinematicState& y) noexcept {
    std::swap(x.t, y.t);
    std::swap(x.ground, y.ground);
    x.u.swap(y.u);
    x.v.swap(y.v);
    x.a.swap(y.a);
  }
};

}  // namespace poundsim
