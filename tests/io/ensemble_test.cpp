// Ensembles of records: per-record results, their mean and maximum, resumption, and ensemble
// objectives for studies and the optimiser.

#include <cmath>
#include <filesystem>

#include <gtest/gtest.h>

#include "poundsim/io/study_database.hpp"
#include "poundsim/io/study_run.hpp"
#include "../test_models.hpp"

namespace poundsim::io {
namespace {

namespace fs = std::filesystem;

const fs::path kRecords = fs::path(POUNDSIM_SOURCE_DIR) / "data" / "ground_motions";

std::string ensemble_input(const std::string& kind) {
  return testing::model_toml("[1, 1]", testing::fig2('c')) + R"([excitation]
kind = "record"
target_pga_g = 0.3
[analysis]
kind = ")" + kind + R"("
dt = 0.002
duration = 8.0
[ensemble]
records = ["RSN6_IMPVALL.I_I-ELC180.AT2", "elCentro.AT2", "RSN758_LOMAP_EMY260.AT2"]
)";
}

RunInput read(const std::string& text, std::vector<std::string> overrides = {}) {
  return read_input_string(text, "ensemble.toml", kRecords, overrides);
}

TEST(Ensemble, MeanAndMaximumOverTheRecords) {
  const fs::path dir = fs::temp_directory_path() / "poundsim_ensemble";
  fs::remove_all(dir);
  StudyRunOptions first;
  first.max_points = 1;
  const RunInput in = read(ensemble_input("ensemble"));
  EXPECT_FALSE(run_ensemble(in, dir, first).complete());
  const nlohmann::json s = to_json(run_ensemble(in, dir));
  ASSERT_TRUE(s["complete"].get<bool>());
  ASSERT_EQ(s["records"].size(), 3u);
  const auto rows = StudyDatabase(dir / "ensemble.sqlite").rows();
  ASSERT_EQ(rows.size(), 3u);
  for (const char* key : {"peak_V1_W", "ratio_to_free_2", "amp_u_1_1", "min_gap_1_1_m", "impacts"}) {
    double sum = 0, largest = -1;
    for (const auto& r : rows) {
      sum += r.metrics[key].get<double>();
      largest = std::max(largest, r.metrics[key].get<double>());
    }
    EXPECT_NEAR(s["mean"][key].get<double>(), sum / 3, 1e-14 * std::abs(sum)) << key;
    EXPECT_EQ(s["max"][key].get<double>(), largest) << key;
  }
  for (const auto& r : rows) {
    EXPECT_NEAR(r.metrics["pga_g"].get<double>(), 0.3, 1e-12);
    EXPECT_LT(r.metrics["energy_residual"].get<double>(), 1e-10);
  }
  fs::remove_all(dir);
}

TEST(Ensemble, BareBaselineOfAnEnsemblePointIsBarePounding) {
  // The bare-pounding reference keeps the point's model when the records are re-read.
  std::string text = ensemble_input("study");
  text += R"([study]
each = "ensemble"
[[study.parameter]]
key = "model.dimensionless.mu"
values = [2.0]
)";
  const RunInput study = read(text);
  const RunInput point = with_settings(study, study_points(*study.study)[0]);
  const PointFigures bare_figures = baseline_figures(point, 1);
  const nlohmann::json bare = to_json(bare_figures);
  const std::vector<Setting> bare_settings{make_setting("model.dimensionless.eta", {0.0}),
                                           make_setting("model.dimensionless.mu", {0.0}),
                                           make_setting("model.dimensionless.epsilon", {0.0})};
  const RunInput made_bare = with_settings(study, bare_settings);
  const nlohmann::json direct = to_json(point_figures(made_bare, 1, nullptr));
  EXPECT_EQ(bare["max_peak_V_W"], direct["max_peak_V_W"]);
  EXPECT_EQ(bare["peak_V2_W"], direct["peak_V2_W"]);
  const std::vector<double> bare_peaks = bare_figures.peak_V_W();
  const PointFigures with_figures = point_figures(point, 1, &bare_peaks);
  const nlohmann::json with = to_json(with_figures);
  EXPECT_NE(with["max_peak_V_W"], bare["max_peak_V_W"]);  // the gap elements change the response
  EXPECT_NEAR(with["ratio_to_bare_1"].get<double>(), with["peak_V1_W"].get<double>() / bare["peak_V1_W"].get<double>(), 1e-15);
  // The typed figures and their columns agree: an ensemble's headline is its mean over records.
  EXPECT_EQ(with_figures.max_peak_V_W(), with["max_peak_V_W"].get<double>());
  EXPECT_EQ(with_figures.bare->max_ratio_to_bare, with["max_ratio_to_bare"].get<double>());
  EXPECT_EQ(bare_peaks, peak_V_W_of(bare, 2));
}

}  // namespace
}  // namespace poundsim::io
