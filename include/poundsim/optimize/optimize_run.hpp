#pragma once
/// @file
/// Design of the gap elements (analysis.kind = "optimize"): NLopt chooses the variables (any
/// numeric input keys within bounds, e.g. η, μ, ε̄, δ̄, e) that minimise an objective — the larger
/// of the frames' peak V/W over a frequency band ("max_peak") or the larger ratio of peak to
/// free-frame peak ("max_ratio_to_free") — with a global algorithm, then a local one from its
/// best point. docs/studies.md describes the input and the files.

#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "poundsim/analysis/figures_of_merit.hpp"
#include "poundsim/io/input.hpp"
#include "poundsim/io/table.hpp"

namespace poundsim::optimize {

using io::Objective;
using io::OptimizeSettings;
using io::RunInput;

/// The figure that `objective` minimises, of a point's figures.
[[nodiscard]] inline double objective_of(const PointFigures& figures, Objective objective) {
  return objective == Objective::max_peak ? figures.max_peak_V_W() : figures.max_ratio_to_free();
}

/// One NLopt stage as it ran.
struct OptimizationStage {
  std::string stage;        ///< "global" or "local".
  std::string algorithm;    ///< NLopt's name, e.g. GN_DIRECT_L.
  std::string outcome;      ///< NLopt's result, e.g. MAXEVAL_REACHED.
  long evaluations = 0;
};

/// What an optimisation found, typed: optimize.json (to_json) and the console report (report)
/// are both written from it.
struct OptimizationResult {
  std::filesystem::path source;     ///< The input file.
  std::string title;
  OptimizeSettings settings;        ///< As run.
  std::vector<double> optimum;      ///< Per design variable, in the order of settings.variables.
  double objective = 0;             ///< The objective at the optimum.
  PointFigures optimum_figures;     ///< Every figure of merit of the optimum.
  PointFigures bare_figures;        ///< The same of bare pounding at the optimum's joints.
  std::string metric;               ///< The figure minimised, as its column (e.g. max_peak_V_W) …
  std::string meaning;              ///< … and what it measures.
  std::vector<OptimizationStage> stages;
  long evaluations = 0;
  double run_time = 0;              ///< [s] wall clock, reported as is.
  /// evaluations.csv: evaluation (from 1), stage, each variable, objective (empty unless done),
  /// status, error.
  io::Table evaluation_table;
  /// optimum_frf.csv and bare_frf.csv, for a frequency-response objective.
  std::optional<io::Table> optimum_frf, bare_frf;

  /// The minimised figure of bare pounding, to compare with `objective`.
  [[nodiscard]] double bare_objective() const {
    return objective_of(bare_figures, settings.objective);
  }
};

/// Runs the optimisation of `input` and writes optimize.json, evaluations.csv and, for a
/// frequency-response objective, optimum_frf.csv and bare_frf.csv into `out_dir`.
/// `progress` is called after every evaluation with (evaluations, budget).
OptimizationResult run_optimization(const RunInput& input, const std::filesystem::path& out_dir,
                                    const std::function<void(int, int)>& progress = {});

/// optimize.json (docs/studies.md).
nlohmann::json to_json(const OptimizationResult& result);

/// The console report: the optimum against bare pounding by the objective's metric, the files
/// written into `out_dir`.
std::string report(const OptimizationResult& result, const std::filesystem::path& out_dir);

}  // namespace poundsim::optimize
