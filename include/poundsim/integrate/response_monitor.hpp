#pragma once
/// @file
/// The response monitor: the peaks of a simulation's response (floor displacements, velocities,
/// accelerations and drifts, base and first-storey shears, approaches of neighbouring floors,
/// forces and counts of the gap elements), taken at every accepted state and between them on
/// the trajectory that the integrator provides. The simulation loop feeds it; it never changes
/// the simulation.

#include <cstddef>
#include <cstdint>
#include <cmath>
#include <limits>
#include <optional>
#include <vector>

#include "poundsim/dynamics/event.hpp"
#include "poundsim/dynamics/state.hpp"
#include "poundsim/model/law.hpp"
#include "poundsim/model/model.hpp"

namespace poundsim {

/// Largest absolute value of a response and when it occurred.
struct Peak {
  double value = 0.0;
  double time = 0.0;
  void update(double x, double t) {
    const double a = x < 0 ? -x : x;
    if (a > value) {
      value = a;
      time = t;
    }
  }
};

/// Peaks are taken at every accepted state (steps, events) and between them: a displacement, drift
/// or shear whose rate changes sign inside a step peaks there. Newmark takes that peak from the
/// cubic Hermite model of the step (values and rates at both ends, error O(h⁴)); the exact
/// integrator finds it on its exact trajectory.
struct FloorResponse {
  Peak displacement;           ///< |u| [m]
  Peak velocity;               ///< |u̇| [m/s]
  Peak acceleration;           ///< |ü| relative [m/s²]
  Peak absolute_acceleration;  ///< |ü + a_g| [m/s²]
  Peak drift;                  ///< |u_i − u_{i−1}| [m]
  std::int64_t yield_excursions = 0;  ///< Times the storey below began to yield (yielding laws).
  /// A rigid impact (the paper's element reaching its stop, bare pounding) or a lock changes the
  /// floor's velocity at once: the largest such jump |Δu̇| [m/s]. Its acceleration is a Dirac
  /// pulse of area Δu̇, which the accelerations above (taken at states) do not contain.
  Peak velocity_jump;
  /// With ResponseMonitor::set_impact_duration(τ > 0), each jump is spread over an equivalent
  /// half-sine pulse of duration τ, of peak π Δu̇ / (2τ), added to the floor's acceleration
  /// just before and just after the impact: the largest |ü ± pulse| and |ü + a_g ± pulse|
  /// [m/s²]. Zero without impacts or without τ.
  Peak impact_acceleration, impact_absolute_acceleration;

  /// The peak acceleration with the impacts' equivalent pulses (relative, absolute).
  [[nodiscard]] Peak acceleration_with_impacts() const { return larger(acceleration, impact_acceleration); }
  [[nodiscard]] Peak absolute_acceleration_with_impacts() const {
    return larger(absolute_acceleration, impact_absolute_acceleration);
  }

 private:
  static Peak larger(const Peak& a, const Peak& b) { return b.value > a.value ? b : a; }
};

struct GapResponse {
  int contacts = 0, separations = 0, impacts = 0, locks = 0, unlocks = 0;
  Peak force;             ///< F = c ṡ + k s, plus the stop reaction when locked [N].
  Peak impact_velocity;   ///< Closing velocity at impact [m/s].
  Peak impulse;           ///< Impulse of one impact or lock [N·s].
  Peak shortening;        ///< Largest s > 0 [m].
  double locked_time = 0.0;  ///< Total time spent locked [s].
  double contact_time = 0.0;  ///< Total time the element transmitted a force (contact or locked) [s].
  /// Contacts that ended in a separation, and what they did: the longest (its duration [s] and
  /// when it ended) and the effective restitution of each, −ṡ at separation / ṡ at contact.
  int completed_contacts = 0;
  Peak longest_contact;
  int restitution_samples = 0;  ///< completed contacts that began closing (ṡ > 0)
  double restitution_sum = 0.0;
  double min_restitution = std::numeric_limits<double>::infinity();
  double max_restitution = -std::numeric_limits<double>::infinity();
  /// Mean effective restitution of the completed contacts (NaN when none).
  [[nodiscard]] double mean_restitution() const {
    return restitution_samples > 0 ? restitution_sum / restitution_samples : std::numeric_limits<double>::quiet_NaN();
  }
};

/// Corresponding floors of neighbouring frames (whether or not a gap element joins them).
struct NeighbourResponse {
  int left_frame = 0;  ///< Frame f; its neighbour is f+1.
  int floor = 0;       ///< The floor of frame f
  int right_floor = 0; ///< and the floor of frame f+1 facing it (facing_floors).
  /// A slab facing the neighbour's column: the points are the slab and the column at its height
  /// (the struck side's floor above is the one named).
  std::optional<ColumnStrike> column{};
  /// The largest u_L − u_R [m] (signed: how far the left floor came towards the right one); its
  /// positive part is the smallest gap that avoids contact.
  double max_approach = -std::numeric_limits<double>::infinity();
  double max_approach_time = 0.0;
  void update(double approach, double t) {
    if (approach > max_approach) {
      max_approach = approach;
      max_approach_time = t;
    }
  }
};

struct ResponseStatistics {
  std::vector<FloorResponse> floors;  ///< By DOF (DofLayout numbering).
  std::vector<NeighbourResponse> neighbours;  ///< Every pair of corresponding floors.
  std::vector<Peak> base_shear;       ///< |V| = |K_1 u_1| per frame [N].
  std::vector<Peak> storey_shear;     ///< |K_1 u_1 + C_1 u̇_1| per frame: spring and dashpot [N].
  std::vector<GapResponse> gaps;
  std::int64_t steps = 0;             ///< Grid steps.
  std::int64_t substeps = 0;          ///< Accepted Newmark steps, including partial ones.
  /// Trial sub-steps spent on events: locating them, and checking a step whose guards did not
  /// change sign for one that rose and fell inside it (the grazing checks below).
  std::int64_t guard_evaluations = 0;
  /// Of guard_evaluations, the grazing checks: what locating the events took is the rest
  /// (bench/step_benchmark.cpp reports both).
  std::int64_t grazing_checks = 0;
  std::int64_t events = 0;
  std::int64_t phases_factorised = 0; ///< Configurations assembled and factorised.
  std::int64_t newton_steps = 0;      ///< Newmark steps and sub-steps solved by Newton (smooth laws).
  std::int64_t newton_iterations = 0; ///< Their iterations (each one tangent factorisation).
};

/// The trajectory of an integrator between two accepted states: the state at s, the time from
/// an origin the integrator chooses.
class DenseOutput {
 public:
  virtual void state_at(double s, KinematicState& out) = 0;
  /// t, u and u̇ at s, the same values state_at gives (ü and the ground acceleration may be left
  /// as they were): the searches for extrema of displacements and drifts need no more, and the
  /// exact integrator then skips half its work.
  virtual void motion_at(double s, KinematicState& out) { state_at(s, out); }

 protected:
  ~DenseOutput() = default;
};

class ResponseMonitor {
 public:
  /// `first_storey`: the linear form of each frame's first storey, whose spring force k u₁ + f₀
  /// is the base shear and whose whole force k u₁ + c u̇₁ + f₀ is the first-storey shear.
  ResponseMonitor(const Model& model, const DofLayout& layout, std::vector<LinearForm> first_storey);

  /// A first storey's drift is its floor's displacement: its peak is that peak (refined between
  /// samples alike), copied here rather than tracked twice in every step.
  [[nodiscard]] const ResponseStatistics& statistics() const {
    for (const int d : first_storey_dofs_) {
      FloorResponse& floor = stats_.floors[static_cast<std::size_t>(d)];
      floor.drift = floor.displacement;
    }
    return stats_;
  }
  /// The counts (steps, events, …) are the simulation loop's to keep.
  [[nodiscard]] ResponseStatistics& counts() { return stats_; }

  /// Forgets every peak and count.
  void reset();

  /// V = k u₁ + f₀ of frame f at x [N]: the first storey's spring force.
  [[nodiscard]] double base_shear(const KinematicState& x, int f) const {
    const LinearForm& storey = first_storey_[static_cast<std::size_t>(f)];
    return storey.stiffness * x.u(layout_.dof(f, 0)) + storey.force_at_zero;
  }
  /// k u₁ + c u̇₁ + f₀ of frame f at x [N].
  [[nodiscard]] double storey_shear(const KinematicState& x, int f) const {
    const auto d = static_cast<Eigen::Index>(first_storey_dofs_[static_cast<std::size_t>(f)]);
    return first_storey_[static_cast<std::size_t>(f)].force(x.u.data()[d], x.v.data()[d]);
  }
  /// The floor DOF above frame f's first storey, and that storey's linear form: storey_shear's
  /// terms (the lockstep kernel computes the same shear over its lanes).
  [[nodiscard]] int first_storey_dof(int f) const { return first_storey_dofs_[static_cast<std::size_t>(f)]; }
  [[nodiscard]] const LinearForm& first_storey_form(int f) const { return first_storey_[static_cast<std::size_t>(f)]; }
  /// Σ shear·0 over the frames' first-storey shears at x: ±0 when they are all finite, NaN
  /// otherwise (Loop::all_finite).
  [[nodiscard]] double storey_shear_poison(const KinematicState& x) const {
    double poison = 0.0;
    for (std::size_t f = 0; f < first_storey_dofs_.size(); ++f) poison += storey_shear(x, static_cast<int>(f)) * 0.0;
    return poison;
  }
  /// The first storey of frame f now has the linear form `form` (a yielding storey changed its
  /// mode or plastic drift).
  void set_first_storey(int f, const LinearForm& form) { first_storey_[static_cast<std::size_t>(f)] = form; }
  /// The base shear V and first-storey shear of frame f at time t, for a first storey whose
  /// force is not a linear form (sampled at accepted states, not refined between them).
  void observe_first_storey(int f, double base_shear, double storey_shear, double t) {
    stats_.base_shear[static_cast<std::size_t>(f)].update(base_shear, t);
    stats_.storey_shear[static_cast<std::size_t>(f)].update(storey_shear, t);
  }
  /// The storey below floor DOF `dof` yielded or unloaded, its plastic drift now `plastic_drift`
  /// [m] (NaN for a law without one). An excursion that unloads with its plastic drift changed by
  /// no more than `round_off` [m] was a graze of the yield surface — the trajectory touched it
  /// within round-off, as Newmark's can where the exact solution only reaches it — and is not
  /// counted.
  void observe_storey_event(int dof, EventKind kind, double plastic_drift, double round_off) {
    const auto i = static_cast<std::size_t>(dof);
    if (kind == EventKind::yield) {
      ++stats_.floors[i].yield_excursions;
      plastic_at_yield_[i] = plastic_drift;
    } else if (kind == EventKind::unload && std::abs(plastic_drift - plastic_at_yield_[i]) <= round_off) {
      --stats_.floors[i].yield_excursions;
    }
  }

  /// The floors, shears and approaches at the accepted state x.
  void observe(const KinematicState& x);
  /// The duration τ [s] of the half-sine pulse a rigid impact's velocity jump is spread over
  /// (FloorResponse::impact_acceleration); 0: none.
  void set_impact_duration(double tau) { impact_duration_ = tau; }
  /// Events at x.t changed the floors' velocities from `v_before` and their accelerations from
  /// `a_before` (rigid impacts, locks) to x's: the velocity jumps and their equivalent pulses.
  void observe_velocity_jumps(const Eigen::VectorXd& v_before, const Eigen::VectorXd& a_before,
                              const KinematicState& x);
  /// Gap element p transmits `force` [N] at shortening s [m] at time t.
  void observe_gap(std::size_t p, double force, double s, double t) {
    GapResponse& g = stats_.gaps[p];
    g.force.update(force, t);
    if (s > 0) g.shortening.update(s, t);
  }
  /// An event of gap element p at t; `closing_velocity` before it [m/s], its impulse [N·s].
  void observe_event(std::size_t p, EventKind kind, double closing_velocity, double impulse, double t);
  /// Gap element p was locked over a step of h [s].
  void observe_locked(std::size_t p, double h) { stats_.gaps[p].locked_time += h; }
  /// Gap element p transmitted a force over an accepted step of length h.
  void observe_in_contact(std::size_t p, double h) { stats_.gaps[p].contact_time += h; }

  /// Peaks strictly inside a Newmark step from a to b: each quantity q with rate q̇ is the cubic
  /// Hermite interpolant of (q, q̇) at both ends, which peaks where q̇ changes sign.
  void observe_step(const KinematicState& a, const KinematicState& b);
  /// Peaks strictly inside a step from a to b of an integrator that knows its trajectory: where
  /// a rate changes sign, the instant is found on `trajectory` (times from `origin`) by the Illinois
  /// method (bracketed_roots.hpp).
  void observe_step(const KinematicState& a, const KinematicState& b, double origin, DenseOutput& trajectory);

 private:
  DofLayout layout_;
  std::vector<LinearForm> first_storey_;
  /// The two points of every NeighbourResponse, as the ends of a link (floors, or a floor and a
  /// column point): their approach is the link's d.
  struct FacingPoints {
    int a = 0, b = 0;
    ColumnPoint a_column{}, b_column{};
    [[nodiscard]] bool joins_floors() const { return a_column.at_floor() && b_column.at_floor(); }
  };
  std::vector<FacingPoints> facing_;
  bool facing_at_floors_ = true;  ///< Every facing pair joins floors (no column point).
  std::vector<int> first_storey_dofs_;                 ///< The floor above each frame's first storey.
  std::vector<double> contact_start_;    ///< When each element's current contact began (NaN: none)
  std::vector<double> contact_closing_;  ///< ṡ at that contact's onset [m/s]
  std::vector<double> plastic_at_yield_; ///< Each storey's plastic drift when it last began to yield [m]
  double impact_duration_ = 0.0;         ///< τ of set_impact_duration [s]
  mutable ResponseStatistics stats_;  ///< Mutable: statistics() copies the first storeys' drifts.
  KinematicState node_;  ///< Scratch for states on a trajectory.
};

}  // namespace poundsim
