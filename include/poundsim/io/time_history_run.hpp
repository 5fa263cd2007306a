#pragma once
/// @file
/// The time-history analysis as the command line runs it: integrate, write DIR/history.csv,
/// DIR/events.csv and DIR/summary.json (formats in docs/output.md), all or nothing.

#include <filesystem>

#include <nlohmann/json.hpp>

#include "poundsim/io/input.hpp"
#include "poundsim/integrate/simulator.hpp"

namespace poundsim::io {

/// Runs `input` and writes its files into `out_dir`. Returns the summary that was written.
/// Throws InputError for a model the simulator rejects, SimulationError when integration fails,
/// std::runtime_error when a file cannot be written; in every case no output file is left.
nlohmann::json run_time_history(const RunInput& input, const std::filesystem::path& out_dir);

/// The summary of a finished (or advanced) simulation; `free`: the statistics of the same frames
/// without gap elements (for amplifications and separation distances), or null; `run_time` [s]
/// is reported as is.
nlohmann::json summarize(const RunInput& input, const Simulator& sim, const ResponseStatistics* free,
                         double run_time);

/// The correlation coefficient of two modes (ω [rad/s], ζ) under broad-band excitation
/// (Der Kiureghian's CQC coefficient), used by the double-difference combination (DDC) of
/// separation distances: Δ = √(u_A² + u_B² − 2ρ u_A u_B).
double modal_correlation(double omega_a, double zeta_a, double omega_b, double zeta_b);

/// Frame and floor (1-based) of every DOF, for column names and reports.
std::string dof_label(const DofLayout& layout, int dof);

}  // namespace poundsim::io
