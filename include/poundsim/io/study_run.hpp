#pragma once
/// @file
/// Parametric studies (analysis.kind = "study"): the same input run over a grid, a list or a
/// random sample of values of any input keys, each point a frequency response or a time history,
/// with figures of merit per point written to an SQLite database as the points finish.
/// docs/studies.md describes the input, the metrics and the files.

#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "poundsim/analysis/figures_of_merit.hpp"
#include "poundsim/io/input.hpp"
#include "poundsim/io/point_distribution.hpp"
#include "poundsim/io/study_database.hpp"
#include "poundsim/io/table.hpp"

namespace poundsim::io {

/// The settings of one point, in parameter order.
using PointValues = std::vector<Setting>;

/// The points of a study, in a fixed order (ids 0, 1, …): grid (the first parameter varies
/// slowest), list (zipped) or random (uniform, or log-uniform, from the seed).
std::vector<PointValues> study_points(const StudySettings& study);

/// The input of every point of a study or ensemble (`kind`), in id order, read from its settings
/// and so validated before anything runs: a point that breaks a rule is an InputError naming
/// where its parameter is defined, the point, its values and the rule.
std::vector<RunInput> point_inputs(const RunInput& input, AnalysisKind kind);

/// A stable fingerprint of everything that determines a run's results (model, analysis,
/// excitation, study or optimiser definition, the contents of its record files, the version):
/// FNV-1a of its canonical description.
std::string fingerprint(const RunInput& input);

/// Key of the bare-pounding reference of a point: points that share it share the reference.
std::string baseline_key(const RunInput& point);

/// Figures of merit of one point (docs/studies.md): its frequency response over the band of the
/// study or optimiser, its time history, or its ensemble's; compared with bare pounding whose
/// figures are `bare` (or not, when null: baseline_figures' columns). `threads` for a frequency
/// response's points and an ensemble's records.
PointFigures point_figures(const RunInput& point, int threads, const std::vector<FigureColumn>* bare);

/// The figures as the study table's columns, name → value (a count as an integer).
nlohmann::json to_json(const PointFigures& figures);

/// Figures stored as columns (to_json) as FigureColumns again.
std::vector<FigureColumn> figure_columns_of(const nlohmann::json& columns);

/// Bare pounding in the point's joints: every gap element a rigid stop (k = c = ε = 0) at the
/// width of its joint (RunInput::joint_widths), where the floors collide without the element.
[[nodiscard]] Model bare_pounding_model(const RunInput& point);

/// The bare-pounding version of a point (bare_pounding_model), its figures.
PointFigures baseline_figures(const RunInput& point, int threads);

/// The records' scale factors of an ensemble point ([ensemble.scaling]: they depend on the
/// point's model); empty without scaling.
[[nodiscard]] std::vector<double> record_factors(const RunInput& point);
/// The figures of record `record` of an ensemble point, its file scaled by `factor` when given.
[[nodiscard]] TimeHistoryFigures record_figures(const RunInput& point, std::size_t record, std::optional<double> factor);
/// A record's figures as bytes and back (CBOR of every field, each double to the bit): what the
/// ranks of an MPI job send each other.
[[nodiscard]] std::string to_bytes(const TimeHistoryFigures& figures);
[[nodiscard]] TimeHistoryFigures time_history_figures_from_bytes(const std::string& bytes);
/// A point's figures, whatever its kind, as bytes and back (the same): what an optimisation
/// keeps of each evaluation in its database and the ranks send each other.
[[nodiscard]] std::string to_bytes(const PointFigures& figures);
[[nodiscard]] PointFigures point_figures_from_bytes(const std::string& bytes);

struct StudyRunOptions {
  std::optional<long> max_points;               ///< Run at most this many new points, then stop.
  std::function<void(int, int)> progress;       ///< (done, to do) after every point.
  /// Asked before every point (and bare-pounding reference) starts: true stops the run with
  /// RunStopped once the points running have finished and are stored (may be empty).
  std::function<bool()> stop_requested;
  /// The processes that share the points (an MPI job), or none: this process's threads. On a
  /// worker rank the run computes what the coordinator sends, writes nothing and returns a
  /// result with `worker` set; the results are the same, bit for bit, whatever the ranks.
  PointDistribution* distribution = nullptr;
};

/// The finished point with the lowest max_peak_V_W.
struct BestPoint {
  long id = 0;                   ///< 1-based, as in study.csv.
  nlohmann::json parameters;     ///< Key → value of its overrides.
  nlohmann::json metrics;        ///< Metric name → value (docs/studies.md).
};

/// What a study or an ensemble run found, typed: summary.json (to_json) and the console report
/// (report) are both written from it. The parameters and metrics of a point stay name → value
/// maps: they are the columns of the study table, which the input chooses.
struct StudyResult {
  AnalysisKind kind = AnalysisKind::study;  ///< study or ensemble.
  bool worker = false;                    ///< A worker rank's: it computed points, wrote nothing, holds nothing else.
  std::filesystem::path source;           ///< The input file.
  std::string title;
  StudySettings study;                    ///< As run (an ensemble's: a list over its records).
  std::vector<std::string> parameters;    ///< The keys varied, in order.
  long points = 0;                        ///< In the whole study.
  long finished = 0;                      ///< Done or failed, earlier runs included.
  long failed = 0;
  long skipped_as_finished = 0;           ///< Finished by earlier runs, so not run now.
  long run_this_time = 0;
  std::optional<BestPoint> lowest_max_peak;
  std::filesystem::path database;         ///< study.sqlite or ensemble.sqlite.
  double run_time = 0;                    ///< [s] wall clock of this run, reported as is.
  std::vector<StudyDatabase::Row> rows;   ///< The whole database, by id.

  [[nodiscard]] bool complete() const { return finished == points; }
  /// Ensembles: the mean and the maximum of every numeric metric over the finished records
  /// (objects metric → value); null when no record finished.
  nlohmann::json mean, max;
  /// Ensembles with [ensemble.scaling]: the factors, the target and the range (record_scaling.hpp).
  nlohmann::json scaling;
  /// And the records' scaled spectra with their mean and the target (spectra.csv).
  std::optional<Table> spectra;
};

/// Runs the study of `input` into `out_dir`: study.sqlite (resumable), then study.csv and
/// summary.json. Returns what it found.
StudyResult run_study(const RunInput& input, const std::filesystem::path& out_dir,
                      const StudyRunOptions& options = {});

/// Runs an ensemble (analysis.kind = "ensemble"): one time history per record, in parallel,
/// into `out_dir`: ensemble.sqlite (resumable), ensemble.csv, and summary.json with the
/// per-record results and the mean and maximum of every metric over the records.
StudyResult run_ensemble(const RunInput& input, const std::filesystem::path& out_dir,
                         const StudyRunOptions& options = {});

/// summary.json of a study or an ensemble (docs/studies.md).
nlohmann::json to_json(const StudyResult& result);

/// The console report: points run, the best point (a study) or the per-frame means and maxima
/// (an ensemble), the files written into `out_dir`.
std::string report(const StudyResult& result, const std::filesystem::path& out_dir);

/// The points of a study as a table (study.csv, ensemble.csv; docs/studies.md): id (from 1),
/// status, the parameters, the figures of merit (by name), run_time_s, error.
[[nodiscard]] Table study_table(const std::vector<std::string>& parameters, const std::vector<StudyDatabase::Row>& rows);

/// The unit of a study or optimisation column: a figure's declared unit (declared_unit), else
/// from its name's SI suffix (_m, _m_s, _m_s2, _s, _N, _Ns, _J, _g, _rad_s; _W, _at, amp_… and
/// names with the word "ratio", "over" or "amplification": "1"), "" otherwise.
/// python/poundsim/results.py's column_unit reads the same declarations (poundsim._core's
/// figure_columns) for the files it reads (python/tests/test_analyses.py compares the two).
[[nodiscard]] std::string column_unit(std::string_view name);

/// Writes the points of a study database as CSV: id, status, parameters, metrics, error, run time.
void export_study(const std::filesystem::path& database, const std::filesystem::path& csv);

}  // namespace poundsim::io
