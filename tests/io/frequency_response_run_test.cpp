// The frequency-response run's typed result: the peaks per branch are the largest points of the
// curves it returns, and summary.json is written from the result.

#include "poundsim/io/frequency_response_run.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <numbers>
#include <string>

#include <fmt/format.h>
#include <gtest/gtest.h>

#include "poundsim/analysis/response_metrics.hpp"
#include "poundsim/error.hpp"
#include "poundsim/integrate/simulator.hpp"
#include "poundsim/units.hpp"

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


TEST(FrequencyResponseResult, ContinuationWritesBranchesStabilityAndBifurcations) {
  // Fig. 2b (bare pounding) between 0.55 and 0.8 by continuation: the resonance branch folds
  // (an unstable middle branch) and a period-doubling window follows, in which the responses
  // from rest that are not periodic are reported as simulated.
  const fs::path figure = fs::path(POUNDSIM_SOURCE_DIR) / "examples" / "paper" / "fig2b.toml";
  const std::vector<std::string> overrides{"frf.points=26", "frf.ratio_min=0.55", "frf.ratio_max=0.8",
                                           "frf.method=\"continuation\"", "analysis.integrator=\"exact\"",
                                           "frf.steps_per_period=32"};
  const RunInput input = read_input(figure, overrides);
  const fs::path out = fs::temp_directory_path() / "poundsim_frf_continuation";
  const FrequencyResponseResult r = run_frequency_response(input, out);
  int unstable = 0, folds = 0, doublings = 0, simulated = 0;
  for (const FrfPoint& p : r.points) {
    EXPECT_GE(p.ratio, 0.55);
    if (!p.continued) {
      EXPECT_EQ(p.periodicity, 0) << p.ratio;  // a periodic response from rest is continued
      EXPECT_GT(p.ratio, 0.7) << p.ratio;
      ++simulated;
      continue;
    }
    EXPECT_LE(p.ratio, 0.8);
    ASSERT_FALSE(p.multipliers.empty());
    EXPECT_EQ(p.stable, std::abs(p.multipliers.front()) < 1.0);
    unstable += p.stable ? 0 : 1;
    folds += p.bifurcation == BifurcationKind::fold ? 1 : 0;
    doublings += p.bifurcation == BifurcationKind::period_doubling ? 1 : 0;
  }
  EXPECT_GT(unstable, 0);
  EXPECT_GE(folds, 1);  // the resonance branch turns back
  EXPECT_GE(doublings, 1);
  EXPECT_GE(simulated, 1);
  // The peaks reported are those of stable orbits and of the responses simulated.
  const double w1 = reference_weight(input.model);
  double peak = 0;
  for (const FrfPoint& p : r.points) {
    if (p.stable || !p.continued) peak = std::max(peak, p.interacting.base_shear[0] / w1);
  }
  EXPECT_EQ(r.branches.at("continuation").frames[0].peak_v_w, peak);
  // frf.csv carries the branch, the stability and the multipliers; summary.json the bifurcations.
  std::ifstream csv(out / "frf.csv");
  std::string header;
  std::getline(csv, header);
  for (const char* column : {"branch_id", "parent_branch", "stable", "max_multiplier", "bifurcation", "multipliers"}) {
    EXPECT_NE(header.find(column), std::string::npos) << column;
  }
  std::ifstream summary_file(out / "summary.json");
  const nlohmann::json summary = nlohmann::json::parse(summary_file);
  EXPECT_EQ(summary, to_json(r));
  EXPECT_EQ(summary["analysis"]["method"], "continuation");
  EXPECT_GE(summary["continuation"]["bifurcations"].size(), 3u);
  fs::remove_all(out);
}

// Each continued orbit's state on the Poincaré section, run by the exact integrator from t = 0
// for its period, comes back to itself: the written state and period are the orbit's, checked
// independently of the shooting that found it. Fig. 2b from 0.55 to 0.8, stable and unstable
// orbits alike (an unstable one diverges only slowly over one period).
TEST(FrequencyResponseResult, AContinuedOrbitRestartedFromItsSectionStateRepeats) {
  const fs::path figure = fs::path(POUNDSIM_SOURCE_DIR) / "examples" / "paper" / "fig2b.toml";
  const RunInput input = read_input(figure, std::vector<std::string>{"frf.points=6", "frf.ratio_min=0.55", "frf.ratio_max=0.8",
                                                                     "frf.method=\"continuation\"",
                                                                     "analysis.integrator=\"exact\"", "frf.steps_per_period=32"});
  const FrequencyResponseResult r = analyse_frequency_response(input, {});
  const DofLayout layout(input.model);
  int checked = 0;
  for (std::size_t i = 0; i < r.points.size(); i += 7) {
    const FrfPoint& p = r.points[i];
    ASSERT_EQ(p.section_u.size(), static_cast<std::size_t>(layout.size()));
    InitialConditions ic;
    for (int f = 0; f < input.model.frame_count(); ++f) ic.displacement.emplace_back(), ic.velocity.emplace_back();
    for (int dof = 0; dof < layout.size(); ++dof) {
      ic.displacement[static_cast<std::size_t>(layout.frame_of(dof))].push_back(p.section_u[static_cast<std::size_t>(dof)]);
      ic.velocity[static_cast<std::size_t>(layout.frame_of(dof))].push_back(p.section_v[static_cast<std::size_t>(dof)]);
    }
    const double period = p.periodicity * 2 * std::numbers::pi / p.omega;
    TimeHistoryOptions options = input.analysis.options;
    options.integrator = Integrator::exact;
    options.dt = period / (32.0 * p.periodicity);
    Simulator sim(input.model, HarmonicExcitation{.amplitude = input.frf->amplitude_g * standard_gravity, .omega = p.omega},
                  options, ic);
    sim.advance_to(period);
    double size = 0, error = 0;
    for (int dof = 0; dof < layout.size(); ++dof) {
      const auto d = static_cast<std::size_t>(dof);
      size = std::max({size, std::abs(p.section_u[d]), std::abs(p.section_v[d]) / p.omega});
      error = std::max({error, std::abs(sim.state().u(dof) - p.section_u[d]),
                        std::abs(sim.state().v(dof) - p.section_v[d]) / p.omega});
    }
    EXPECT_LT(error, 1e-7 * size) << "ratio " << p.ratio << ", period " << p.periodicity;
    ++checked;
  }
  EXPECT_GE(checked, 3);
}

TEST(FrequencyResponseInput, ContinuationOptionsBelongToTheContinuationMethod) {
  const fs::path figure = fs::path(POUNDSIM_SOURCE_DIR) / "examples" / "paper" / "fig2c.toml";
  try {
    static_cast<void>(read_input(figure, std::vector<std::string>{"frf.continuation.max_step=0.5"}));
    FAIL() << "a [frf.continuation] table with method = \"simulation\" was accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("continuation"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("only for method = \"continuation\""), std::string::npos) << e.what();
  }
  try {
    static_cast<void>(read_input(figure, std::vector<std::string>{"frf.method=\"continuation\"", "frf.continuation.min_step=0.5"}));
    FAIL() << "min_step above initial_step was accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("min_step"), std::string::npos) << e.what();
  }
  try {
    static_cast<void>(read_input(figure, std::vector<std::string>{"frf.method=\"continuation\""}));
    FAIL() << "continuation with the Newmark integrator was accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("analysis.integrator: must be \"exact\" for continuation"), std::string::npos) << e.what();
  }
  const RunInput in = read_input(figure, std::vector<std::string>{"frf.method=\"continuation\"", "analysis.integrator=\"exact\"",
                                                                 "frf.continuation.max_parameter_step=0.002"});
  EXPECT_EQ(in.frf->method, FrfMethod::continuation);
  EXPECT_EQ(in.frf->continuation.max_parameter_step, 0.002);
  const FrequencyResponseOptions o = frequency_response_options(in);
  EXPECT_EQ(o.method, FrfMethod::continuation);
  EXPECT_EQ(o.continuation.max_parameter_step, 0.002);
}

TEST(FrequencyResponseInput, ContinuationIsTheDefaultWhereItApplies) {
  // The exact integrator, no sweep asked for, the displacement criterion: continuation; otherwise
  // the brute force, as before; a method given is the method run.
  const fs::path figure = fs::path(POUNDSIM_SOURCE_DIR) / "examples" / "paper" / "fig2c.toml";
  const auto method = [&](std::vector<std::string> overrides) { return read_input(figure, overrides).frf->method; };
  EXPECT_EQ(method({}), FrfMethod::simulation);  // the paper's inputs: Newmark
  EXPECT_EQ(method({"analysis.integrator=\"exact\""}), FrfMethod::continuation);
  EXPECT_EQ(method({"analysis.integrator=\"exact\"", "frf.sweep=\"up\""}), FrfMethod::simulation);
  EXPECT_EQ(method({"analysis.integrator=\"exact\"", "analysis.separation=\"force\""}), FrfMethod::simulation);
  EXPECT_EQ(method({"analysis.integrator=\"exact\"", "frf.method=\"simulation\""}), FrfMethod::simulation);
  // A study's points keep the brute force unless they ask (their metrics take every point).
  const fs::path study = fs::path(POUNDSIM_SOURCE_DIR) / "examples" / "study_eta_mu.toml";
  EXPECT_EQ(read_input(study, std::vector<std::string>{"analysis.integrator=\"exact\""}).frf->method, FrfMethod::simulation);
  // input.toml says which ran.
  const RunInput exact = read_input(figure, std::vector<std::string>{"analysis.integrator=\"exact\""});
  EXPECT_NE(to_toml(exact).find("method = 'continuation'"), std::string::npos) << to_toml(exact);
}

TEST(FrequencyResponseResult, APeriodTwoBubbleIsFollowedOnceRoundAndClosed) {
  // Fig. 4a near 1.365: the period-1 branch doubles its period at ≈ 1.3609 and undoubles at ≈ 1.37;
  // the period-2 branch born at the first is a closed bubble ending at the second. Followed from its
  // birth both ways, each way goes once round and stops where it began (without the closing test
  // it went round until its budget: hundreds of points).
  const fs::path figure = fs::path(POUNDSIM_SOURCE_DIR) / "examples" / "paper" / "fig4a.toml";
  const RunInput input = read_input(figure, std::vector<std::string>{
      "analysis.integrator=\"exact\"", "frf.steps_per_period=16", "frf.ratio_min=1.36", "frf.ratio_max=1.372", "frf.points=4"});
  ASSERT_EQ(input.frf->method, FrfMethod::continuation);
  const FrequencyResponseResult r = analyse_frequency_response(input);
  std::vector<double> doublings;
  std::map<int, std::pair<double, double>> bubbles;  // period-2 branch → its ratio range
  std::map<int, int> points;
  for (const FrfPoint& p : r.points) {
    if (p.periodicity == 1 && p.bifurcation == BifurcationKind::period_doubling) doublings.push_back(p.ratio);
    if (p.periodicity != 2 || p.parent_branch < 0) continue;
    auto [it, fresh] = bubbles.try_emplace(p.branch_id, p.ratio, p.ratio);
    it->second.first = std::min(it->second.first, p.ratio);
    it->second.second = std::max(it->second.second, p.ratio);
    ++points[p.branch_id];
  }
  ASSERT_EQ(doublings.size(), 2u);
  ASSERT_GE(bubbles.size(), 2u);
  for (const auto& [id, range] : bubbles) {
    if (points[id] < 20) continue;  // a short piece from the seed's side, not the bubble
    EXPECT_NEAR(range.first, std::min(doublings[0], doublings[1]), 1e-3) << id;
    EXPECT_NEAR(range.second, std::max(doublings[0], doublings[1]), 1e-3) << id;
    EXPECT_LT(points[id], 60) << id;
  }
}

}  // namespace
}  // namespace poundsim::io
