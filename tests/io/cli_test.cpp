// The command-line program end to end: exit codes, messages, files written whole or not at all.

#include <sys/wait.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

namespace {

namespace fs = std::filesystem;

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

std::string slurp(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

class Cli : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("poundsim_cli_" + std::string(::testing::UnitTest::GetInstance()->current_test_info()->name()));
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
  EXPECT_EQ(header, "t,u_1_1,u_2_1,v_1_1,v_2_1,a_1_1,a_2_1,V_1,V_2,F_1_1,E_input,E_kinetic,E_storey_strain,"
                    "E_gap_strain,E_storey_damping,E_gap_damping,E_impact,E_residual");
  int rows = 0;
  for (std::string line; std::getline(history, line);) ++rows;
  EXPECT_EQ(rows, 2001);  // t = 0, 0.01, ..., 20
  const auto summary = nlohmann::json::parse(slurp(out / "summary.json"));
  EXPECT_EQ(summary["counts"]["steps"], 20000);
  EXPECT_GT(summary["impacts"].get<int>(), 0);
  EXPECT_LT(summary["energy"]["max_relative_residual"].get<double>(), 1e-11);
  EXPECT_NEAR(summary["excitation"]["ratio"].get<double>(), 0.8, 1e-15);
  const std::string events = slurp(out / "events.csv");
  EXPECT_EQ(events.rfind("t,frame_left,frame_right,floor,kind,relative_velocity_before,"
                         "relative_velocity_after,impulse\n", 0), 0u);
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
  EXPECT_NE(r.output.find("extra: unknown key"), std::string::npos) << r.output;
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

TEST_F(Cli, UnwritableOutputFailsWithCodeOne) {
  const fs::path blocker = write("occupied", "a file where the folder should be");
  const Result r = run("run " + example("fig2c_ratio0.8.toml") + " --out " + (blocker / "sub").string());
  EXPECT_EQ(r.code, 1);
  EXPECT_NE(r.output.find("cannot create the output folder"), std::string::npos) << r.output;
}

TEST_F(Cli, EveryExampleRunsWithBothIntegrators) {
  // Time histories and frequency responses with both integrators; studies and the optimiser
  // (whose points are frequency responses) with Newmark and a smaller budget.
  std::vector<fs::path> examples;
  for (const auto& dir : {"/examples", "/examples/paper"}) {
    for (const auto& entry : fs::directory_iterator(std::string(POUNDSIM_SOURCE_DIR) + dir)) {
      if (entry.path().extension() == ".toml") examples.push_back(entry.path());
    }
  }
  EXPECT_GE(examples.size(), 13u);
  for (const fs::path& example : examples) {
    const std::string text = slurp(example);
    const bool frf = text.find("kind = \"frf\"") != std::string::npos;
    const bool study = text.find("kind = \"study\"") != std::string::npos;
    const bool optimize = text.find("kind = \"optimize\"") != std::string::npos;
    const bool ensemble = text.find("kind = \"ensemble\"") != std::string::npos;
    for (const char* integrator : {"newmark", "exact"}) {
      if ((study || optimize) && std::string(integrator) == "exact") continue;
      const fs::path out = dir_ / (example.stem().string() + "_" + integrator);
      std::string extra = std::string(" --set analysis.integrator=") + integrator;
      if (frf && std::string(integrator) == "exact") extra += " --set frf.points=12 --set frf.steps_per_period=16";
      if (optimize) extra += " --set optimize.global_evaluations=6 --set optimize.local_evaluations=4";
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
        EXPECT_LT(summary["energy"]["max_relative_residual"].get<double>(), 1e-9) << example;
      }
    }
  }
}

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

TEST_F(Cli, VerifyPrintsTheTablesAndWritesTheReport) {
  const fs::path report = dir_ / "verification.md";
  const Result r = run("verify --write " + report.string());
  ASSERT_EQ(r.code, 0) << r.output;
  EXPECT_NE(r.output.find("Newmark against the exact integrator"), std::string::npos);
  EXPECT_NE(slurp(report).find("# Verification"), std::string::npos);
}

}  // namespace
