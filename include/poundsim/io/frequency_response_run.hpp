#pragma once
/// @file
/// The frequency-response analysis as the command line runs it: DIR/frf.csv and DIR/summary.json
/// (formats in docs/output.md), all or nothing.

#include <filesystem>
#include <functional>

#include <nlohmann/json.hpp>

#include "poundsim/analysis/frequency_response.hpp"
#include "poundsim/io/input.hpp"
#include "poundsim/io/output_files.hpp"

namespace poundsim::io {

/// Runs the [frf] analysis of `input` and writes its files into `out_dir`; `progress` (may be
/// empty) is called after every point. Returns the summary that was written.
nlohmann::json run_frequency_response(const RunInput& input, const std::filesystem::path& out_dir,
                                      const std::function<void(int, int)>& progress = {});

/// The options of the library call that `input` describes.
FrequencyResponseOptions frequency_response_options(const RunInput& input);

/// Writes the frf.csv table: ratio, V<f>_W…, V<f>_free_W…, periodicity, then the rest.
void write_frf_table(OutputFile& out, const Model& model, const std::vector<FrfPoint>& points);

/// Summary of a frequency response: peaks of every curve, periodicities, run time.
nlohmann::json summarize_frequency_response(const RunInput& input, const std::vector<FrfPoint>& points,
                                            double run_time);

}  // namespace poundsim::io
