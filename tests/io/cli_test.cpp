// The command-line program end to end: exit codes, messages, files written whole or not at all.

#include <sys/wait.h>

#include <algorithm>
#include <cctype>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "../test_files.hpp"
#include <nlohmann/json.hpp>

namespace {

namespace fs = std::filesystem;
using poundsim::testing::slurp;

struct Result {
  int code;
  std::string output;
};

Result run(const std::string& arguments) {
  const std::string command = std::string(POUNDSIM_CLI) + " " + arguments + " 2>&1";
  std::FILE* pipe = popen(command.c_str(), "r");
  std::string output;
  char buffer[4096];
  while (std::fgets(buffer, sizeof buffer, pipe) != nullptr) output += buffer;
  const int status = pclose(pipe);
  return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, output};
}


class Cli : public ::testing::Test {
 protected:
  void SetUp() override {
    std::string name = ::testing::UnitTest::GetInstance()->current_test_info()->name();
    std::replace(name.begin(), name.end(), '/', '_');  // a parametrised test's name: one folder
    dir_ = fs::temp_directory_path() / ("poundsim_cli_" + name);
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  fs::path write(const std::string& name, const std::string& text) {
    std::ofstream(dir_ / name) << text;
    return dir_ / name;
  }
  static std::string example(const std::string& name) {
    return std::string(POUNDSIM_SOURCE_DIR) + "/examples/" + name;
  }
  fs::path dir_;
};

TEST_F(Cli, VersionAndHelp) {
  EXPECT_EQ(run("--version").code, 0);
  EXPECT_NE(run("--version").output.find("poundsim 0."), std::string::npos);
  const Result help = run("run --help");
  EXPECT_EQ(help.code, 0);
  EXPECT_NE(help.output.find("--set"), std::string::npos);
  EXPECT_EQ(run("").code, 2);
  EXPECT_EQ(run("frobnicate").code, 2);
  EXPECT_EQ(run("run " + example("fig2c_ratio0.8.toml")).code, 2);  // --out is required
}

TEST_F(Cli, RunsTheFig2cExampleAndWritesTheThreeFiles) {
  const fs::path out = dir_ / "out";
  const Result r = run("run " + example("fig2c_ratio0.8.toml") + " --out " + out.string());
  ASSERT_EQ(r.code, 0) << r.output;
  ASSERT_TRUE(fs::exists(out / "history.csv"));
  ASSERT_TRUE(fs::exists(out / "events.csv"));
  ASSERT_TRUE(fs::exists(out / "summary.json"));
  for (const auto& entry : fs::directory_iterator(out)) {
    EXPECT_EQ(entry.path().filename().string().front() == '.', false) << "temporary left: " << entry.path();
  }
  std::istringstream history(slurp(out / "history.csv"));
  std::string header;
  std::getline(history, header);
  EXPECT_EQ(header, "t_s,u_1_1_m,u_2_1_m,v_1_1_m_s,v_2_1_m_s,a_1_1_m_s2,a_2_1_m_s2,V_1_N,V_2_N,F_1_1_N,E_input_J,"
                    "E_kinetic_J,E_storey_strain_J,E_gap_strain_J,E_storey_damping_J,E_gap_damping_J,E_impact_J,"
                    "E_residual_J");
  int rows = 0;
  for (std::string line; std::getline(history, line);) ++rows;
  EXPECT_EQ(rows, 2001);  // t = 0, 0.01, ..., 20
  const auto summary = nlohmann::json::parse(slurp(out / "summary.json"));
  EXPECT_EQ(summary["counts"]["steps"], 20000);
  EXPECT_GT(summary["impacts"].get<int>(), 0);
  EXPECT_LT(summary["energy"]["max_relative_residual"].get<double>(), 1e-11);
  EXPECT_NEAR(summary["excitation"]["ratio"].get<double>(), 0.8, 1e-15);
  const std::string events = slurp(out / "events.csv");
  EXPECT_EQ(events.rfind("t_s,frame_left,frame_right,floor,kind,relative_velocity_before_m_s,"
                         "relative_velocity_after_m_s,impulse_Ns\n", 0), 0u);
  EXPECT_NE(events.find(",1,2,1,impact,"), std::string::npos);
}

TEST_F(Cli, SameInputSameBytes) {
  const std::string model = example("fig2c_ratio0.8.toml") + " --set analysis.duration=5";
  ASSERT_EQ(run("run " + model + " --out " + (dir_ / "a").string()).code, 0);
  ASSERT_EQ(run("run " + model + " --out " + (dir_ / "b").string()).code, 0);
  EXPECT_EQ(slurp(dir_ / "a" / "history.csv"), slurp(dir_ / "b" / "history.csv"));
  EXPECT_EQ(slurp(dir_ / "a" / "events.csv"), slurp(dir_ / "b" / "events.csv"));
  auto a = nlohmann::json::parse(slurp(dir_ / "a" / "summary.json"));
  auto b = nlohmann::json::parse(slurp(dir_ / "b" / "summary.json"));
  a.erase("run_time_s");  // the one field that measures the machine, not the model
  b.erase("run_time_s");
  a.erase("input");
  b.erase("input");
  EXPECT_EQ(a, b);
}

TEST_F(Cli, BadInputExitsWithCodeTwoAndWritesNothing) {
  const fs::path out = dir_ / "out";
  fs::create_directories(out);
  std::ofstream(out / "summary.json") << "old results\n";
  const fs::path model = write("bad.toml", slurp(example("fig2c_ratio0.8.toml")) + "\n[extra]\nkey = 1\n");
  const Result r = run("run " + model.string() + " --out " + out.string());
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.output.find("bad.toml:"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("extra: unknown table"), std::string::npos) << r.output;
  EXPECT_EQ(slurp(out / "summary.json"), "old results\n");  // untouched
  EXPECT_FALSE(fs::exists(out / "history.csv"));

  const Result override = run("run " + example("fig2c_ratio0.8.toml") + " --out " + out.string() +
                              " --set model.dimensionless.restitution=2");
  EXPECT_EQ(override.code, 2);
  EXPECT_NE(override.output.find("--set model.dimensionless.restitution=2: "
                                 "model.dimensionless.restitution: must be in [0, 1] (got 2)"),
            std::string::npos)
      << override.output;
  // --max-points limits the points of a study or an ensemble; anywhere else it is an error, not ignored.
  for (const char* other : {"fig2c_ratio0.8.toml", "optimize_gap_elements.toml"}) {
    const Result limited = run("run " + example(other) + " --out " + out.string() + " --max-points 3");
    EXPECT_EQ(limited.code, 2) << other;
    EXPECT_NE(limited.output.find("--max-points applies to studies and ensembles only"), std::string::npos)
        << limited.output;
  }
  const Result missing = run("run " + (dir_ / "nothing.toml").string() + " --out " + out.string());
  EXPECT_EQ(missing.code, 2);
  EXPECT_NE(missing.output.find("nothing.toml: cannot open the model file"), std::string::npos);
  EXPECT_FALSE(fs::exists(out / "history.csv"));
}

// `poundsim check` reads and validates a file — its records and every study point or ensemble
// record included — without running anything or writing a file; bad input exits 2 with run's
// message.
TEST_F(Cli, CheckValidatesWithoutRunning) {
  const fs::path before = fs::current_path();
  fs::current_path(dir_);
  const Result study = run("check " + example("study_eta_mu.toml"));
  EXPECT_EQ(study.code, 0) << study.output;
  EXPECT_NE(study.output.find("valid: analysis.kind = \"study\", 2 frames, 1 gap elements, 20 points read and valid"),
            std::string::npos)
      << study.output;
  const Result ensemble = run("check " + example("ensemble_fig2_frames.toml"));
  EXPECT_EQ(ensemble.code, 0) << ensemble.output;
  EXPECT_NE(ensemble.output.find("4 records read and valid"), std::string::npos) << ensemble.output;
  EXPECT_TRUE(fs::is_empty(dir_));
  // A study point that breaks a rule: μ < 0 at the third point, named with where the parameter is
  // defined and its values.
  std::string text = slurp(example("study_eta_mu.toml"));
  text.replace(text.find("values = [0.0, 0.5, 1.0, 2.0]"), 30, "values = [0.0, 0.5, -1.0, 2.0]");
  const Result point = run("check " + write("bad_point.toml", text).string());
  EXPECT_EQ(point.code, 2) << point.output;
  EXPECT_NE(point.output.find("study.parameter[2].key: study point 3 (model.dimensionless.eta = 0.0, model.dimensionless.mu = -1.0)"),
            std::string::npos)
      << point.output;
  // A misspelt key, with --set as for run.
  const Result misspelt = run("check " + example("fig2c_ratio0.8.toml") + " --set analysis.durtion=3");
  EXPECT_EQ(misspelt.code, 2) << misspelt.output;
  EXPECT_NE(misspelt.output.find("analysis.durtion: unknown key for kind = \"time_history\"; did you mean 'duration'?"),
            std::string::npos)
      << misspelt.output;
  fs::current_path(before);
}

TEST_F(Cli, UnwritableOutputFailsWithCodeOne) {
  const fs::path blocker = write("occupied", "a file where the folder should be");
  const Result r = run("run " + example("fig2c_ratio0.8.toml") + " --out " + (blocker / "sub").string());
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.output.find("cannot create the output folder"), std::string::npos) << r.output;
}

/// Every example input (examples/, examples/paper/, examples/contact_laws/), sorted: one test
/// each below, so that ctest spreads them over the cores (under the sanitizers they take minutes).
std::vector<fs::path> example_files() {
  std::vector<fs::path> examples;
  for (const auto& dir : {"/examples", "/examples/paper", "/examples/contact_laws"}) {
    for (const auto& entry : fs::directory_iterator(std::string(POUNDSIM_SOURCE_DIR) + dir)) {
      if (entry.path().extension() == ".toml") examples.push_back(entry.path());
    }
  }
  std::sort(examples.begin(), examples.end());
  return examples;
}

TEST(CliExamples, AllAreRun) { EXPECT_GE(example_files().size(), 21u); }

class CliExample : public Cli, public ::testing::WithParamInterface<fs::path> {};

// Time histories and frequency responses with both integrators; studies and the optimiser
// (whose points are frequency responses) with Newmark and a smaller budget.
TEST_P(CliExample, RunsWithBothIntegrators) {
  const fs::path& example = GetParam();
  const std::string text = slurp(example);
  const bool frf = text.find("kind = \"frf\"") != std::string::npos;
  const bool study = text.find("kind = \"study\"") != std::string::npos;
  const bool optimize = text.find("kind = \"optimize\"") != std::string::npos;
  const bool ensemble = text.find("kind = \"ensemble\"") != std::string::npos;
  // The smooth contact laws: Newmark alone, whose balance's residual is then its integration
  // error, O((ωh)²) (docs/model.md#smooth-contact-laws), not round-off.
  const bool smooth = text.find("law = \"hertz") != std::string::npos || text.find("law = \"jankowski\"") != std::string::npos;
  for (const char* integrator : {"newmark", "exact"}) {
    if ((study || optimize) && std::string(integrator) == "exact") continue;
    if (smooth && std::string(integrator) == "exact") {
      const Result refused = run("run " + example.string() + " --quiet --out " + (dir_ / "refused").string() +
                                 " --set analysis.integrator=exact");
      EXPECT_EQ(refused.code, 2) << example;
      EXPECT_NE(refused.output.find("is not piecewise linear: use integrator = \"newmark\""), std::string::npos)
          << refused.output;
      EXPECT_FALSE(fs::exists(dir_ / "refused")) << example;
      continue;
    }
    const fs::path out = dir_ / (example.stem().string() + "_" + integrator);
    std::string extra = std::string(" --set analysis.integrator=") + integrator;
    // Simulated (continuation, the exact integrator's default, has tests of its own).
    if (frf && std::string(integrator) == "exact") {
      extra += " --set frf.points=12 --set frf.steps_per_period=16 --set frf.method=simulation";
    }
    if (optimize) extra += " --set optimize.global_evaluations=6 --set optimize.local_evaluations=4";
    // An optimisation over a suite of records with a front: 2 s of each record (the sanitizers).
    if (optimize && text.find("[optimize.pareto]") != std::string::npos) extra += " --set analysis.duration=2";
    const Result r = run("run " + example.string() + " --quiet --out " + out.string() + extra);
    EXPECT_EQ(r.code, 0) << example << "\n" << r.output;
    EXPECT_EQ(r.output, "") << example;
    if (study) {
      EXPECT_TRUE(fs::exists(out / "study.csv")) << example;
    } else if (ensemble) {
      const auto summary = nlohmann::json::parse(slurp(out / "summary.json"));
      EXPECT_TRUE(summary["complete"].get<bool>()) << example;
      EXPECT_EQ(summary["failed"], 0) << example;
      EXPECT_TRUE(fs::exists(out / "ensemble.csv")) << example;
    } else if (optimize) {
      EXPECT_TRUE(fs::exists(out / "optimize.json")) << example;
    } else if (frf) {
      EXPECT_TRUE(fs::exists(out / "frf.csv")) << example;
    } else {
      const auto summary = nlohmann::json::parse(slurp(out / "summary.json"));
      EXPECT_EQ(summary["analysis"]["integrator"], integrator);
      EXPECT_LT(summary["energy"]["max_relative_residual"].get<double>(), smooth ? 1e-4 : 1e-9) << example;
    }
  }
}

INSTANTIATE_TEST_SUITE_P(Examples, CliExample, ::testing::ValuesIn(example_files()),
                         [](const ::testing::TestParamInfo<fs::path>& example) {
                           std::string name = example.param.parent_path().filename().string() + "_" + example.param.stem().string();
                           for (char& c : name) {
                             if (std::isalnum(static_cast<unsigned char>(c)) == 0) c = '_';
                           }
                           return name;
                         });

TEST_F(Cli, FrequencyResponseWritesTheTable) {
  const fs::path out = dir_ / "frf";
  const Result r = run("run " + example("paper/fig2a.toml") + " --out " + out.string() +
                       " --set frf.points=5 --set frf.sweep=both");
  ASSERT_EQ(r.code, 0) << r.output;
  std::istringstream table(slurp(out / "frf.csv"));
  std::string header;
  std::getline(table, header);
  EXPECT_EQ(header.rfind("ratio,V1_W,V2_W,V1_free_W,V2_free_W,periodicity,branch,", 0), 0u) << header;
  int up = 0, down = 0;
  for (std::string line; std::getline(table, line);) {
    up += line.find(",up,") != std::string::npos;
    down += line.find(",down,") != std::string::npos;
  }
  EXPECT_EQ(up, 5);
  EXPECT_EQ(down, 5);
  const auto summary = nlohmann::json::parse(slurp(out / "summary.json"));
  EXPECT_EQ(summary["analysis"]["kind"], "frf");
  EXPECT_TRUE(summary["branches"].contains("up"));
  // The free frames' peak over five points 0.2 … 1.6 lies at ω̄/ω₁ = 0.55 or 0.9 …; V/W > 0.
  EXPECT_GT(summary["branches"]["up"]["frames"][0]["peak_free_V_W"].get<double>(), 0.2);
}

// Defect 6: --max-points 0 printed CLI11's range of a long double (309 digits).
TEST_F(Cli, MaxPointsMustBeAWholeNumberOfPoints) {
  const std::string study = example("study_eta_mu.toml") + " --out " + (dir_ / "out").string();
  for (const char* bad : {"0", "-1", "abc", "1e3", "99999999999999999999"}) {
    const Result r = run("run " + study + " --max-points " + bad);
    EXPECT_EQ(r.code, 2) << bad;
    EXPECT_NE(r.output.find(std::string("--max-points ") + bad + ": expected a whole number of points from 1 to "
                            "9223372036854775807"), std::string::npos) << r.output;
    EXPECT_LT(r.output.size(), 200u) << r.output;
  }
  EXPECT_FALSE(fs::exists(dir_ / "out"));
}

// Defects 5 and 6: a directory read as an empty model ("dir.toml:1:1: : missing …"), /dev/zero
// was read without end.
TEST_F(Cli, ModelMustBeARegularFileOfBoundedSize) {
  fs::create_directories(dir_ / "dir.toml");
  const Result directory = run("run " + (dir_ / "dir.toml").string() + " --out " + (dir_ / "out").string());
  EXPECT_EQ(directory.code, 2);
  EXPECT_NE(directory.output.find("dir.toml: cannot read the model file: a directory"), std::string::npos)
      << directory.output;
  EXPECT_EQ(directory.output.find(": :"), std::string::npos) << directory.output;
  const Result zero = run("run /dev/zero --out " + (dir_ / "out").string());
  EXPECT_EQ(zero.code, 2);
  EXPECT_NE(zero.output.find("/dev/zero: cannot read the model file: not a regular file"), std::string::npos)
      << zero.output;
  EXPECT_FALSE(fs::exists(dir_ / "out"));
}

// Defect 12: bare pounding, the reference of studies and the optimiser, collides at the joint
// width, not at the gap element's gap: a 20 mm gap with 10 mm of travel in a 40 mm joint.
TEST_F(Cli, BarePoundingBaselinesCollideAtTheJointWidth) {
  const std::string frames = R"([[frames]]
storeys = 2
mass = 1.0e5
stiffness = 1.0e8
damping_ratio = 0.02
[[frames]]
storeys = 2
mass = 1.0e5
stiffness = 3.0e8
damping_ratio = 0.02
[gap_elements]
gap = 0.02
shortening = 0.01
stiffness = 2.0e7
restitution = 0.5
joint_width = 0.04
[excitation]
kind = "harmonic"
amplitude_g = 0.6
ratio = 1.0
)";
  const std::string analysis = "[analysis]\nkind = \"time_history\"\nduration = 3.0\ndt = 0.002\n";
  const fs::path direct = write("direct.toml", frames + analysis);
  const fs::path study = write("study.toml", frames + R"([analysis]
kind = "study"
duration = 3.0
dt = 0.002
[study]
each = "time_history"
[[study.parameter]]
key = "gap_elements.damping"
values = [0.0, 1.0e5]
)");
  ASSERT_EQ(run("run " + study.string() + " --quiet --out " + (dir_ / "study").string()).code, 0);
  const std::string bare_set = " --set gap_elements.stiffness=0.0 --set gap_elements.shortening=0.0 --quiet";
  ASSERT_EQ(run("run " + direct.string() + bare_set + " --set gap_elements.gap=0.04 --out " + (dir_ / "joint").string()).code, 0);
  ASSERT_EQ(run("run " + direct.string() + bare_set + " --out " + (dir_ / "gap").string()).code, 0);
  const auto peak = [&](const std::string& folder, int frame) {
    return nlohmann::json::parse(slurp(dir_ / folder / "summary.json"))["peaks"]["base_shear"][frame]["over_frame1_weight"]
        .get<double>();
  };
  // The study's CSV: the bare peaks of every point are those of the direct run at 40 mm.
  std::istringstream csv(slurp(dir_ / "study" / "study.csv"));
  std::string header, row;
  std::getline(csv, header);
  std::vector<std::string> names;
  for (std::stringstream h(header); std::getline(h, row, ',');) names.push_back(row);
  int rows = 0;
  for (std::string line; std::getline(csv, line); ++rows) {
    std::vector<std::string> cells;
    for (std::stringstream l(line); std::getline(l, row, ',');) cells.push_back(row);
    for (int f = 0; f < 2; ++f) {
      const auto at = std::find(names.begin(), names.end(), "bare_peak_V" + std::to_string(f + 1) + "_W");
      ASSERT_NE(at, names.end()) << header;
      EXPECT_EQ(std::stod(cells[static_cast<std::size_t>(at - names.begin())]), peak("joint", f)) << line;
    }
  }
  EXPECT_EQ(rows, 2);
  EXPECT_GT(nlohmann::json::parse(slurp(dir_ / "joint" / "summary.json"))["impacts"].get<int>(), 0);
  EXPECT_NE(peak("joint", 0), peak("gap", 0));  // the joint matters: at 20 mm the response differs

  // The optimiser's bare-pounding response is the frequency response of bare pounding at the joint.
  const std::string model = R"([model]
storeys = [1, 1]
[model.dimensionless]
lambda2 = 200.0
alpha = 0.25
beta = 1.0
gamma = 0.5
xi = 0.05
delta = 0.25
eta = 0.125
mu = 1.0
epsilon = 0.5
restitution = 0.75
joint_width = 1.0
[frf]
amplitude_g = 0.2
ratio_min = 0.6
ratio_max = 1.2
points = 3
steps_per_period = 32
max_periods = 100
)";
  const fs::path optimize = write("optimize.toml", model + R"([analysis]
kind = "optimize"
[optimize]
each = "frf"
global = "none"
local_evaluations = 2
[[optimize.variable]]
key = "model.dimensionless.eta"
min = 0.0
max = 0.25
)");
  const fs::path frf = write("frf.toml", model + "[analysis]\nkind = \"frf\"\n");
  ASSERT_EQ(run("run " + optimize.string() + " --quiet --out " + (dir_ / "optimize").string()).code, 0);
  ASSERT_EQ(run("run " + frf.string() + " --quiet --out " + (dir_ / "bare") .string() +
                " --set model.dimensionless.delta=1.0 --set model.dimensionless.eta=0.0 --set model.dimensionless.mu=0.0"
                " --set model.dimensionless.epsilon=0.0").code, 0);
  EXPECT_EQ(slurp(dir_ / "optimize" / "bare_frf.csv"), slurp(dir_ / "bare" / "frf.csv"));
}

TEST_F(Cli, VerifyPrintsTheTablesAndWritesTheReport) {
  const fs::path report = dir_ / "verification.md";
  const Result r = run("verify --write " + report.string());
  ASSERT_EQ(r.code, 0) << r.output;
  EXPECT_NE(r.output.find("Newmark against the exact integrator"), std::string::npos);
  EXPECT_NE(slurp(report).find("# Verification"), std::string::npos);
}

}  // namespace
