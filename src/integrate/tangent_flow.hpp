#pragma once
// The sensitivity J = ∂x(t)/∂x(t₀) of the exact integrator's state x = [u; u̇] (full floor
// coordinates) to where the run started: the monodromy matrix of a periodic orbit when t − t₀ is
// its period (docs/periodic-orbits.md).
//
// Between events the flow of a phase is affine in its state, so J moves with the phase
// propagator: J(t) = T Φ(t − t_s) G J(t_s), with G the gather (the leftmost floor of each rigid
// group), Φ = e^{A s} (ExactPhase::propagator) and T the scatter to the floors. At an event at
// time t* on the guard h(x) = 0 whose state jumps by x⁺ = g(x⁻) (positions kept, velocities
// mapped linearly by the impacts and plastic merges at that instant, Γ), the event time moves
// with the start and J takes the saltation matrix
//
//     S = G_x + (f⁺ − G_x f⁻) ∇hᵀ / (∇h · f⁻),   G_x = diag(I, Γ),
//
// f⁻, f⁺ = ẋ just before and after the instant (Aizerman & Gantmacher 1958; Müller 1995,
// "Calculation of Lyapunov exponents for dynamic systems with discontinuities", Chaos, Solitons &
// Fractals 5(9)). Contact onset and separation (Γ = I) jump the accelerations only; an impact
// of restitution e maps the closing speed w to −e w; a lock merges the pair's velocities
// (momentum kept); an unlock (h = −λ) jumps the accelerations. The formula needs a transversal
// crossing (∇h·f⁻ ≠ 0): where it vanishes the orbit grazes and the map is not smooth.
//
// Under a harmonic forcing A sin ω̄t it can also carry y = ∂x(t)/∂ω̄ at fixed t and start (the
// continuation's ∂P/∂ω̄ without a second run: periodic_orbits.cpp). Within a phase the state is
// x = x_p + e^{As}(…) with the harmonic particular solution x_p(t) = Im(H e^{iω̄t}), H = a h (a
// the forcing amplitude), (iω̄I − A) h = e, so y − ∂x_p/∂ω̄ follows the homogeneous flow:
//
//     y(t) = z(t) + Φ(t − t_s)(y(t_s) − z(t_s)),   z(t) = ∂x_p/∂ω̄ = Im((H' + i t H) e^{iω̄t}),
//
// H' = a dh/dω̄ (ExactPhase::harmonic_response_rate). Each term of y grows like t|H|, and
// ∂P/∂ω̄ = y(kT) − ẋ(kT)·kT/ω̄ subtracts two such terms: about log₁₀(2πk) digits are lost, a
// few for the periods a continuation follows. The guards and the event maps do not depend
// on ω̄, so at an event y takes the same saltation matrix as the columns of J: it is kept as J's
// last column.

#include <span>

#include <Eigen/Core>

#include "poundsim/dynamics/linear_phase.hpp"
#include "poundsim/integrate/exact_phase.hpp"

namespace poundsim::detail {

class TangentFlow {
 public:
  explicit TangentFlow(Eigen::Index dofs);

  /// J = I (and y = 0) at time t: the sensitivities start here.
  void reset(double t);
  /// From the next reset on, also carry y = ∂x/∂ω̄ (the forcing must be harmonic).
  void track_frequency(bool track);
  /// A segment of `trajectory` (the closed form of `phase` from t) starts: J follows its
  /// propagator from here. Both must outlive the segment.
  void start_segment(const LinearPhase& phase, const ExactTrajectory& trajectory, double t);
  /// The segment was abandoned (its phase is gone): J stays where it was last brought.
  void end_segment() { segment_ = false; }
  /// Brings J to time t on the current segment.
  void propagate_to(double t);

  /// An instant of events at the state reached (J brought there): `gradient` is ∇h of the guard
  /// that crossed (full coordinates, 2N), `before` = ẋ⁻ = [u̇; ü]. The velocity maps of the
  /// instant follow; end_events applies the saltation matrix.
  void begin_events(const Eigen::Ref<const Eigen::RowVectorXd>& gradient, const Eigen::VectorXd& velocity,
                    const Eigen::VectorXd& acceleration);
  /// Floors of groups `left` and `right` (`group` of each floor) collided with restitution e:
  /// v_L⁺ = c − e m_R w/(m_L+m_R), v_R⁺ = c + e m_L w/(m_L+m_R), c their centre's velocity,
  /// w = v_L − v_R (impact.hpp).
  void pair_impact(std::span<const int> group, int left, int right, double mass_left, double mass_right,
                   double restitution);
  /// Every floor of a group took the group's centre-of-mass velocity (a lock's plastic merge).
  void merge(std::span<const int> group, const Eigen::VectorXd& floor_mass, const Eigen::VectorXd& group_mass);
  /// The instant ended at ẋ⁺ = [u̇⁺; ü⁺]: J ← S J.
  void end_events(const Eigen::VectorXd& velocity, const Eigen::VectorXd& acceleration);
  [[nodiscard]] bool in_events() const { return in_events_; }

  /// ∂x(t)/∂x(t₀) at the time J was last brought to (2N × 2N, x = [u; u̇]).
  [[nodiscard]] Eigen::Ref<const Eigen::MatrixXd> sensitivity() const { return j_.leftCols(2 * n_); }
  /// y = ∂x(t)/∂ω̄ at fixed t there (2N; track_frequency).
  [[nodiscard]] Eigen::Ref<const Eigen::VectorXd> frequency_sensitivity() const { return j_.col(2 * n_); }
  [[nodiscard]] bool tracks_frequency() const { return frequency_; }
  [[nodiscard]] double time() const { return time_; }
  /// Events whose saltation was applied since reset, and the smallest |∇h·f⁻| relative to
  /// |∇h| |f⁻| among them (near 0: a grazing crossing).
  [[nodiscard]] long events() const { return events_; }
  [[nodiscard]] double least_transversality() const { return least_transversality_; }

 private:
  Eigen::Index n_;
  Eigen::MatrixXd j_, gathered_, propagated_;  // j_ = [J y] (y only when frequency_)
  ExactPhase::Projection projected_;  // V⁻¹ gathered_ (a modal phase: ExactPhase::project_modes)
  Eigen::VectorXd jump_;                  // end_events' work: f⁺ − G f⁻,
  Eigen::RowVectorXd time_sensitivity_;   // ∇h J / ∇h·f⁻,
  Eigen::MatrixXd velocity_rows_;         // Γ J_v
  Eigen::MatrixXd velocity_map_;  ///< Γ of the current instant (N × N)
  Eigen::RowVectorXd gradient_;
  Eigen::VectorXd before_;
  const LinearPhase* phase_ = nullptr;
  const ExactPhase* exact_ = nullptr;
  double start_ = 0.0, time_ = 0.0;
  bool segment_ = false, in_events_ = false;
  bool frequency_ = false;
  // The segment's H and H' (reduced) and ω̄, for z(t) (frequency_ only).
  Eigen::VectorXcd harmonic_, harmonic_rate_;
  double omega_ = 0.0;
  Eigen::VectorXd particular_;  // z(t), reduced
  void particular_rate(double t);  // particular_ = z(t)
  [[nodiscard]] Eigen::Index columns() const { return 2 * n_ + (frequency_ ? 1 : 0); }
  long events_ = 0;
  double least_transversality_ = 1.0;
};

}  // namespace poundsim::detail
