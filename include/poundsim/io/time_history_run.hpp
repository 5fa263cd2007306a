#pragma once
/// @file
/// The time-history analysis as the command line runs it: analyse_time_history
/// (analysis/time_history.hpp), writing DIR/history.csv and DIR/events.csv as it runs and
/// DIR/summary.json and DIR/input.toml at the end (formats in docs/output.md), all or nothing.

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "poundsim/analysis/separation.hpp"
#include "poundsim/analysis/time_history.hpp"
#include "poundsim/io/input.hpp"
#include "poundsim/integrate/simulator.hpp"

namespace poundsim::io {

/// What a time-history run found, typed: summary.json (to_json) and the console report (report)
/// are both written from it; nothing reads the JSON back.
struct TimeHistoryResult : TimeHistoryAnalysis {
  RunInput input;        ///< What was run; summary.json echoes its model, excitation and analysis.
  double run_time = 0;   ///< [s] wall clock, reported as is.

  [[nodiscard]] int impacts() const;               ///< Over every gap element.
  [[nodiscard]] double max_gap_force() const;      ///< [N] over every gap element.
  [[nodiscard]] double max_impact_impulse() const; ///< [N·s] over every gap element.
};

/// The free runs of every time history this process makes — a run, a study's or an
/// optimisation's points, an ensemble's records, their MPI tasks, a Python session's runs: those
/// that differ in their gap elements alone share them (FreeRunMemo, analysis/time_history.hpp).
/// Up to 64 runs and 256 MiB kept.
[[nodiscard]] FreeRunMemo& process_free_runs();

/// Runs `input` (analyse_time_history) with `observer`, writing nothing: what the command line
/// and the Python module both run. Throws as run_time_history does.
TimeHistoryResult analyse_run(const RunInput& input, const TimeHistoryObserver& observer = {});

/// Runs `input` (analyse_time_history) and writes its files into `out_dir`. Returns what it
/// found (to_json of which is the summary that was written). Throws InputError for a model the
/// simulator rejects, SimulationError when integration fails, std::runtime_error when a file
/// cannot be written; in every case no output file is left.
TimeHistoryResult run_time_history(const RunInput& input, const std::filesystem::path& out_dir);

/// summary.json (docs/output.md).
nlohmann::json to_json(const TimeHistoryResult& result);

/// The separation at every pair of facing floors (analysis/separation.hpp) from the run's free
/// response; empty without a free run.
[[nodiscard]] std::vector<FloorSeparation> separations(const TimeHistoryResult& result);

/// The warning when the run's energy balance does not close well enough to trust it
/// (energy_balance_warning), in summary.json and the console report; nothing otherwise.
std::optional<std::string> energy_warning(const TimeHistoryResult& result);

/// The console report: peaks, impacts, energy balance, the files written into `out_dir`.
std::string report(const TimeHistoryResult& result, const std::filesystem::path& out_dir);


/// Frame and floor (1-based) of every DOF, for column names and reports.
std::string dof_label(const DofLayout& layout, int dof);

}  // namespace poundsim::io
