// The continuation in a model parameter as the command line runs it (analysis.kind =
// "continuation"): Fig. 2c's frames at 0.8 ω₁ as the gap opens, where the contact ends at the gap
// the linear frames' closed form gives; its files; and the rules of [parameter].

#include "poundsim/io/continuation_run.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "poundsim/analysis/response_metrics.hpp"
#include "poundsim/error.hpp"
#include "poundsim/units.hpp"

namespace poundsim::io {
namespace {

namespace fs = std::filesystem;

const fs::path kExample = fs::path(POUNDSIM_SOURCE_DIR) / "examples" / "continuation" / "fig2c_gap.toml";

std::string error_of(const std::vector<std::string>& overrides) {
  try {
    static_cast<void>(read_input(kExample, overrides));
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(ContinuationRun, TheFramesStopTouchingWhereTheirClosedFormReachesTheGap) {
  const RunInput input = read_input(kExample, std::vector<std::string>{});
  ASSERT_TRUE(input.parameter);
  EXPECT_EQ(input.parameter->key, "model.dimensionless.delta");
  const fs::path out = fs::temp_directory_path() / "poundsim_continuation_run";
  fs::remove_all(out);
  const ContinuationRunResult r = run_continuation(input, out);

  // The gap is proportional to δ̄; the linear frames' relative displacement u₁ − u₂ is harmonic,
  // and the frames touch while its amplitude exceeds the gap: the grazing δ̄ in closed form.
  const Model at_one = read_input(kExample, std::vector<std::string>{"model.dimensionless.delta=1.0"}).model;
  const double gap_per_delta = at_one.gaps.front().gap();
  const double omega = 0.8 * reference_frequency(at_one);
  const double amplitude = 0.2 * standard_gravity;
  const Eigen::VectorXd x = linear_steady_state(at_one, amplitude, omega);  // [u1 u2 v1 v2]
  const double grazing = std::hypot(x(0) - x(1), (x(2) - x(3)) / omega) / gap_per_delta;
  ASSERT_GT(grazing, 1.0);
  ASSERT_LT(grazing, 1.1);

  double lowest = 10, highest = 0;
  int beyond = 0, grazings = 0;
  for (std::size_t i = 0; i < r.points.size(); ++i) {
    const ParameterPoint& p = r.points[i];
    EXPECT_EQ(p.response.ratio, 0.8);
    EXPECT_TRUE(p.response.continued);
    lowest = std::min(lowest, p.parameter);
    highest = std::max(highest, p.parameter);
    if (p.response.bifurcation == BifurcationKind::grazing) {
      // Flagged at the first point past it: the closed form lies between it and the one before.
      ++grazings;
      ASSERT_GT(i, 0u);
      EXPECT_LT(r.points[i - 1].parameter, grazing);
      EXPECT_GT(p.parameter, grazing);
    }
    if (p.parameter > grazing + 1e-9) {
      // Past it the orbit is the linear frames' steady state: the free response.
      ++beyond;
      EXPECT_EQ(p.response.events, 0) << p.parameter;
      for (std::size_t f = 0; f < 2; ++f) {
        EXPECT_NEAR(p.response.interacting.base_shear[f], p.response.free.base_shear[f],
                    1e-9 * p.response.free.base_shear[f])
            << p.parameter;
      }
    } else if (p.parameter < grazing - 1e-3) {
      EXPECT_GT(p.response.events, 0) << p.parameter;  // the gap element closes and opens
    }
  }
  EXPECT_EQ(grazings, 1);
  EXPECT_GT(beyond, 20);
  EXPECT_EQ(lowest, 0.05);  // each direction ends on its end of the range
  EXPECT_EQ(highest, 1.5);

  // orbits.csv: the parameter first, then frf.csv's columns, a row per point; summary.json is the
  // result's; input.toml runs again with the same key.
  std::ifstream csv(out / "orbits.csv");
  std::string header, line;
  std::getline(csv, header);
  EXPECT_EQ(header.rfind("parameter,ratio,V1_W,V2_W,", 0), 0u) << header;
  for (const char* column : {"branch_id", "stable", "max_multiplier", "bifurcation", "multipliers"}) {
    EXPECT_NE(header.find(column), std::string::npos) << column;
  }
  std::size_t rows = 0;
  while (std::getline(csv, line)) ++rows;
  EXPECT_EQ(rows, r.points.size());
  std::ifstream summary_file(out / "summary.json");
  const nlohmann::json summary = nlohmann::json::parse(summary_file);
  EXPECT_EQ(summary, to_json(r));
  EXPECT_EQ(summary["parameter"]["key"], "model.dimensionless.delta");
  EXPECT_EQ(summary["points"], r.points.size());
  const RunInput again = read_input(out / "input.toml", std::vector<std::string>{});
  ASSERT_TRUE(again.parameter);
  EXPECT_EQ(again.parameter->key, input.parameter->key);
  EXPECT_EQ(again.parameter->start, 0.25);
  fs::remove_all(out);
}

TEST(ContinuationInput, BadParametersAreRefusedNamingTheKey) {
  struct Case {
    std::vector<std::string> overrides;
    const char* expected;
  };
  const std::vector<Case> cases{
      {{"parameter.key=\"frf.amplitude_g\""}, "parameter.key: 'frf.amplitude_g' is not a key of the model"},
      {{"parameter.max=0.01"}, "parameter.max: must be larger than min"},
      {{"parameter.start=2.0"}, "parameter.start: must lie in [min, max]"},
      {{"frf.ratios=[0.8, 0.9]"}, "frf.ratios: analysis.kind = \"continuation\" runs at one forcing frequency"},
      {{"frf.method=\"simulation\""}, "frf.method: analysis.kind = \"continuation\" shoots and continues orbits"},
      {{"analysis.integrator=\"newmark\""}, "analysis.integrator: must be \"exact\" for continuation"},
      {{"analysis.kind=\"frf\""}, "parameter: only for analysis.kind = \"continuation\""},
  };
  for (const Case& c : cases) {
    const std::string message = error_of(c.overrides);
    EXPECT_NE(message.find(c.expected), std::string::npos) << c.overrides.front() << "\n" << message;
    EXPECT_NE(message.find("fig2c_gap.toml"), std::string::npos) << message;
  }
  // A value the model refuses inside the range is found before any run, named at the key.
  const RunInput negative = read_input(kExample, std::vector<std::string>{"parameter.min=-1.0"});
  try {
    static_cast<void>(analyse_continuation(negative));
    FAIL() << "a negative gap was accepted";
  } catch (const InputError& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find("parameter.key: at model.dimensionless.delta = -1"), std::string::npos) << message;
  }
}

}  // namespace
}  // namespace poundsim::io
