#pragma once
/// @file
/// Exception types. Bad *input* (a file, a key, a value) is an InputError whose message already
/// names the file, the key or line and the rule that was broken; the command-line program prints
/// it and exits with code 2. A numerical failure during a run is a SimulationError (exit code 1).
/// Programmer errors are assertions, not exceptions.

#include <stdexcept>
#include <string>

namespace poundsim {

/// Invalid user input: a model, an option or a file. what() is the complete message.
class InputError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// The simulation could not continue (singular matrix, unresolvable chattering, ...).
class SimulationError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

}  // namespace poundsim
