#pragma once
/// @file
/// Design of the gap elements (analysis.kind = "optimize"): NLopt chooses the variables (any
/// numeric input keys within bounds, e.g. η, μ, ε̄, δ̄, e) that minimise an objective — any
/// figure of merit of an evaluation: the larger peak V/W over a frequency band, the worse
/// frame's peak drift ratio or floor acceleration over an ensemble of records, … — subject to
/// limits on other figures (stroke use ≤ 1, element force ≤ a limit), with a global algorithm,
/// then a local one from its best point. Algorithms that take no constraints run inside NLopt's
/// augmented Lagrangian (AUGLAG). A Pareto front against a second figure comes from the
/// ε-constraint method: one constrained optimisation per limit on it. docs/studies.md
/// describes the input and the files.

#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "poundsim/analysis/figures_of_merit.hpp"
#include "poundsim/io/input.hpp"
#include "poundsim/io/point_distribution.hpp"
#include "poundsim/io/table.hpp"

namespace poundsim::optimize {

using io::OptimizeSettings;
using io::RunInput;

/// One NLopt stage as it ran.
struct OptimizationStage {
  std::string stage;        ///< "global" or "local" (a Pareto point's: "pareto[2].global", …).
  std::string algorithm;    ///< NLopt's name, e.g. GN_DIRECT_L, or AUGLAG(GN_DIRECT_L) when the
                            ///< augmented Lagrangian carries the constraints for it.
  std::string outcome;      ///< NLopt's result, e.g. MAXEVAL_REACHED.
  long evaluations = 0;     ///< New evaluations (a point evaluated before is not run again).
};

/// A constraint at a design: its figure's value there and whether it holds.
struct ConstraintOutcome {
  io::OptimizeConstraint constraint;
  std::optional<double> value;  ///< None when the design has no such figure (e.g. bare pounding's stroke use).
  bool holds = false;
};

/// One point of a Pareto front: the objective minimised with the second figure ≤ limit.
struct ParetoPoint {
  std::optional<double> limit;  ///< None: the objective's own optimum (no limit).
  std::vector<double> optimum;  ///< Per design variable.
  double objective = 0, metric = 0;
  bool feasible = false;   ///< It meets the limit and every constraint.
  bool dominated = false;  ///< Another point of the front is no worse in both and better in one.
};

/// The trade-off between the objective and a second figure (optimize.pareto).
struct ParetoResult {
  std::string objective, metric;  ///< Their columns.
  std::vector<ParetoPoint> points;  ///< In order of the limits, the objective's optimum last.
};

/// What an optimisation found, typed: optimize.json (to_json) and the console report (report)
/// are both written from it.
struct OptimizationResult {
  std::filesystem::path source;     ///< The input file.
  std::string title;
  OptimizeSettings settings;        ///< As run.
  std::vector<double> optimum;      ///< Per design variable, in the order of settings.variables.
  double objective = 0;             ///< The objective at the optimum.
  /// Whether the optimum meets every constraint (when none of the evaluations did, the optimum
  /// is the one that broke them least).
  bool feasible = true;
  std::vector<ConstraintOutcome> constraints, bare_constraints;  ///< At the optimum, of bare pounding.
  PointFigures optimum_figures;     ///< Every figure of merit of the optimum.
  PointFigures bare_figures;        ///< The same of bare pounding at the optimum's joints.
  std::string metric;               ///< The figure minimised, as its column (e.g. max_peak_V_W) …
  std::string meaning;              ///< … and what it measures.
  std::vector<OptimizationStage> stages;
  long evaluations = 0;
  /// Of the evaluations, those read from optimize.sqlite (an earlier run of the same input that
  /// was stopped or finished), not computed again.
  long reused = 0;
  /// Designs this run computed: the evaluations not read, and on several ranks the designs it
  /// guessed the search would ask for and it did not (kept in the database all the same).
  long computed = 0;
  double run_time = 0;              ///< [s] wall clock, reported as is.
  /// evaluations.csv: evaluation (from 1), stage, each variable, objective and each other
  /// figure a constraint or the front bounds (empty unless done), feasible (with constraints),
  /// status, error.
  io::Table evaluation_table;
  /// optimum_frf.csv and bare_frf.csv, for a frequency-response objective.
  std::optional<io::Table> optimum_frf, bare_frf;
  std::optional<ParetoResult> pareto;
  std::optional<io::Table> pareto_table;  ///< pareto.csv.

  /// The minimised figure of bare pounding, to compare with `objective`; none when bare
  /// pounding has no such figure.
  [[nodiscard]] std::optional<double> bare_objective() const { return bare_figures.figure(metric); }
};

/// Runs the optimisation of `input` and writes optimize.json, evaluations.csv, for a
/// frequency-response objective optimum_frf.csv and bare_frf.csv, and for a Pareto front
/// pareto.csv into `out_dir`. Every design evaluated is kept as it is computed in
/// `out_dir`/optimize.sqlite: a run of the same input that was stopped (or killed) and is run
/// again replays the search from it, computing only what it had not (a database of another
/// input is refused, InputError). `progress` is called after every evaluation with
/// (evaluations, budget).
/// `ranks`: the processes of an MPI job (rank 0 runs this; the others run serve_optimization),
/// which compute the designs of a batch at once — the designs NLopt will ask for next as far as
/// they can be foreseen, and an ensemble design's records —; the evaluations and the optimum are
/// the same bit for bit as on one process.
OptimizationResult run_optimization(const RunInput& input, const std::filesystem::path& out_dir,
                                    const std::function<void(int, int)>& progress = {},
                                    io::PointDistribution* ranks = nullptr);

/// A worker rank's part of run_optimization: computes the designs and records it is sent until
/// rank 0 ends the optimisation.
void serve_optimization(const RunInput& input, io::PointDistribution& ranks);

/// What the figure of column `name` measures, for reports ("" when it has no description).
[[nodiscard]] std::string figure_meaning(std::string_view name);

/// optimize.json (docs/studies.md).
nlohmann::json to_json(const OptimizationResult& result);

/// The console report: the optimum against bare pounding by the objective's metric, the files
/// written into `out_dir`.
std::string report(const OptimizationResult& result, const std::filesystem::path& out_dir);

}  // namespace poundsim::optimize
