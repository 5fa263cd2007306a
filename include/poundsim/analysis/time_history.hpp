#pragma once
/// @file
/// A time history of a model under an excitation, without files: the simulator integrates to the
/// duration, an observer sees the state at every output instant and every event (the command
/// line writes them to history.csv and events.csv, io/time_history_run.hpp), and the result holds
/// the peaks, the energy balance and the same frames' response without gap elements
/// (amplifications and separation distances are taken from it).

#include <cstdint>
#include <deque>
#include <functional>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "poundsim/dynamics/energy.hpp"
#include "poundsim/dynamics/event.hpp"
#include "poundsim/integrate/response_monitor.hpp"
#include "poundsim/integrate/simulator.hpp"
#include "poundsim/model/excitation.hpp"
#include "poundsim/model/model.hpp"

namespace poundsim {

/// What to integrate, in SI.
struct TimeHistoryProblem {
  Model model;
  Excitation excitation;
  TimeHistoryOptions options;
  InitialConditions initial;
  double duration = 0.0;   ///< [s], > 0.
  double output_dt = 0.0;  ///< Spacing of the output instants [s], > 0.
};

/// The output instants of a problem after t = 0: output_dt, 2 output_dt, … up to the duration
/// (a last one at the duration when it is not a multiple), as a double so that a caller can
/// bound it before it becomes an integer.
[[nodiscard]] double output_instants(double duration, double output_dt);

/// What a time history shows its caller while it runs. Either may be empty.
struct TimeHistoryObserver {
  /// At t = 0, at every multiple of output_dt up to the duration, and at the duration.
  std::function<void(const Simulator&)> on_output;
  /// At every event (contact, impact, separation, lock, unlock), in time order.
  std::function<void(const Event&)> on_event;
};

/// What a time history found.
struct TimeHistoryAnalysis {
  Model model;                     ///< As the simulator integrated it.
  DofLayout layout;                ///< Its degrees of freedom (frame, floor).
  TimeHistoryOptions options;      ///< As the simulator applied them.
  ResponseStatistics statistics;   ///< Peaks and counts of the interacting frames.
  /// The same frames without gap elements over the same time; none without gap elements. Its
  /// peaks are the free run's to the bit; its counts (steps, guard evaluations) are this run's
  /// when free_from_this_run, otherwise those of the free run, possibly an earlier point's
  /// (FreeRunMemo).
  std::optional<ResponseStatistics> free;
  /// `free` is this run's own response, not a second run: no gap element closed, no guard fired
  /// and every step was a whole grid step, so the frames moved, to the bit, as they do without
  /// gap elements (docs/numerics.md, "The free frames' run").
  bool free_from_this_run = false;
  EnergyBalance energy;             ///< At the end [J].
  /// What each gap element's law dissipated [J] (EnergyMeter::element_dissipation); empty with
  /// the exact integrator, whose integrals are not per element.
  std::vector<double> element_dissipation;
  /// What each storey ended with, by the DOF of the floor above it: its drift at the end (the
  /// residual drift once the motion has died out) [m] and the hysteretic energy it dissipated
  /// [J] (0 for a storey that does not yield).
  std::vector<double> final_drift;
  std::vector<double> storey_hysteretic;
  double relative_residual = 0;     ///< Energy balance residual ÷ scale, at the end.
  double max_relative_residual = 0; ///< The largest over the run.
  double end_time = 0;              ///< [s]
};

/// When a run's energy balance is too far from closing to trust its response.
///
/// Newmark closes the balance of piecewise-linear laws to round-off (≈ 1e-14 of the largest
/// energy) and that of smooth laws (Hertz, Hertzdamp, Jankowski, Bouc–Wen) to O(dt²); the exact
/// integrator closes it to round-off. A larger residual says the steps are too long for the
/// contact or yielding they resolve.
struct EnergyBalanceCheck {
  /// The largest relative residual over the run above which a run warns [-].
  double warn_above = 1e-3;
};

/// The warning for a run whose largest relative energy residual exceeds `check.warn_above`,
/// with the advice that fits `integrator` and whether the model has smooth (Newton) laws;
/// nothing when the balance closes well enough.
[[nodiscard]] std::optional<std::string> energy_balance_warning(double max_relative_residual, Integrator integrator,
                                                                bool smooth_laws, const EnergyBalanceCheck& check = {});

/// What a free run depends on: the frames and the floors that face each other (not the gap
/// elements), the excitation, the options, the initial conditions and the end [s].
struct FreeRunKey {
  std::vector<Frame> frames;
  std::vector<FloorPair> facing;
  Excitation excitation;
  TimeHistoryOptions options;
  InitialConditions initial;
  double end_time = 0.0;
  [[nodiscard]] bool operator==(const FreeRunKey&) const = default;
};

/// Free runs already made, shared by the time histories of a study, an ensemble or an
/// optimisation whose points differ in their gap elements only (their frames, records and
/// options the same): a point whose free run is here takes its statistics instead of running
/// the frames again. A run is deterministic, so they are the bits it would compute. Keys are
/// compared with ==, and the numbers of the frames (masses, stiffnesses, dashpots, heights,
/// damping ratios), the excitation, the options and the initial conditions also bit for bit
/// (== takes −0 for +0). Only real free runs are kept, with their own counts. Thread-safe; at
/// most `capacity` runs and `byte_budget` bytes of keys and statistics are kept (a record is its
/// samples: a study over long records must not fill the memory), the least recently used dropped
/// first; a run larger than the budget alone is not kept.
class FreeRunMemo {
 public:
  explicit FreeRunMemo(std::size_t capacity = 64, std::size_t byte_budget = std::size_t{256} << 20)
      : capacity_(capacity), byte_budget_(byte_budget) {}
  /// The free frames' statistics for `key`, if a run made them.
  [[nodiscard]] std::optional<ResponseStatistics> find(const FreeRunKey& key);
  /// Keeps what the free run for `key` gave (nothing if it is kept already).
  void add(const FreeRunKey& key, const ResponseStatistics& free);
  /// Forgets every run (a long-lived process between unrelated studies).
  void clear();
  [[nodiscard]] std::int64_t hits() const;
  [[nodiscard]] std::int64_t misses() const;
  [[nodiscard]] std::size_t size() const;
  /// What the kept runs take, roughly: their keys' and statistics' arrays [bytes].
  [[nodiscard]] std::size_t bytes() const;

 private:
  struct Entry {
    std::uint64_t fingerprint = 0;
    std::size_t bytes = 0;
    FreeRunKey key;
    ResponseStatistics free;
  };
  /// The entry of `key` (with fingerprint `print`), or end(); the mutex held.
  std::deque<Entry>::iterator locate(std::uint64_t print, const FreeRunKey& key);
  std::size_t capacity_, byte_budget_;
  std::size_t bytes_ = 0;
  mutable std::mutex mutex_;
  std::deque<Entry> entries_;
  std::int64_t hits_ = 0, misses_ = 0;
};

/// The key of a problem's free run ending at `end_time`.
[[nodiscard]] FreeRunKey free_run_key(const TimeHistoryProblem& problem, double end_time);

/// Integrates `problem` to its duration. Throws std::invalid_argument for a model or options the
/// simulator refuses (or more output instants than an int64 holds), SimulationError when the
/// integration fails. With `memo`, the free run is taken from it when it holds one for the same key, and a run made
/// is added to it.
TimeHistoryAnalysis analyse_time_history(const TimeHistoryProblem& problem, const TimeHistoryObserver& observer = {},
                                         FreeRunMemo* memo = nullptr);

}  // namespace poundsim
