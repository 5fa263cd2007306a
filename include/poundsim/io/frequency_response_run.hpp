#pragma once
/// @file
/// The frequency-response analysis as the command line runs it: DIR/frf.csv and DIR/summary.json
/// (formats in docs/output.md), all or nothing.

#include <filesystem>
#include <functional>
#include <map>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "poundsim/analysis/frequency_response.hpp"
#include "poundsim/io/input.hpp"
#include "poundsim/io/output_files.hpp"
#include "poundsim/io/table.hpp"

namespace poundsim::io {

/// The peaks of one frame's curves on one branch of a frequency response.
struct FramePeaks {
  double peak_v_w = 0;          ///< Largest V/W₁ with the gap elements.
  double peak_ratio = 0;        ///< ω̄/ω₁ where it is.
  double peak_free_v_w = 0;     ///< Largest V/W₁ of the frame alone.
  double peak_free_ratio = 0;   ///< ω̄/ω₁ where that is.
};

/// The points of one branch (from rest, up, down): how many, of which periodicity, the peaks.
struct BranchPeaks {
  int points = 0;
  std::map<int, int> periodicity;  ///< Periodicity (1 for period-1, 0 for not periodic) → points.
  std::vector<FramePeaks> frames;  ///< Per frame.
};

/// What a frequency-response run found, typed: summary.json (to_json) and the console report
/// (report) are both written from it.
struct FrequencyResponseResult {
  RunInput input;                  ///< What was run.
  std::vector<FrfPoint> points;    ///< In the order of the ratios (and branches).
  std::map<std::string, BranchPeaks> branches;  ///< By branch name.
  double run_time = 0;             ///< [s] wall clock, reported as is.
};

/// Runs the [frf] analysis of `input`, writing nothing (what the command line and the Python module
/// both run); `progress` (may be empty) is called after every point and may stop the run by
/// throwing (RunStopped).
FrequencyResponseResult analyse_frequency_response(const RunInput& input,
                                                   const std::function<void(int, int)>& progress = {});

/// Runs the [frf] analysis of `input` and writes its files into `out_dir`; `progress` (may be
/// empty) is called after every point. Returns what it found.
FrequencyResponseResult run_frequency_response(const RunInput& input, const std::filesystem::path& out_dir,
                                               const std::function<void(int, int)>& progress = {});

/// The result of the frequency response `points` of `input`: the peaks of every curve per branch.
FrequencyResponseResult frequency_response_result(const RunInput& input, std::vector<FrfPoint> points,
                                                  double run_time);

/// summary.json (docs/output.md).
nlohmann::json to_json(const FrequencyResponseResult& result);

/// The console report: the peaks per branch and frame, the files written into `out_dir`.
std::string report(const FrequencyResponseResult& result, const std::filesystem::path& out_dir);

/// The branches and bifurcations of continued points, typed: summary.json's `continuation` block
/// of a frequency response and the branches of a continuation in a parameter are written from it.
struct ContinuedBranch {
  int branch = 0, periodicity = 0, parent = -1, points = 0, stable_points = 0;
  double min = 0.0, max = 0.0;  ///< the range of the branch's x (ratio or parameter)
};
struct ContinuedBifurcation {
  int branch = 0;
  BifurcationKind kind = BifurcationKind::none;
  double at = 0.0;              ///< x of the point
  double max_multiplier = 0.0;  ///< its largest |μ|
};
struct ContinuedBranches {
  std::vector<ContinuedBranch> branches;  ///< by branch id
  std::vector<ContinuedBifurcation> bifurcations;  ///< in the points' order
};

/// Of the continued ones of `points`, point i at x = at[i].
[[nodiscard]] ContinuedBranches continued_branches(const std::vector<FrfPoint>& points, const std::vector<double>& at);

/// {"branches": [...], "bifurcations": [...]} with x named `x` (<x>_min, <x>_max, <x>).
nlohmann::json to_json(const ContinuedBranches& continued, std::string_view x);

/// The options of the library call that `input` describes.
FrequencyResponseOptions frequency_response_options(const RunInput& input);

/// The frf.csv table: ratio, V<f>_W…, V<f>_free_W…, periodicity, branch, transient_periods,
/// omega_rad_s, S<f>_W…, S<f>_free_W…, top<f>_m…, top<f>_free_m…, events, impacts (docs/output.md).
[[nodiscard]] Table frf_table(const Model& model, const std::vector<FrfPoint>& points);


}  // namespace poundsim::io
