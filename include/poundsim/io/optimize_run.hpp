#pragma once
/// @file
/// Design of the gap elements (analysis.kind = "optimize"): NLopt chooses the variables (any
/// numeric input keys within bounds, e.g. η, μ, ε̄, δ̄, e) that minimise an objective — the larger
/// of the frames' peak V/W over a frequency band ("max_peak") or the larger ratio of peak to
/// free-frame peak ("max_ratio_to_free") — with a global algorithm, then a local one from its
/// best point. docs/studies.md describes the input and the files.

#include <filesystem>
#include <functional>

#include <nlohmann/json.hpp>

#include "poundsim/io/input.hpp"

namespace poundsim::io {

/// Runs the optimisation of `input` and writes optimize.json, evaluations.csv and, for a
/// frequency-response objective, optimum_frf.csv and bare_frf.csv into `out_dir`.
/// `progress` is called after every evaluation with (evaluations, budget).
nlohmann::json run_optimization(const RunInput& input, const std::filesystem::path& out_dir,
                                const std::function<void(int, int)>& progress = {});

}  // namespace poundsim::io
