#pragma once
/// @file
/// How the record targets hand an input to the record readers.

#include <filesystem>
#include <string>
#include <string_view>

#include "fuzz_support.hpp"
#include "poundsim/io/ground_motion.hpp"

namespace poundsim::fuzz {

/// Reads `data` as the record file `name` with `options`: from memory through
/// io::parse_ground_motion where the library has it (found by argument-dependent lookup, so that
/// this compiles with and without it), else through a file in the scratch folder, which costs an
/// order of magnitude in executions per second.
template <class Options>
io::GroundMotionRecord read_record(std::string_view data, const std::filesystem::path& name, const Options& options) {
  if constexpr (requires { parse_ground_motion(std::string(data), name, options); }) {
    return parse_ground_motion(std::string(data), name, options);
  } else {
    static const std::filesystem::path file = scratch_dir() / name;
    write_file(file, data);
    return io::read_ground_motion(file, options);
  }
}

}  // namespace poundsim::fuzz
