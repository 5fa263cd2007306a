// The frequency-response run's typed result: the peaks per branch are the largest points of the
// curves it returns, and summary.json is written from the result.

#include "poundsim/io/frequency_response_run.hpp"

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <string>

#include <fmt/format.h>
#include <gtest/gtest.h>

#include "poundsim/analysis/response_metrics.hpp"

namespace poundsim::io {
namespace {

namespace fs = std::filesystem;

TEST(FrequencyResponseResult, PeaksAreThoseOfItsPointsAndTheSummaryIsWrittenFromIt) {
  // Figure 2c of the paper on a coarse grid, swept up and down.
  const fs::path figure = fs::path(POUNDSIM_SOURCE_DIR) / "examples" / "paper" / "fig2c.toml";
  const std::vector<std::string> overrides{"frf.points=8", "frf.sweep=\"both\"", "frf.ratio_min=0.6",
                                           "frf.ratio_max=1.3"};
  const RunInput input = read_input(figure, overrides);
  const fs::path out = fs::temp_directory_path() / "poundsim_frf_result";
  const FrequencyResponseResult r = run_frequency_response(input, out);
  ASSERT_EQ(r.points.size(), 16u);  // eight ratios, up and down
  ASSERT_EQ(r.branches.size(), 2u);
  const double w1 = reference_weight(input.model);
  for (const auto& [name, branch] : r.branches) {
    EXPECT_EQ(branch.points, 8) << name;
    int counted = 0;
    for (const auto& [periodicity, n] : branch.periodicity) counted += n;
    EXPECT_EQ(counted, 8) << name;
    for (std::size_t f = 0; f < 2; ++f) {
      double peak = 0, at = 0;
      for (const FrfPoint& p : r.points) {
        if (to_string(p.branch) == name && p.interacting.base_shear[f] / w1 > peak) {
          peak = p.interacting.base_shear[f] / w1;
          at = p.ratio;
        }
      }
      EXPECT_EQ(branch.frames[f].peak_v_w, peak) << name << " frame " << f + 1;
      EXPECT_EQ(branch.frames[f].peak_ratio, at) << name << " frame " << f + 1;
      EXPECT_GT(peak, 0.0);
    }
  }
  std::ifstream summary(out / "summary.json");
  EXPECT_EQ(nlohmann::json::parse(summary), to_json(r));
  const std::string text = report(r, out);
  const FramePeaks& up1 = r.branches.at("up").frames[0];
  EXPECT_NE(text.find(fmt::format("up   frame 1: peak V/W {:.4f} at ω̄/ω₁ = {:.3f}", up1.peak_v_w, up1.peak_ratio)),
            std::string::npos)
      << text;
  fs::remove_all(out);
}

}  // namespace
}  // namespace poundsim::io
