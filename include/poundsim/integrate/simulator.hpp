#pragma once
/// @file
/// Event-driven time-history analysis of frames with gap elements.
///
/// The step algorithm (x is the state, S the contact configuration, h the step):
///
///     x⁺ = Newmark(x, S, h); evaluate every guard of S at x⁺
///     if no guard fired (and no grazing contact was found inside the step):
///         accept x⁺
///     else:
///         bracket the first event to the event tolerance (event_location.hpp), accept the
///         Newmark sub-step to its upper end, then apply every event fired there:
///         mode changes, impacts (restitution, simultaneous pairs resolved in sequence),
///         locking of chattering pairs; re-equilibrate ü; apply any event this triggers at once;
///         continue with the rest of the step.
///
/// Grid steps end at multiples of h whatever the events, so outputs and runs with different
/// tolerances line up. Guards (positive = fired), per element:
///
///     open     s − s_e(t)        contact (impact when ε = 0)
///     contact  s − ε             impact
///              −s  or  −F        separation (displacement or force criterion)
///     locked   −λ                unlock (λ is the stop reaction, compression positive)
///
/// Persistent contact. After an impact the pair is locked at s = ε when it is pressed together
/// (the relative acceleration with equal velocities, ä > 0) and its next flight would be shorter
/// than lock_time: the opening velocity r satisfies 2r ≤ ä·lock_time. This turns the infinite
/// sequence of impacts of e < 1 (and the micro-bounces of e = 1 at zero velocity, as in the
/// paper's Fig. 4 with δ = 0) into a constrained phase; the kinetic energy of the relative motion,
/// which the sequence would dissipate, is booked as impact loss. See docs/model.md.
///
/// Example:
/// @code
///   Simulator sim(model, HarmonicExcitation{0.2 * standard_gravity, 11.3},
///                 TimeHistoryOptions{.dt = 1e-3});
///   sim.advance_to(20.0);
///   double peak = sim.statistics().base_shear[0].value;
/// @endcode

#include <cstdint>
#include <functional>
#include <limits>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "poundsim/error.hpp"
#include "poundsim/fields.hpp"
#include "poundsim/model/contact_state.hpp"
#include "poundsim/dynamics/energy.hpp"
#include "poundsim/dynamics/event.hpp"
#include "poundsim/integrate/event_location.hpp"
#include "poundsim/model/excitation.hpp"
#include "poundsim/dynamics/linear_phase.hpp"
#include "poundsim/dynamics/system.hpp"
#include "poundsim/model/model.hpp"
#include "poundsim/integrate/integrator.hpp"
#include "poundsim/integrate/newmark.hpp"
#include "poundsim/integrate/response_monitor.hpp"

namespace poundsim {

namespace detail {
class Stepper;
class TangentFlow;
}  // namespace detail

class Lockstep;

/// Options of the time-history integration. SI units.
struct TimeHistoryOptions {
  double dt = 0.0;                 ///< Newmark step h [s]; required, > 0.
  double event_tolerance = 1e-10;  ///< Event times are bracketed to this width [s]; > 0.
  /// A pressed pair whose next flight would be shorter than this locks [s]; ≥ 10 × event_tolerance.
  double lock_time = 1e-6;
  /// An impact closing slower than this fraction of its floors' speeds, |u̇_L| + |u̇_R|, is
  /// plastic (e = 0): such a bounce carries at most ratio² of the pair's kinetic energy, and with
  /// e near 1 it would chatter without end at the resolution of event location. See
  /// docs/model.md (resting contact). 0 switches the rule off. In [0, 1).
  double rest_velocity_ratio = 1e-4;
  SeparationCriterion separation = SeparationCriterion::displacement;
  Integrator integrator = Integrator::newmark;
  /// Newmark with smooth laws: Newton stops when the residual per unit mass is below this
  /// fraction of the accelerations' size; in (0, 1e-3].
  double newton_tolerance = 1e-10;
  int newton_max_iterations = 50;  ///< Beyond this a step fails, naming the element; ≥ 1.
  /// The duration [s] of the half-sine pulse over which the peaks spread a rigid impact's
  /// velocity jump, so that a floor's peak acceleration includes the impact: π Δu̇ / (2τ) on
  /// top of the acceleration at the impact (FloorResponse::impact_acceleration). 0: the
  /// accelerations exclude rigid impacts, whose velocity jumps are reported alone. ≥ 0.
  double impact_duration = 0.0;
  int max_events_per_step = 100000;        ///< Beyond this the run stops with an error.
  std::size_t phase_cache_size = 4096;     ///< Factorised configurations kept.

  /// The fields a model file sets (its [analysis] table; dt is read with the analysis it
  /// belongs to), with their units and ranges: fields.hpp.
  static constexpr auto fields() {
    using O = TimeHistoryOptions;
    return std::tuple{
        ChoiceField{"integrator", &O::integrator,
                    std::array{std::pair<std::string_view, Integrator>{"newmark", Integrator::newmark},
                               std::pair<std::string_view, Integrator>{"exact", Integrator::exact}},
                    "Newmark's average acceleration, or the closed-form solution of each phase"},
        NumberField{"event_tolerance", &O::event_tolerance, "s", positive,
                    "Newmark: event times are bracketed to this width"},
        NumberField{"lock_time", &O::lock_time, "s", positive,
                    "a pressed pair whose next bounce would be shorter locks (persistent contact)"},
        NumberField{"rest_velocity_ratio", &O::rest_velocity_ratio, "", below_one,
                    "an impact closing slower than this fraction of its floors' speeds is plastic"},
        ChoiceField{"separation", &O::separation, separation_criterion_names,
                    "contact ends when s returns to 0, or when the element force would become tensile"},
        NumberField{"newton_tolerance", &O::newton_tolerance, "", Interval{.lo = 0.0, .hi = 1e-3, .lo_open = true},
                    "Newmark with smooth laws: Newton's residual per unit mass, relative to the accelerations"},
        IntegerField{"newton_max_iterations", &O::newton_max_iterations, 1, 1000,
                     "Newmark with smooth laws: Newton's iterations per step before it fails"},
        NumberField{"impact_duration", &O::impact_duration, "s", non_negative,
                    "rigid impacts: the half-sine pulse a velocity jump is spread over in the peak "
                    "accelerations (0: accelerations exclude rigid impacts)"},
    };
  }

  [[nodiscard]] bool operator==(const TimeHistoryOptions&) const = default;

  /// Newton's options of a step with smooth laws.
  [[nodiscard]] NewtonOptions newton() const {
    return {.max_iterations = newton_max_iterations, .tolerance = newton_tolerance};
  }

  /// Throws std::invalid_argument naming the field that is out of range.
  void validate() const;

  /// The rules of the system's events these options set.
  [[nodiscard]] EventRules event_rules() const {
    return {.separation = separation, .event_tolerance = event_tolerance, .lock_time = lock_time,
            .rest_velocity_ratio = rest_velocity_ratio};
  }

  /// The rule between lock_time and event_tolerance, when broken: "X s must be at least
  /// 10 × event_tolerance = Y s" (validate() throws it; the reader names the key and the line).
  [[nodiscard]] std::optional<std::string> lock_time_violation() const;
};

/// Initial floor displacements [m] and velocities [m/s] relative to the ground, per frame and
/// floor. Empty means at rest.
struct InitialConditions {
  std::vector<std::vector<double>> displacement;
  std::vector<std::vector<double>> velocity;
  [[nodiscard]] bool operator==(const InitialConditions&) const = default;
};

/// How a run to a time ended: the simulation loop's answer to "why did you stop?".
struct SimulationStatus {
  StopReason reason = StopReason::reached_time;
  /// [s] The time reached; after a failure, the time of the last state the loop had accepted
  /// (the start of the failed step when an event could not be located or a phase factorised).
  double time = 0.0;
  std::string message;  ///< What failed and where; empty when the time was reached.
  [[nodiscard]] bool ok() const { return reason == StopReason::reached_time; }
};

namespace detail {

/// The simulation loop as its integrator sees it (src/integrate/steppers.hpp): the state, the
/// contact state and the current phase of the system, the guard values at both ends of the step,
/// and the monitors the accepted states go to. An integrator advances the state to the next grid
/// time by accept()ing the states it reaches and calling apply_pending_events() where guards
/// fired; it asks the system (system()) for the guards. The Simulator is this loop with its
/// public face (advance_to, restart, the results).
class Loop {
  friend class poundsim::Lockstep;  // the plain grid steps of several loops at once (lockstep.hpp)

 public:
  /// Guard values g and rates ġ (PoundingSystem::evaluate_guards): at the current state (lo), at
  /// the end of the trial step (hi), and scratch (work).
  struct Guards {
    std::vector<double> lo, hi, work, rate_lo, rate_hi, rate_work;
  };

  [[nodiscard]] const PoundingSystem& system() const { return system_; }
  [[nodiscard]] const TimeHistoryOptions& options() const { return options_; }
  [[nodiscard]] const KinematicState& state() const { return state_; }
  [[nodiscard]] const ContactState& contact() const { return contact_; }
  [[nodiscard]] const LinearPhase& phase() const { return *phase_; }
  [[nodiscard]] EnergyMeter& meter() { return energy_; }
  [[nodiscard]] const EnergyMeter& meter() const { return energy_; }
  [[nodiscard]] ResponseMonitor& monitor() { return monitor_; }
  [[nodiscard]] Guards& guards() { return guards_; }
  /// The sensitivities of the state to the start of the run, when tracked (else null).
  [[nodiscard]] TangentFlow* tangent() { return tracking_ ? tangent_.get() : nullptr; }
  /// False while the simulator keeps the state alone (Simulator::record_responses).
  [[nodiscard]] bool recording() const { return recording_; }
  /// False while the energy balance is not kept (Simulator::meter_energy).
  [[nodiscard]] bool metering() const { return metering_; }

  /// The system's guards at x with the loop's contact state; the current phase gives λ.
  void evaluate_guards(const KinematicState& x, std::span<double> g, std::span<double> dg) {
    system_.evaluate_guards(x, *phase_, contact_, g, dg);
  }
  /// λ of the locked elements at x (the state about to be accepted).
  void compute_stop_reactions(const KinematicState& x) { system_.compute_stop_reactions(x, *phase_, contact_); }
  /// Accepts a Newmark step to `next`, whose guards are guards().hi: energy by the trapezoidal
  /// rule, peaks on the cubic Hermite model of the step.
  void accept(KinematicState& next);
  /// Makes `next` the current state (swapped with it) and records its statistics, which read λ:
  /// the last evaluation of λ must have been at `next`.
  void after_accept(KinematicState& next);
  /// Applies the events whose guards().lo fired at the current state, and those they trigger,
  /// until none fires.
  void apply_pending_events();

 protected:
  Loop(PoundingSystem system, const TimeHistoryOptions& options);
  ~Loop();
  Loop(const Loop&) = delete;
  Loop& operator=(const Loop&) = delete;

  /// Makes the phase of the contact configuration current, with the lengths of its locked links.
  LinearPhase& activate_phase();
  /// Reports an event; velocities after are read from the current state.
  void emit(int gap, EventKind kind, double left_before, double right_before, double impulse);
  void record_statistics();
  /// The drift [m] and restoring force [N] of the storey below floor DOF `dof` now.
  [[nodiscard]] double storey_drift(int dof) const;
  [[nodiscard]] double restoring_force(int dof) const;
  /// Frame f's base shear (restoring force) and first-storey shear (with its dashpot) now [N],
  /// when its first storey's law is smooth; nothing otherwise (the monitor's linear form gives them).
  struct FirstStoreyForces {
    double base_shear = 0.0;
    double storey_shear = 0.0;
  };
  [[nodiscard]] std::optional<FirstStoreyForces> smooth_first_storey(int f) const;
  /// Frames whose first storey's law is smooth (a Bouc–Wen storey): their base shear is not a
  /// linear form's, so the loop samples it at every accepted state.
  std::vector<int> smooth_first_storeys_;
  /// Throws SimulationError naming the time and the quantity when the state, a force or an energy
  /// is no longer finite.
  void check_finite() const;
  /// Whether the quantities check_finite() names are all finite: its fast pass.
  [[nodiscard]] bool all_finite() const;

  PoundingSystem system_;
  TimeHistoryOptions options_;
  ContactState contact_;
  std::map<ContactConfiguration, std::unique_ptr<LinearPhase>> phases_;
  LinearPhase* phase_ = nullptr;
  EnergyMeter energy_;
  ResponseMonitor monitor_;  ///< Peaks and counts.
  std::unique_ptr<Stepper> stepper_;  ///< Newmark or exact (options_.integrator)
  std::unique_ptr<TangentFlow> tangent_;  ///< ∂x/∂x₀ (Simulator::track_sensitivity), kept when off
  bool tracking_ = false;
  bool recording_ = true;
  bool metering_ = true;
  KinematicState state_;
  Guards guards_;
  int events_this_step_ = 0;
  /// The floors' velocities and accelerations before the events of an instant (the velocity jumps).
  Eigen::VectorXd v_before_events_, a_before_events_;
  std::function<void(const Event&)> on_event_;

 private:
  class Events;  // the loop as the system's EventHandler
  std::unique_ptr<Events> events_;
};

}  // namespace detail

class Simulator : private detail::Loop {
  friend class Lockstep;

 public:
  /// Validates its inputs (std::invalid_argument on failure) and equilibrates the initial state.
  Simulator(Model model, Excitation excitation, TimeHistoryOptions options,
            const InitialConditions& initial = {});
  ~Simulator();
  Simulator(const Simulator&) = delete;
  Simulator& operator=(const Simulator&) = delete;

  /// Called for every event, in time order.
  void set_event_handler(std::function<void(const Event&)> handler) {
    on_event_ = std::move(handler);
  }
  /// Integrates grid steps of h until `t` [s]; the last step is shortened to end exactly at t.
  /// Throws SimulationError (with its StopReason) when the integration fails; after a failure
  /// every later call throws it again.
  void advance_to(double t);
  /// The same, with a failure returned as a status instead of thrown. The state is then the one
  /// at the failure's instant (not a solution: do not continue from it).
  [[nodiscard]] SimulationStatus run_to(double t);

  /// Continues from the current state (displacements, velocities, contact configuration, locked
  /// links) under a new excitation and step, with the clock reset to 0 — a frequency sweep's next
  /// point. Statistics and the energy balance start afresh. After a failure it throws that
  /// failure again (there is no state to continue from); a failure while it settles the state
  /// fails the simulator like one in advance_to.
  void restart(Excitation excitation, double dt);

  /// Starts again from the floors' displacements `u` [m] and velocities `v` [m/s] (DofLayout
  /// order) at t = 0 under the same excitation and step: each element's mode follows from u as
  /// at construction, statistics and the energy balance start afresh, a failure is forgotten
  /// (the state is new). The phases already built are kept: a periodic orbit's Newton
  /// iterations start one run after another from nearby states. Throws std::invalid_argument
  /// when the state cannot start (a size, a non-finite value, an element compressed past its
  /// stop) and SimulationError when settling it fails.
  void reset_state(const Eigen::VectorXd& u, const Eigen::VectorXd& v);

  /// From now on (and after every restart or reset_state) tracks J = ∂x(t)/∂x(0), the
  /// sensitivity of x = [u; u̇] to the state the run started from, through every phase and event
  /// (src/integrate/tangent_flow.hpp). The exact integrator only: std::invalid_argument otherwise.
  /// false stops tracking.
  void track_sensitivity(bool track = true);
  /// J at the current time (2N × 2N); track_sensitivity() first.
  [[nodiscard]] Eigen::Ref<const Eigen::MatrixXd> sensitivity();
  /// From now on (and after every restart or reset_state) also tracks y = ∂x(t)/∂ω̄ at fixed t,
  /// the sensitivity to the forcing frequency, beside J (src/integrate/tangent_flow.hpp): a
  /// harmonic excitation and track_sensitivity() first, std::invalid_argument otherwise. false
  /// stops it.
  void track_frequency_sensitivity(bool track = true);
  /// y at the current time (2N); track_frequency_sensitivity() first.
  [[nodiscard]] Eigen::Ref<const Eigen::VectorXd> frequency_sensitivity();
  /// Events since J started whose crossing was least transversal: min |∇h·ẋ| / (|∇h| |ẋ|) over
  /// them (1 without events): near 0 the orbit grazes a guard and J is not the map's derivative.
  [[nodiscard]] double least_transversality() const;

  /// False: the simulator keeps the state, the events, their counts and the sensitivity but
  /// neither the energy balance nor the peaks, at the samples or between them (the exact
  /// integrator locates extrema on its trajectory and integrates the energy in closed form, which
  /// costs a recorded period several times its state alone, docs/periodic-orbits.md; for Newmark
  /// the peaks and the balance are a third of a step): statistics() and energy() then do not describe
  /// the run. A periodic orbit's Newton iterations need only the state reached, and the orbit
  /// found is run once more with them; a brute-force frequency response needs no peak of its
  /// transient: reset_statistics() after record_responses(true) starts the window's peaks there.
  /// The energy balance is not restarted by reset_statistics(): a run that turns recording off
  /// and on again with meter_energy(true) has a balance with a hole in it (the frequency
  /// response meters none). True (the default) keeps everything.
  void record_responses(bool record) { recording_ = record; }
  /// False: the peaks and the state are kept but not the energy balance, whose integrals cost a
  /// sixth of a Newmark step (the free frames beside a time history need the peaks alone);
  /// energy() then stays where the run started. True (the default) keeps it.
  void meter_energy(bool meter) { metering_ = meter; }

  /// Forgets the peaks and counts gathered so far (e.g. after a transient).
  void reset_statistics();
  /// One grid step.
  void step();

  [[nodiscard]] double time() const { return state_.t; }
  /// The origin of the step grid, t = origin + k·dt [s]: 0 until advance_to() stops off the grid
  /// (a partial step), whose end becomes the new origin.
  [[nodiscard]] double grid_origin() const { return grid_origin_; }
  using Loop::state;
  [[nodiscard]] const ContactConfiguration& configuration() const { return contact_.config; }
  /// What each link's law keeps now (a storey's plastic drift, …), by law and slot.
  [[nodiscard]] const LinkStates& law_states() const { return contact_.states; }
  /// The system integrated: frames, gap elements, excitation, event rules.
  using Loop::system;
  [[nodiscard]] const Model& model() const { return system_.model(); }
  [[nodiscard]] const DofLayout& layout() const { return system_.layout(); }
  using Loop::options;
  [[nodiscard]] const Excitation& excitation() const { return system_.excitation(); }

  /// a_g at the current time [m/s²].
  [[nodiscard]] double ground_acceleration_now() const;
  /// s of gap element p now [m].
  [[nodiscard]] double shortening(int p) const;
  /// Force transmitted by gap element p now [N], compression positive (0 when open).
  [[nodiscard]] double gap_force(int p) const;
  /// The restoring force of the storey below floor DOF `dof` now (its law's, without its
  /// dashpot: K d for a linear storey; what hysteresis loops plot) [N].
  [[nodiscard]] double storey_force(int dof) const;
  /// The drift of that storey now [m].
  [[nodiscard]] double storey_drift(int dof) const;
  /// V = K_1 u_1 of frame f now [N].
  [[nodiscard]] double base_shear(int f) const;
  /// K_1 u_1 + C_1 u̇_1 of frame f now [N].
  [[nodiscard]] double storey_shear(int f) const;

  [[nodiscard]] const EnergyBalance& energy() const { return energy_.balance(); }
  [[nodiscard]] const EnergyMeter& energy_meter() const { return energy_; }
  [[nodiscard]] const ResponseStatistics& statistics() const { return monitor_.statistics(); }

 private:
  void integrate_to(double t_end, bool nominal);
  void settle_state();
  /// settle_state() at a new start (restart, reset_state), a failure recorded; then statistics
  /// and the sensitivities start here.
  void start_afresh();
  /// A failed simulator throws its failure again; record_failure makes it failed.
  void throw_if_failed() const;
  void record_failure(const SimulationError& e);

  double grid_origin_ = 0.0;
  std::int64_t grid_index_ = 0;
  std::optional<SimulationStatus> failure_;  ///< Once the integration has failed
};

}  // namespace poundsim
