#pragma once
/// @file
/// Frequency responses of pounding frames under harmonic base acceleration a_g = A sin(ω̄t): the
/// paper's results (Figs. 2–4) are the steady-state amplitude of each frame's base shear V = K₁u₁,
/// divided by the weight W of frame 1, against ω̄/ω₁.
///
/// The steady state is detected, not assumed. The state y = [u; u̇/ω̄] (and the contact
/// configuration) is sampled on the Poincaré section t = m T, T = 2π/ω̄. The response is periodic
/// with period kT when the last k sections each repeat the one k periods earlier to a relative
/// `tolerance`; the smallest such k ≤ max_periodicity is reported, after which k more periods are
/// run and the peaks over them are the amplitudes. If no k is found within `max_periods`, the
/// response is reported as not periodic (k = 0: quasi-periodic or chaotic) and the peaks are taken
/// over the following `window_periods` periods.
///
/// A point starts from rest (default), or — in a sweep up or down in frequency — from the steady
/// state of the previous point, so that coexisting periodic branches and the jumps between them
/// show. The frames without gap elements are linear: their amplitudes are computed in closed form
/// from (K − ω̄²M + iω̄C) U = −M 1 A, frame by frame.

#include <array>
#include <complex>
#include <functional>
#include <limits>
#include <string>
#include <vector>

#include "poundsim/analysis/orbit_options.hpp"
#include "poundsim/fields.hpp"
#include "poundsim/model/model.hpp"
#include "poundsim/integrate/simulator.hpp"

namespace poundsim {

enum class SweepMode : std::uint8_t {
  from_rest,  ///< every frequency from rest, independently (in parallel)
  up,         ///< increasing frequency, each from the previous steady state
  down,       ///< decreasing frequency, likewise
  both,       ///< up and down sweeps, both reported
};

/// The names of the sweep modes in a model file (frf.sweep) and in outputs.
inline constexpr std::array<std::pair<std::string_view, SweepMode>, 4> sweep_mode_names{{
    {"rest", SweepMode::from_rest}, {"up", SweepMode::up}, {"down", SweepMode::down}, {"both", SweepMode::both}}};

[[nodiscard]] std::string_view to_string(SweepMode mode);

struct SteadyStateOptions {
  int steps_per_period = 128;   ///< Newmark steps (exact integrator: samples) per period T.
  double tolerance = 1e-6;      ///< Poincaré repetition, relative to the largest |y| seen.
  int max_periods = 600;        ///< Periods simulated before the response is called non-periodic.
  int max_periodicity = 8;      ///< Largest k looked for.
  int window_periods = 64;      ///< Periods over which a non-periodic response's peaks are taken.

  /// The most periods (and steps per period) one point may ask for.
  static constexpr int max_count = 1'000'000;
  static constexpr int largest_periodicity = 1000;  ///< max_periodicity's bound.
  /// The fields a model file sets ([frf]): fields.hpp.
  static constexpr auto fields() {
    using O = SteadyStateOptions;
    return std::tuple{
        IntegerField{"steps_per_period", &O::steps_per_period, 8, max_count,
                     "Newmark steps (exact integrator: samples) per forcing period"},
        NumberField{"tolerance", &O::tolerance, "", open_unit,
                    "the Poincaré sections must repeat to this, relative to the largest state"},
        IntegerField{"max_periodicity", &O::max_periodicity, 1, largest_periodicity,
                     "the largest period (in forcing periods) looked for"},
        IntegerField{"max_periods", &O::max_periods, 1, max_count,
                     "forcing periods simulated before a response is declared not periodic"},
        IntegerField{"window_periods", &O::window_periods, 1, max_count,
                     "periods over which a non-periodic response's peaks are taken"},
    };
  }

  /// Throws std::invalid_argument naming the field that is out of range.
  void validate() const;
};

struct FrequencyResponseOptions {
  double amplitude = 0.0;        ///< A [m/s²]
  std::vector<double> ratios;    ///< ω̄/ω₁, ω₁ of frame 1 alone
  FrfMethod method = FrfMethod::simulation;
  SweepMode sweep = SweepMode::from_rest;  ///< simulation: the sweep
  SteadyStateOptions steady;     ///< simulation, and where continuation falls back to it
  /// continuation: the ratios span the range followed; orbits are sampled steady.steps_per_period
  /// times a period (peaks are refined between samples).
  ShootingOptions shooting;
  ContinuationOptions continuation;
  /// Integrator, event tolerance, lock time, separation; dt is set per point from T.
  TimeHistoryOptions time_history;
  int threads = 0;               ///< 0: all hardware threads. Results do not depend on it.
  /// Points from rest with Newmark that each thread steps together (integrate/lockstep.hpp), in
  /// [1, Lockstep::kLanes = 8]; 1 runs one point after another. Results do not depend on it.
  int lanes = 8;
  /// Called after every point with (points done, points in all); from worker threads.
  std::function<void(int, int)> progress;
};

/// Steady-state peaks per frame.
struct FrameAmplitudes {
  std::vector<double> base_shear;        ///< max |K₁u₁| [N]
  std::vector<double> storey_shear;      ///< max |K₁u₁ + C₁u̇₁| [N]
  std::vector<double> top_displacement;  ///< max |u| of the top floor [m]
};

struct FrfPoint {
  double ratio = 0.0;            ///< ω̄/ω₁
  double omega = 0.0;            ///< ω̄ [rad/s]
  SweepMode branch = SweepMode::from_rest;  ///< from_rest, up or down
  FrameAmplitudes interacting;
  FrameAmplitudes free;          ///< the frames without gap elements (closed form)
  int periodicity = 0;           ///< k ≥ 1, or 0 when not periodic within the budget
  int transient_periods = 0;     ///< periods simulated until the repetition was found (or the budget)
  long events = 0;               ///< events over the steady-state window
  long impacts = 0;              ///< impacts over the steady-state window
  // Continuation (FrfMethod::continuation):
  bool continued = false;        ///< a continued orbit (else simulated: stable by construction)
  int branch_id = -1;            ///< the branch it lies on (−1: simulated)
  int parent_branch = -1;        ///< the branch a period-doubled branch was born from
  bool stable = true;            ///< every Floquet multiplier inside the unit circle
  std::vector<std::complex<double>> multipliers;  ///< by decreasing modulus (continued orbits)
  BifurcationKind bifurcation = BifurcationKind::none;  ///< between this point and the one before
  /// A continued orbit's state on the Poincaré section (t = 0 mod its period), every floor in
  /// DofLayout's order: displacements [m] and velocities [m/s] from which the orbit repeats, so
  /// that it can be restarted or checked independently (empty for a simulated point).
  std::vector<double> section_u, section_v;
};

/// The peaks per frame of what `sim` ran since its statistics were last reset.
[[nodiscard]] FrameAmplitudes run_amplitudes(const Simulator& sim);

/// ω₁: fundamental circular frequency of frame 1 alone [rad/s].
[[nodiscard]] double reference_frequency(const Model& model);

/// Closed-form steady-state amplitudes of every frame alone (no gap elements).
[[nodiscard]] FrameAmplitudes free_response(const Model& model, double amplitude, double omega);

/// One point: the steady state reached from the state of `sim` (or from rest when null, in which
/// case `sim` is created), which is then left at that steady state (at a Poincaré section) for the
/// next point of a sweep. The transient runs with Simulator::record_responses(false) and the
/// whole point without the energy balance (meter_energy(false), which `sim` keeps): nothing here
/// reports either, and the window's peaks start at its reset_statistics() as before.
FrfPoint steady_state_point(const Model& model, double amplitude, double ratio,
                            const SteadyStateOptions& steady, const TimeHistoryOptions& options,
                            std::unique_ptr<Simulator>& sim);

/// The whole frequency response. Throws std::invalid_argument for bad options; errors of a point
/// (SimulationError) propagate.
std::vector<FrfPoint> frequency_response(const Model& model, const FrequencyResponseOptions& options);

}  // namespace poundsim
