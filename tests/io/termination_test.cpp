// SIGTERM and SIGINT to the command-line program in the middle of a run: it ends by the signal
// (a shell reports 143 / 130), leaves no temporary and no partial result, keeps what the folder
// held before, and leaves a study's database whole, closed and resumable.

#include <fcntl.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <csignal>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>

#include "poundsim/io/study_database.hpp"
#include "../test_files.hpp"
#include "../test_models.hpp"

namespace poundsim::io {
namespace {

namespace fs = std::filesystem;
using poundsim::testing::slurp;

fs::path fresh(const std::string& name) { return poundsim::testing::fresh_folder("termination_" + name); }



std::set<std::string> names(const fs::path& dir) {
  std::set<std::string> out;
  for (const auto& e : fs::directory_iterator(dir)) out.insert(e.path().filename().string());
  return out;
}

/// Starts the command-line program with `args` (no shell in between: the pid is the program's),
/// with the signals `ignored` ignored (as nohup does).
pid_t start(const std::vector<std::string>& args, const std::vector<int>& ignored = {}) {
  // argv is built before fork: the child of a threaded process may only exec.
  std::vector<std::string> all{POUNDSIM_CLI};
  all.insert(all.end(), args.begin(), args.end());
  std::vector<char*> argv;
  for (std::string& a : all) argv.push_back(a.data());
  argv.push_back(nullptr);
  const pid_t child = fork();
  if (child == 0) {
    // As a program started in the foreground: a test runner started in the background (by a
    // non-interactive shell) ignores SIGINT, and an ignored signal would be inherited.
    std::signal(SIGINT, SIG_DFL);
    std::signal(SIGTERM, SIG_DFL);
    for (const int s : ignored) std::signal(s, SIG_IGN);
    execv(POUNDSIM_CLI, argv.data());
    _exit(127);
  }
  return child;
}

/// start(), with stderr into `error_file` and files limited to `file_limit` bytes (ulimit -f) when > 0.
pid_t start_limited(const std::vector<std::string>& args, const fs::path& error_file, long file_limit = 0) {
  std::vector<std::string> all{POUNDSIM_CLI};
  all.insert(all.end(), args.begin(), args.end());
  std::vector<char*> argv;
  for (std::string& a : all) argv.push_back(a.data());
  argv.push_back(nullptr);
  const std::string error_path = error_file.string();
  const pid_t child = fork();
  if (child == 0) {
    std::signal(SIGINT, SIG_DFL);
    std::signal(SIGTERM, SIG_DFL);
    std::signal(SIGXFSZ, SIG_DFL);
    const int fd = open(error_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    if (fd >= 0) dup2(fd, STDERR_FILENO);
    if (file_limit > 0) {
      const rlimit limit{static_cast<rlim_t>(file_limit), static_cast<rlim_t>(file_limit)};
      setrlimit(RLIMIT_FSIZE, &limit);
    }
    execv(POUNDSIM_CLI, argv.data());
    _exit(127);
  }
  return child;
}

/// Waits up to `seconds` for the child; kills it (SIGKILL) if it is still running then.
int finish(pid_t child, double seconds) {
  int status = 0;
  const auto until = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
  while (waitpid(child, &status, WNOHANG) == 0) {
    if (std::chrono::steady_clock::now() > until) {
      kill(child, SIGKILL);
      waitpid(child, &status, 0);
      ADD_FAILURE() << "the program did not end within " << seconds << " s of the signal";
      return status;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  return status;
}

/// The size of the temporary of history.csv in `dir`, or -1 when there is none.
long temporary_size(const fs::path& dir) {
  std::error_code ec;
  for (const auto& e : fs::directory_iterator(dir, ec)) {
    const std::string name = e.path().filename().string();
    if (name.starts_with(".history.csv.") && name.ends_with(".tmp")) {
      const auto size = fs::file_size(e.path(), ec);
      return ec ? 0 : static_cast<long>(size);
    }
  }
  return -1;
}

class Termination : public ::testing::TestWithParam<int> {};

TEST_P(Termination, ATimeHistoryLeavesNoTemporaryAndKeepsThePreviousResults) {
  const int sig = GetParam();
  const fs::path dir = fresh(fmt::format("time_history_{}", sig));
  const fs::path out = dir / "out";
  fs::create_directories(out);
  std::ofstream(out / "history.csv") << "previous\n";  // the results of an earlier run
  // Every step written (output_dt = dt): the history's temporary passes a megabyte within a second.
  const pid_t child = start({"run", std::string(POUNDSIM_SOURCE_DIR) + "/examples/fig2c_ratio0.8.toml", "--quiet",
                             "--out", out.string(), "--set", "analysis.duration=2000", "--set",
                             "analysis.output_dt=0.001"});
  ASSERT_GT(child, 0);
  bool writing = false;
  for (int i = 0; i < 6000 && !writing; ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
    writing = temporary_size(out) > 0;
  }
  EXPECT_TRUE(writing) << "the run wrote nothing into a temporary within 30 s";
  kill(child, sig);
  const int status = finish(child, 20);
  ASSERT_TRUE(WIFSIGNALED(status)) << "status " << status;
  EXPECT_EQ(WTERMSIG(status), sig);
  EXPECT_EQ(names(out), std::set<std::string>{"history.csv"});
  EXPECT_EQ(slurp(out / "history.csv"), "previous\n");
  fs::remove_all(dir);
}

TEST(Termination, ASignalIgnoredAtTheStartStaysIgnored) {
  // `nohup poundsim run …`: the hang-up of the terminal must not stop the run.
  const fs::path dir = fresh("nohup");
  const pid_t child = start({"run", std::string(POUNDSIM_SOURCE_DIR) + "/examples/fig2c_ratio0.8.toml", "--quiet",
                             "--out", dir.string(), "--set", "analysis.duration=2000", "--set",
                             "analysis.output_dt=0.001"},
                            {SIGHUP});
  ASSERT_GT(child, 0);
  for (int i = 0; i < 6000 && temporary_size(dir) <= 0; ++i) std::this_thread::sleep_for(std::chrono::milliseconds(5));
  kill(child, SIGHUP);
  std::this_thread::sleep_for(std::chrono::milliseconds(200));
  kill(child, SIGTERM);
  const int status = finish(child, 20);
  ASSERT_TRUE(WIFSIGNALED(status)) << "status " << status;
  EXPECT_EQ(WTERMSIG(status), SIGTERM);
  EXPECT_TRUE(names(dir).empty());
  fs::remove_all(dir);
}

const std::string kStudy = testing::model_toml("[1, 1]", testing::fig2('c')) + R"([analysis]
kind = "study"
[frf]
amplitude_g = 0.2
ratio_min = 0.4
ratio_max = 1.2
points = 41
steps_per_period = 256
[study]
each = "frf"
threads = 2
[[study.parameter]]
key = "model.dimensionless.eta"
values = [0.0, 0.125, 0.25]
[[study.parameter]]
key = "model.dimensionless.mu"
min = 0.5
max = 2.0
points = 3
)";

TEST_P(Termination, AStudyClosesItsDatabaseAndResumes) {
  const int sig = GetParam();
  const fs::path dir = fresh(fmt::format("study_{}", sig));
  std::ofstream(dir / "study.toml") << kStudy;
  const std::vector<std::string> args{"run", (dir / "study.toml").string(), "--quiet", "--out", (dir / "out").string()};
  const pid_t child = start(args);
  ASSERT_GT(child, 0);
  // Two worker threads run points: the signal must be taken whichever thread it reaches.
  long seen = 0;
  for (int i = 0; i < 6000 && seen < 2; ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
    if (!fs::exists(dir / "out" / "study.sqlite")) continue;
    try {
      seen = static_cast<long>(StudyDatabase(dir / "out" / "study.sqlite").rows().size());
    } catch (const std::exception&) {
    }
  }
  kill(child, sig);
  const int status = finish(child, 20);
  ASSERT_TRUE(WIFSIGNALED(status)) << "status " << status;
  EXPECT_EQ(WTERMSIG(status), sig);
  // The database alone: closed (no -wal or -shm), no temporary, no summary or table of a part.
  EXPECT_EQ(names(dir / "out"), std::set<std::string>{"study.sqlite"});
  const long before = static_cast<long>(StudyDatabase(dir / "out" / "study.sqlite").rows().size());
  EXPECT_GE(before, 2);
  EXPECT_LT(before, 9) << "the study finished before the signal; make it slower";
  // Run again: the rest is computed, and the study completes.
  const int again = finish(start(args), 600);
  ASSERT_TRUE(WIFEXITED(again) && WEXITSTATUS(again) == 0) << "status " << again;
  const auto rows = StudyDatabase(dir / "out" / "study.sqlite").rows();
  ASSERT_EQ(rows.size(), 9u);
  for (std::size_t i = 0; i < rows.size(); ++i) EXPECT_EQ(rows[i].id, static_cast<long>(i));
  EXPECT_EQ(names(dir / "out"), (std::set<std::string>{"input.toml", "study.csv", "study.csv-metadata.json", "study.sqlite", "summary.json"}));
  fs::remove_all(dir);
}

TEST(Termination, ASecondRunIntoTheSameFolderIsRefusedNamingTheFirst) {
  // Two runs into one folder at once: the second lost a race for the database with a raw SQLite
  // error before. It is refused before it computes anything, naming the folder and the process.
  const fs::path dir = fresh("two_writers");
  std::ofstream(dir / "study.toml") << kStudy;
  const fs::path out = dir / "out";
  const pid_t first = start({"run", (dir / "study.toml").string(), "--quiet", "--out", out.string()});
  ASSERT_GT(first, 0);
  for (int i = 0; i < 6000 && !fs::exists(out / "study.sqlite"); ++i) std::this_thread::sleep_for(std::chrono::milliseconds(5));
  ASSERT_TRUE(fs::exists(out / "study.sqlite"));
  const std::string tiny = std::string(POUNDSIM_SOURCE_DIR) + "/tests/repro/tiny_study.toml";
  for (const std::string& input : {tiny, (dir / "study.toml").string()}) {
    const int second = finish(start_limited({"run", input, "--quiet", "--out", out.string()}, dir / "second.txt"), 60);
    ASSERT_TRUE(WIFEXITED(second)) << "status " << second;
    EXPECT_EQ(WEXITSTATUS(second), 2);
    const std::string error = slurp(dir / "second.txt");
    EXPECT_NE(error.find(out.string() + ": another run is writing into this output folder (poundsim process " +
                         std::to_string(first) + ")"),
              std::string::npos)
        << error;
    EXPECT_EQ(error.find("SQLite"), std::string::npos) << error;
  }
  kill(first, SIGTERM);
  finish(first, 20);
  // Once the first has ended the folder is free again: the run resumes and completes.
  const int again = finish(start({"run", (dir / "study.toml").string(), "--quiet", "--out", out.string()}), 600);
  EXPECT_TRUE(WIFEXITED(again) && WEXITSTATUS(again) == 0) << "status " << again;
  fs::remove_all(dir);
}

TEST(Termination, AFileSizeLimitEndsTheRunWithAnErrorAndLeavesNoTemporary) {
  // `ulimit -f`: a write beyond the limit raised SIGXFSZ, whose default action ended the process
  // with its temporaries left behind. The write now fails, and the run ends as on a full disk.
  const fs::path dir = fresh("file_size");
  const fs::path out = dir / "out";
  const int status = finish(start_limited({"run", std::string(POUNDSIM_SOURCE_DIR) + "/examples/fig2c_ratio0.8.toml",
                                           "--quiet", "--out", out.string(), "--set", "analysis.duration=200",
                                           "--set", "analysis.output_dt=0.001"},
                                          dir / "error.txt", 1 << 20),
                            120);
  ASSERT_TRUE(WIFEXITED(status)) << "status " << status;
  EXPECT_EQ(WEXITSTATUS(status), 1);
  const std::string error = slurp(dir / "error.txt");
  EXPECT_NE(error.find("write failed: File too large"), std::string::npos) << error;
  EXPECT_FALSE(fs::exists(out) && !names(out).empty()) << "left behind in " << out;
  fs::remove_all(dir);
}

INSTANTIATE_TEST_SUITE_P(Signals, Termination, ::testing::Values(SIGTERM, SIGINT),
                         [](const ::testing::TestParamInfo<int>& param) {
                           return std::string(param.param == SIGTERM ? "SIGTERM" : "SIGINT");
                         });

}  // namespace
}  // namespace poundsim::io
