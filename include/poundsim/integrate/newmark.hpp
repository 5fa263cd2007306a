#pragma once
/// @file
/// Newmark's average-acceleration method (γ = 1/2, β = 1/4; the paper's choice, unconditionally
/// stable and second-order accurate) for one linear phase.
///
/// A step of length τ from (u, u̇, ü) at t solves, in the phase's reduced coordinates,
///
///     (M + τ/2 C + τ²/4 K) ü⁺ = −m a_g(t+τ) + b − C (u̇ + τ/2 ü) − K (u + τ u̇ + τ²/4 ü)
///     u̇⁺ = u̇ + τ/2 (ü + ü⁺),   u⁺ = u + τ u̇ + τ²/4 (ü + ü⁺)
///
/// This acceleration form is algebraically the usual displacement form, but it never divides by
/// τ²: event location takes sub-steps down to the event tolerance (1e-10 s) without cancellation.
/// The method enforces the equation of motion at t+τ, so ü⁺ is an equilibrium acceleration.
///
/// A step allocates nothing once the integrator is sized.

#include <Eigen/Core>

#include "poundsim/dynamics/linear_phase.hpp"
#include "poundsim/dynamics/state.hpp"

namespace poundsim {

class NewmarkIntegrator {
 public:
  explicit NewmarkIntegrator(Eigen::Index dofs);

  /// Advances `from` by τ = `tau` with the factorisation `solver` of M + τ/2 C + τ²/4 K of
  /// `phase` (phase.step_solver() when τ is the phase's step); `ground_end` is a_g(t+τ).
  /// `from` and `to` must be different objects.
  void step(const LinearPhase& phase, const LinearPhase::Solver& solver,
            const KinematicState& from, double tau, double ground_end, KinematicState& to);

 private:
  Eigen::VectorXd q_, qd_, qdd_, w1_, w2_, rhs_, qdd_new_;
};

}  // namespace poundsim
