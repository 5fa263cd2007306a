#pragma once
/// @file
/// Exception types. Bad *input* (a file, a key, a value) is an InputError whose message already
/// names the file, the key or line and the rule that was broken; the command-line program prints
/// it and exits with code 2. A numerical failure during a run is a SimulationError (exit code 1).
/// Programmer errors are assertions, not exceptions.

#include <cstdint>
#include <stdexcept>
#include <string>
#include <utility>

namespace poundsim {

/// Invalid user input: a model, an option or a file. what() is the complete message.
class InputError : public std::runtime_error {
 public:
  explicit InputError(const std::string& message) : std::runtime_error(message) {}
  /// An error that a setting (`--set key=value`, a study point's or an optimiser variable's
  /// value) caused: `setting` is its key as given, so that a study can report the error where
  /// the file defines that parameter.
  InputError(const std::string& message, std::string setting)
      : std::runtime_error(message), setting_(std::move(setting)) {}
  /// The key of the setting the error is blamed on; empty when it is not blamed on one.
  [[nodiscard]] const std::string& setting() const { return setting_; }

 private:
  std::string setting_;
};

/// Why a simulation stopped: at the time it was asked to reach, or the failure that ended it.
enum class StopReason : std::uint8_t {
  reached_time,    ///< It reached the time asked for.
  non_finite,      ///< The state, a force or an energy is no longer finite.
  event_limit,     ///< More events within one step than max_events_per_step (chattering).
  event_location,  ///< An event could not be located.
  resonance,       ///< Exact integrator: forcing at a natural frequency of an undamped phase.
  singular_phase,  ///< A phase's Newmark matrix could not be factorised.
  no_convergence,  ///< Newton's iterations (smooth laws) did not converge within a step.
  other,           ///< Any other numerical failure.
};

/// The simulation could not continue (singular matrix, unresolvable chattering, ...); `reason`
/// says which (a simulator's run_to returns it as a status).
class SimulationError : public std::runtime_error {
 public:
  explicit SimulationError(const std::string& message, StopReason reason = StopReason::other)
      : std::runtime_error(message), reason_(reason) {}
  [[nodiscard]] StopReason reason() const { return reason_; }

 private:
  StopReason reason_;
};

/// A run stopped because its caller asked it to (Ctrl-C in Python, docs/python.md): thrown by a
/// progress callback or a stop check, it unwinds the run as any error does, so no output file is
/// committed and a study's database stays whole with every point finished so far.
class RunStopped : public std::runtime_error {
 public:
  RunStopped() : std::runtime_error("the run was stopped") {}
};

}  // namespace poundsim
