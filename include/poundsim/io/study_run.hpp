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

#include "poundsim/io/input.hpp"

namespace poundsim::io {

/// The key = value overrides of one point, in parameter order.
using PointValues = std::vector<std::pair<std::string, std::string>>;

/// The points of a study, in a fixed order (ids 0, 1, …): grid (the first parameter varies
/// slowest), list (zipped) or random (uniform, or log-uniform, from the seed).
std::vector<PointValues> study_points(const StudySettings& study);

/// `base` (a study or optimiser input) with one point's overrides applied.
RunInput read_point(const RunInput& base, const PointValues& values);

/// A stable fingerprint of everything that determines a run's results (model, analysis,
/// excitation, study or optimiser definition): FNV-1a of its canonical description.
std::string fingerprint(const RunInput& input);

/// Key of the bare-pounding reference of a point: points that share it share the reference.
std::string baseline_key(const RunInput& point);

/// Figures of merit of one point (docs/studies.md), `baseline` the bare-pounding point's own
/// metrics (or null). `threads` for a frequency response's points.
nlohmann::json point_metrics(const RunInput& point, int threads, const nlohmann::json* baseline);

/// Figures of merit of a frequency response of `model` over the band of ratios [band_min, band_max]
/// (docs/studies.md): band peaks of each frame with and without interaction, and their ratios.
nlohmann::json frf_metrics(const Model& model, const std::vector<FrfPoint>& response, double band_min,
                           double band_max);

/// Bare pounding in the point's joints: every gap element a rigid stop (k = c = ε = 0) at the
/// width of its joint (RunInput::joint_widths), where the floors collide without the element.
[[nodiscard]] Model bare_pounding_model(const RunInput& point);

/// The bare-pounding version of a point (bare_pounding_model), its metrics.
nlohmann::json baseline_metrics(const RunInput& point, int threads);

struct StudyRunOptions {
  std::optional<long> max_points;               ///< Run at most this many new points, then stop.
  std::function<void(int, int)> progress;       ///< (done, to do) after every point.
};

/// Runs the study of `input` into `out_dir`: study.sqlite (resumable), then study.csv and
/// summary.json. Returns the summary.
nlohmann::json run_study(const RunInput& input, const std::filesystem::path& out_dir,
                         const StudyRunOptions& options = {});

/// Runs an ensemble (analysis.kind = "ensemble"): one time history per record, in parallel,
/// into `out_dir`: ensemble.sqlite (resumable), ensemble.csv, and summary.json with the
/// per-record results and the mean and maximum of every metric over the records.
nlohmann::json run_ensemble(const RunInput& input, const std::filesystem::path& out_dir,
                            const StudyRunOptions& options = {});

/// Writes the points of a study database as CSV: id, status, parameters, metrics, error, run time.
void export_study(const std::filesystem::path& database, const std::filesystem::path& csv);

}  // namespace poundsim::io
