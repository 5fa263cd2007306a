#pragma once
/// @file
/// The continuation in a model parameter as the command line runs it (analysis.kind =
/// "continuation"): periodic orbits at [frf]'s one forcing frequency followed as [parameter]'s key
/// runs through its range (analysis/periodic_orbits.hpp). DIR/orbits.csv, DIR/summary.json and
/// DIR/input.toml (formats in docs/output.md), all or nothing.

#include <filesystem>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "poundsim/analysis/periodic_orbits.hpp"
#include "poundsim/io/input.hpp"
#include "poundsim/io/table.hpp"

namespace poundsim::io {

/// What a continuation run found, typed: summary.json and the console report are written from it.
struct ContinuationRunResult {
  RunInput input;                        ///< What was run.
  std::vector<ParameterPoint> points;    ///< Branch after branch (upward from the start, then downward).
  Model start_model;                     ///< The model at [parameter].start (ω₁ and W₁ of the outputs).
  double run_time = 0;                   ///< [s] wall clock, reported as is.
};

/// Runs the continuation of `input`, writing nothing. A value of the parameter that the model
/// refuses (at min, start or max) is an InputError naming [parameter].key; no orbit to start from
/// is a SimulationError.
ContinuationRunResult analyse_continuation(const RunInput& input);

/// Runs it and writes its files into `out_dir`.
ContinuationRunResult run_continuation(const RunInput& input, const std::filesystem::path& out_dir);

/// orbits.csv: `parameter`, then frf.csv's columns (the ratio fixed; peaks over W₁ of the model at
/// the start), per continued point (docs/output.md).
[[nodiscard]] Table continuation_table(const ContinuationRunResult& result);

/// summary.json (docs/output.md).
nlohmann::json to_json(const ContinuationRunResult& result);

/// The console report: the branches and bifurcations, the files written into `out_dir`.
std::string report(const ContinuationRunResult& result, const std::filesystem::path& out_dir);

}  // namespace poundsim::io
