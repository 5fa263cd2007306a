// The plotting scripts under whichever python3 starts them: the first python3 on the PATH (here a
// pyenv interpreter without Matplotlib), Debian's with its site packages hidden (-S), and one
// that has no Matplotlib anywhere to turn to, which must stop with exit code 2 and say what to
// install.

#include <sys/wait.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include <fmt/format.h>
#include <gtest/gtest.h>

namespace {

namespace fs = std::filesystem;

struct Result {
  int code;
  std::string output;
};

Result shell(const std::string& command) {
  std::FILE* pipe = popen((command + " 2>&1").c_str(), "r");
  std::string output;
  char buffer[4096];
  while (std::fgets(buffer, sizeof buffer, pipe) != nullptr) output += buffer;
  const int status = pclose(pipe);
  return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, output};
}

bool is_png(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::string head(8, '\0');
  in.read(head.data(), 8);
  return in && head == "\x89PNG\r\n\x1a\n";
}

class PlotScripts : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("poundsim_python_" + std::string(::testing::UnitTest::GetInstance()->current_test_info()->name()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
    // A tiny result folder: half a second of the Fig. 2c time history.
    const Result run = shell(fmt::format("{} run {}/examples/fig2c_ratio0.8.toml --quiet --out {} --set "
                                         "analysis.duration=0.5",
                                         POUNDSIM_CLI, POUNDSIM_SOURCE_DIR, (dir_ / "th").string()));
    ASSERT_EQ(run.code, 0) << run.output;
  }
  void TearDown() override { fs::remove_all(dir_); }

  /// Runs plot_time_history.py on the folder with `python` (an interpreter and its options).
  [[nodiscard]] Result plot(const std::string& python, const std::string& environment = "") const {
    return shell(fmt::format("{} {} {}/python/plot_time_history.py {}", environment, python, POUNDSIM_SOURCE_DIR,
                             (dir_ / "th").string()));
  }
  [[nodiscard]] bool drew() const {
    return is_png(dir_ / "th" / "response.png") && is_png(dir_ / "th" / "energy.png") &&
           is_png(dir_ / "th" / "profiles.png");
  }
  fs::path dir_;
};

TEST_F(PlotScripts, RunUnderTheFirstPython3OnThePath) {
  if (shell("command -v python3").code != 0) GTEST_SKIP() << "no python3 on the PATH";
  const Result r = plot("python3");
  EXPECT_EQ(r.code, 0) << shell("command -v python3").output << r.output;
  EXPECT_TRUE(drew()) << r.output;
}

TEST_F(PlotScripts, AnInterpreterWithoutMatplotlibHandsOverToDebians) {
  if (shell("/usr/bin/python3 -c 'import matplotlib'").code != 0) {
    GTEST_SKIP() << "/usr/bin/python3 has no Matplotlib (scripts/install-deps.sh installs python3-matplotlib)";
  }
  // -S hides the site packages, Matplotlib among them.
  ASSERT_NE(shell("/usr/bin/python3 -S -c 'import matplotlib'").code, 0);
  const Result r = plot("/usr/bin/python3 -S");
  EXPECT_EQ(r.code, 0) << r.output;
  EXPECT_TRUE(drew()) << r.output;
}

TEST_F(PlotScripts, WithoutMatplotlibAnywhereTheyExitWithCodeTwoAndSayWhatToInstall) {
  // Already handed over once (the variable says so): no interpreter is left to try.
  const Result r = plot("/usr/bin/python3 -S", "POUNDSIM_PLOT_REEXECUTED=/usr/bin/python3");
  EXPECT_EQ(r.code, 2) << r.output;
  EXPECT_NE(r.output.find("plot_time_history.py: error: needs the Python package matplotlib"), std::string::npos)
      << r.output;
  EXPECT_NE(r.output.find("python3-matplotlib"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("python/requirements.txt"), std::string::npos) << r.output;
  EXPECT_EQ(r.output.find("Traceback"), std::string::npos) << r.output;
  EXPECT_FALSE(fs::exists(dir_ / "th" / "response.png"));
}

// The contact-law comparison (python/compare_contact_laws.py) on two of examples/contact_laws/,
// shortened: its table and its bars; a folder that is not a result is refused with exit code 2.
TEST(CompareContactLaws, TabulatesAndDrawsTheLaws) {
  if (shell("/usr/bin/python3 -c 'import matplotlib'").code != 0) GTEST_SKIP() << "no Matplotlib";
  const fs::path dir = fs::temp_directory_path() / "poundsim_compare_contact_laws";
  fs::remove_all(dir);
  for (const char* law : {"paper", "hertzdamp"}) {
    const Result run = shell(fmt::format("{} run {}/examples/contact_laws/{}.toml --quiet --out {} --set analysis.duration=1",
                                         POUNDSIM_CLI, POUNDSIM_SOURCE_DIR, law, (dir / law).string()));
    ASSERT_EQ(run.code, 0) << run.output;
  }
  const Result r = shell(fmt::format("/usr/bin/python3 {}/python/compare_contact_laws.py {} {} --out {}", POUNDSIM_SOURCE_DIR,
                                     (dir / "paper").string(), (dir / "hertzdamp").string(), (dir / "laws.png").string()));
  EXPECT_EQ(r.code, 0) << r.output;
  EXPECT_NE(r.output.find("| paper | "), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("| hertzdamp | "), std::string::npos) << r.output;
  EXPECT_TRUE(is_png(dir / "laws.png")) << r.output;
  const Result bad = shell(fmt::format("/usr/bin/python3 {}/python/compare_contact_laws.py {} --out {}", POUNDSIM_SOURCE_DIR,
                                       dir.string(), (dir / "no.png").string()));
  EXPECT_EQ(bad.code, 2) << bad.output;
  EXPECT_NE(bad.output.find("summary.json: no such file"), std::string::npos) << bad.output;
  EXPECT_FALSE(fs::exists(dir / "no.png"));
  fs::remove_all(dir);
}

}  // namespace
