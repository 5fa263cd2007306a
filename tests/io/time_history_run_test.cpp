// The time-history summary: the free frames, amplifications, and separation distances next to
// the code rules.

#include "poundsim/io/time_history_run.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "poundsim/analysis/response_metrics.hpp"
#include "../test_files.hpp"
#include "../test_models.hpp"

#include <gtest/gtest.h>

namespace poundsim::io {
namespace {

namespace fs = std::filesystem;

TEST(ModalCorrelation, IsTheCqcCoefficient) {
  EXPECT_DOUBLE_EQ(modal_correlation(10.0, 0.05, 10.0, 0.05), 1.0);
  // Periods 2 : 1, 5 % each: 8ζ²(1 + r) r^{3/2} / ((1 − r²)² + 4ζ² r (1 + r²) + 8ζ² r²) at r = 0.5.
  EXPECT_NEAR(modal_correlation(10.0, 0.05, 5.0, 0.05), 0.010606601717798213 / 0.57375, 1e-15);
  EXPECT_NEAR(modal_correlation(5.0, 0.05, 10.0, 0.05), modal_correlation(10.0, 0.05, 5.0, 0.05), 1e-15);
  EXPECT_LT(modal_correlation(10.0, 0.02, 10.5, 0.02), 0.9);  // close modes, light damping
  EXPECT_GT(modal_correlation(10.0, 0.2, 10.5, 0.2), 0.9);
}

TEST(TimeHistorySummary, SeparationAndAmplification) {
  const std::string text = R"([[frames]]
storeys = 2
mass = 1.0e5
stiffness = 5.0e7
damping_ratio = 0.05
storey_height = 3.0
[[frames]]
storeys = 1
mass = 1.0e5
stiffness = 1.2e8
damping_ratio = 0.05
storey_height = 3.0
[gap_elements]
gap = 0.001
restitution = 0.65
[excitation]
kind = "record"
file = "RSN6_IMPVALL.I_I-ELC180.AT2"
target_pga_g = 0.4
[analysis]
kind = "time_history"
duration = 15.0
dt = 0.002
output_dt = 0.1
)";
  const fs::path records = fs::path(POUNDSIM_SOURCE_DIR) / "data" / "ground_motions";
  const RunInput input = read_input_string(text, "two.toml", records);
  const fs::path out = fs::temp_directory_path() / "poundsim_th_summary";
  const nlohmann::json s = to_json(run_time_history(input, out));
  ASSERT_EQ(s["separation"].size(), 1u);
  const auto& sep = s["separation"][0];
  const double min_gap = sep["min_gap_m"].get<double>();
  const auto& rules = sep["rules"];
  const double abs_sum = rules["absolute_sum_m"], srss = rules["srss_m"], ddc = rules["ddc_m"];
  const double u1 = sep["free_peak_displacement_m"][0], u2 = sep["free_peak_displacement_m"][1];
  EXPECT_NEAR(abs_sum, u1 + u2, 1e-15);
  EXPECT_NEAR(srss, std::hypot(u1, u2), 1e-15);
  EXPECT_NEAR(rules["srss_same_floor_levels_m"].get<double>(), 0.7 * srss, 1e-15);
  EXPECT_LE(ddc, srss);
  EXPECT_LE(srss, abs_sum);
  // No combination of the peaks can ask for less than the peaks' difference.
  EXPECT_GE(min_gap, 0.0);
  EXPECT_LE(min_gap, abs_sum);
  EXPECT_TRUE(sep["contact"].get<bool>());  // a 1 mm gap is far too small
  EXPECT_NEAR(sep["gap_over_min_gap"].get<double>(), 0.001 / min_gap, 1e-12);
  EXPECT_NEAR(s["gap_elements"][0]["min_gap_m"].get<double>(), min_gap, 0.0);
  // Amplifications are pounding ÷ free, and drift ratios use the storey heights.
  const auto& floor = s["peaks"]["floors"][0];
  EXPECT_NEAR(floor["amplification"]["displacement"].get<double>(),
              floor["displacement_m"]["value"].get<double>() / floor["free"]["displacement_m"].get<double>(), 1e-15);
  EXPECT_NEAR(floor["interstorey_drift_ratio"].get<double>(), floor["interstorey_drift_m"]["value"].get<double>() / 3.0, 1e-15);
  // Pounding changes the base shears: amplification is the ratio of the two peaks, not 1.
  for (const auto& v : s["peaks"]["base_shear"]) {
    EXPECT_NEAR(v["amplification"].get<double>(), v["value_N"].get<double>() / v["free_value_N"].get<double>(), 1e-15);
    EXPECT_GT(std::abs(v["amplification"].get<double>() - 1.0), 1e-3);
  }
  EXPECT_NEAR(s["excitation"]["pga_g"].get<double>(), 0.4, 1e-12);
  EXPECT_EQ(s["excitation"]["format"], "at2");
  fs::remove_all(out);
}


// The run returns its findings typed; summary.json and the console report are both written from
// them (the program never reads its own JSON). The impacts it counts are the rows of events.csv.
TEST(TimeHistoryResult, SummaryAndReportAreWrittenFromIt) {
  const fs::path example = fs::path(POUNDSIM_SOURCE_DIR) / "examples" / "free_vibration_impact.toml";
  const fs::path out = fs::temp_directory_path() / "poundsim_th_result";
  const TimeHistoryResult r = run_time_history(read_input(example), out);
  std::ifstream summary(out / "summary.json");
  EXPECT_EQ(nlohmann::json::parse(summary), to_json(r));

  std::ifstream events(out / "events.csv");
  std::string line;
  int impact_rows = 0;
  while (std::getline(events, line)) impact_rows += line.find(",impact,") != std::string::npos ? 1 : 0;
  EXPECT_EQ(r.impacts(), impact_rows);
  EXPECT_EQ(r.impacts(), 14);  // the example's two frames released against each other, e = 0.65
  EXPECT_EQ(r.statistics.events, 14);
  EXPECT_EQ(r.energy.input, 0.0);  // free vibration: no ground motion
  EXPECT_LT(r.max_relative_residual, 1e-12);

  const std::string text = report(r, out);
  const Peak& v1 = r.statistics.base_shear[0];
  EXPECT_NE(text.find(fmt::format("frame 1: peak base shear {:.6g} N", v1.value)), std::string::npos) << text;
  EXPECT_NE(text.find(fmt::format("impacts 14, max gap force 0 N, max impact impulse {:.6g} N·s",
                                  r.max_impact_impulse())), std::string::npos) << text;
  EXPECT_NE(text.find(fmt::format("wrote {}/history.csv", out.string())), std::string::npos) << text;
  fs::remove_all(out);
}

// A smooth law stepped too coarsely: its balance residual (O(dt²)) passes the documented bound,
// and the run says so, with the advice for Newmark and smooth laws, in summary.json and the
// console report; at the example's own dt it closes and says nothing.
TEST(TimeHistoryResult, AnEnergyBalanceThatDoesNotCloseIsAWarningWithAdvice) {
  const fs::path example = fs::path(POUNDSIM_SOURCE_DIR) / "examples" / "contact_laws" / "hertzdamp.toml";
  const fs::path out = poundsim::testing::fresh_folder("energy_warning");
  const TimeHistoryResult coarse =
      run_time_history(read_input(example, std::vector<std::string>{"analysis.dt=0.005", "analysis.duration=10"}), out);
  EXPECT_GT(coarse.max_relative_residual, 1e-2);  // (seen: 2.5e-2)
  const nlohmann::json energy = to_json(coarse).at("energy");
  EXPECT_EQ(energy.at("warn_above"), 1e-3);
  const std::string warning = energy.at("warning").get<std::string>();
  EXPECT_NE(warning.find(fmt::format("relative residual reached {:.2e}, above 1e-03", coarse.max_relative_residual)),
            std::string::npos)
      << warning;
  EXPECT_NE(warning.find("halve analysis.dt"), std::string::npos) << warning;
  EXPECT_NE(report(coarse, out).find("  warning: " + warning), std::string::npos);

  const TimeHistoryResult fine = run_time_history(read_input(example, std::vector<std::string>{"analysis.duration=10"}), out);
  EXPECT_LT(fine.max_relative_residual, 1e-3);
  EXPECT_TRUE(to_json(fine).at("energy").at("warning").is_null());
  EXPECT_EQ(report(fine, out).find("  warning:"), std::string::npos);
  // Piecewise-linear laws close to round-off: the advice then says so.
  const std::optional<std::string> linear = energy_balance_warning(2e-3, Integrator::newmark, false);
  ASSERT_TRUE(linear.has_value());
  EXPECT_NE(linear->find("should close to round-off"), std::string::npos) << *linear;
  EXPECT_FALSE(energy_balance_warning(1e-3, Integrator::newmark, true).has_value());
  fs::remove_all(out);
}

// Frames with inelastic storeys: each storey's entry (ductility = peak drift ÷ yield drift,
// hysteretic energies summing to the balance's), and history.csv's drift and restoring-force
// columns, whose last row is the storey's state at the end.
TEST(TimeHistoryResult, InelasticStoreysReportTheirDuctilityResidualDriftAndHysteresis) {
  const fs::path example = fs::path(POUNDSIM_SOURCE_DIR) / "examples" / "el_centro_5_and_8_storeys_bilinear.toml";
  RunInput input = read_input(example);
  input.analysis.duration = 8.0;  // past the strong motion
  const fs::path out = fs::temp_directory_path() / "poundsim_th_bilinear";
  const TimeHistoryResult r = run_time_history(input, out);
  const nlohmann::json summary = to_json(r);
  double hysteretic = 0.0;
  int yielded = 0;
  for (const auto& floor : summary["peaks"]["floors"]) {
    const auto& storey = floor.at("storey");
    EXPECT_EQ(storey["yield_drift_m"].get<double>(), 0.010);
    EXPECT_DOUBLE_EQ(storey["ductility"].get<double>(), floor["interstorey_drift_m"]["value"].get<double>() / 0.010);
    hysteretic += storey["hysteretic_energy_J"].get<double>();
    // A storey dissipates hysteretic energy exactly when it yielded.
    EXPECT_EQ(storey["yield_excursions"].get<int>() > 0, storey["hysteretic_energy_J"].get<double>() > 0);
    yielded += storey["ductility"].get<double>() > 1 ? 1 : 0;
  }
  EXPECT_GE(yielded, 6);
  EXPECT_NEAR(hysteretic, summary["energy"]["storey_hysteretic_J"].get<double>(), 1e-9 * hysteretic);
  EXPECT_LT(r.max_relative_residual, 1e-5);  // Hertzdamp's Newton tolerance dominates

  std::ifstream history(out / "history.csv");
  std::string header, line, last;
  std::getline(history, header);
  while (std::getline(history, line)) last = line;
  std::vector<std::string> names, values;
  for (std::string* text : {&header, &last}) {
    std::vector<std::string>& into = text == &header ? names : values;
    std::size_t from = 0;
    for (std::size_t comma; (comma = text->find(',', from)) != std::string::npos; from = comma + 1) {
      into.push_back(text->substr(from, comma - from));
    }
    into.push_back(text->substr(from));
  }
  const auto column = [&](const std::string& name) {
    const auto at = std::find(names.begin(), names.end(), name);
    EXPECT_NE(at, names.end()) << name;
    return std::stod(values.at(static_cast<std::size_t>(at - names.begin())));
  };
  const auto& first = summary["peaks"]["floors"][0]["storey"];
  EXPECT_DOUBLE_EQ(column("drift_1_1_m"), first["residual_drift_m"].get<double>());
  // The first storey's restoring force at the end is the base shear's then.
  EXPECT_DOUBLE_EQ(column("Fs_1_1_N"), column("V_1_N"));
  EXPECT_DOUBLE_EQ(column("E_storey_hysteretic_J"), summary["energy"]["storey_hysteretic_J"].get<double>());
  fs::remove_all(out);
}

// A run whose gap elements never close moves as the free frames do, so the free response is then
// taken from it instead of a second run (analysis/time_history.cpp): every peak must be the one a
// free run gives, to the bit, whatever the integrator, storey law, contact law or facing. The
// shortcut must not be taken when the run had a contact, nor when outputs between grid points cut
// its steps (the free run takes whole steps).
TEST(TimeHistoryResult, FreeFramesOfARunWithoutContactAreTheFreeRunsToTheBit) {
  struct Case {
    std::string example;
    std::vector<std::string> settings;
    bool from_this_run;
    double output_dt = 0;  // set after reading (an input file's must be a multiple of dt)
  };
  const std::vector<Case> cases = {
      {"fig2c_ratio0.8.toml", {"model.dimensionless.delta=500"}, true},
      {"fig2c_ratio0.8.toml", {"model.dimensionless.delta=500", "analysis.integrator=\"exact\""}, true},
      {"fig4a_ratio0.7.toml", {"model.dimensionless.delta=500"}, true},
      // Outputs every 1.5 steps: the run's steps are cut, the free run's are not.
      {"fig2c_ratio0.8.toml", {"model.dimensionless.delta=500"}, false, 0.0015},
      {"fig2c_ratio0.8.toml", {}, false},  // it pounds
      // Bare pounding: impacts alone, no contact phase.
      {"fig2c_ratio0.8.toml", {"model.dimensionless.eta=0", "model.dimensionless.mu=0", "model.dimensionless.epsilon=0"},
       false},
      // A rigid stop reached with no closing speed, at a coarse event tolerance: no event, but the
      // step is cut there and the accelerations settled again — not the frames alone (a review
      // found the free peaks 4e-10 off when this run was taken for the free one).
      {"fig2c_ratio0.8.toml",
       {"model.dimensionless.eta=0", "model.dimensionless.mu=0", "model.dimensionless.epsilon=0",
        "analysis.duration=10.0", "analysis.event_tolerance=1e-4", "analysis.lock_time=1e-3",
        "model.dimensionless.delta=1.6394047771212414"},
       false},
      // Yielding storeys: their events are located (a run with located crossings makes its free
      // run). Bouc–Wen storeys (smooth, no events) and Hertzdamp elements: Newton's steps.
      {"el_centro_5_and_8_storeys_bilinear.toml", {"gap_elements.gap=1.0", "analysis.duration=6"}, false},
      {"el_centro_5_and_8_storeys_bilinear.toml",
       {"gap_elements.gap=1.0", "analysis.duration=6", "frames[1].storey_law=\"bouc_wen\"",
        "frames[2].storey_law=\"bouc_wen\""},
       true},
      {"slab_to_column.toml", {"gap_elements.gap=1.0", "analysis.duration=6"}, true},
      {"contact_laws/kelvin_voigt.toml", {"gap_elements.gap=1.0", "analysis.duration=4.0007"}, true},  // a partial last step
      {"three_buildings_el_centro.toml", {"gap_elements.gap=1.0", "gap_elements.override[1].joint_width=2",
        "gap_elements.override[1].gap=1.0", "analysis.duration=5"},
       true},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(fmt::format("{} {}", c.example, fmt::join(c.settings, " ")));
    RunInput input = read_input(fs::path(POUNDSIM_SOURCE_DIR) / "examples" / c.example, c.settings);
    if (c.output_dt > 0) input.analysis.output_dt = c.output_dt;
    const TimeHistoryResult r = analyse_run(input);
    ASSERT_TRUE(r.free.has_value());
    EXPECT_EQ(r.free_from_this_run, c.from_this_run);
    for (const GapResponse& g : r.statistics.gaps) {
      if (g.contacts + g.impacts + g.locks > 0) {
        EXPECT_FALSE(r.free_from_this_run);
      }
    }

    Simulator alone(free_frames(r.model), input.excitation, input.analysis.options, input.initial);
    alone.meter_energy(false);
    alone.advance_to(r.end_time);
    const ResponseStatistics &free = *r.free, &expected = alone.statistics();
    testing::expect_same_frame_peaks(free, expected);
    EXPECT_EQ(free.steps, expected.steps);
    EXPECT_EQ(free.substeps, expected.substeps);
    EXPECT_TRUE(free.gaps.empty());
  }
}

// Runs of one process that differ in their gap elements alone — a Python session trying one
// element after another, the points of a study — make the free run once (process_free_runs).
TEST(TimeHistoryResult, RunsOfOneProcessShareTheirFreeRun) {
  const fs::path example = fs::path(POUNDSIM_SOURCE_DIR) / "examples" / "fig2c_ratio0.8.toml";
  // A duration no other test uses: the memo is the process's.
  const RunInput first = read_input(example, std::vector<std::string>{"analysis.duration=3.217"});
  const RunInput second =
      read_input(example, std::vector<std::string>{"analysis.duration=3.217", "model.dimensionless.eta=0.5"});
  FreeRunMemo& memo = process_free_runs();
  const std::int64_t hits = memo.hits(), misses = memo.misses();
  const TimeHistoryResult a = analyse_run(first);
  EXPECT_EQ(memo.misses(), misses + 1);
  const TimeHistoryResult b = analyse_run(second);
  EXPECT_EQ(memo.hits(), hits + 1);
  EXPECT_NE(a.statistics.base_shear[0].value, b.statistics.base_shear[0].value);  // other elements
  Simulator alone(free_frames(b.model), second.excitation, second.analysis.options, second.initial);
  alone.meter_energy(false);
  alone.advance_to(b.end_time);
  ASSERT_TRUE(b.free.has_value());
  testing::expect_same_frame_peaks(*b.free, alone.statistics());
}

}  // namespace
}  // namespace poundsim::io
