// The malformed-input suite: the command-line program run on every tests/malformed/*.toml.
//
// Each case is a model file whose first comment lines say what must happen:
//
//   # expect: <text>      a substring that must appear in stderr (one or more lines)
//   # expect-not: <text>  a substring that must not appear in stderr
//   # args: <arguments>   more arguments for `poundsim run` (e.g. --set key=value); split at blanks,
//                         'single quotes' group, and \n, \r, \t, \\, \xHH are escapes
//
// and every case must: exit with code 2, print every expected substring and none of the others,
// name the case file (or, for a case reading a record under records/, the record file) in stderr,
// and leave no file in the output folder. A case that hangs is killed after 60 s and fails.
// Set POUNDSIM_MALFORMED_CLI to run the suite against another build of the program.

#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>

#include "../test_files.hpp"

extern char** environ;

namespace {

namespace fs = std::filesystem;
using poundsim::testing::slurp;

const fs::path kCases = fs::path(POUNDSIM_SOURCE_DIR) / "tests" / "malformed";

struct Case {
  fs::path file;
  std::vector<std::string> expect, expect_not, args;
  std::string record;  ///< File name of a record under records/ that the case reads, if any.
};

/// Splits an `# args:` line: blanks separate, single quotes group, backslash escapes.
std::vector<std::string> split_arguments(const std::string& line) {
  std::vector<std::string> out;
  std::string current;
  bool quoted = false, started = false;
  for (std::size_t i = 0; i < line.size(); ++i) {
    const char c = line[i];
    if (c == '\'') {
      quoted = !quoted;
      started = true;
    } else if (c == '\\' && i + 1 < line.size()) {
      const char e = line[++i];
      if (e == 'n') current += '\n';
      else if (e == 'r') current += '\r';
      else if (e == 't') current += '\t';
      else if (e == 'x' && i + 2 < line.size()) {
        current += static_cast<char>(std::stoi(line.substr(i + 1, 2), nullptr, 16));
        i += 2;
      } else current += e;
      started = true;
    } else if ((c == ' ' || c == '\t') && !quoted) {
      if (started) out.push_back(current);
      current.clear();
      started = false;
    } else {
      current += c;
      started = true;
    }
  }
  if (started) out.push_back(current);
  return out;
}

Case read_case(const fs::path& file) {
  Case c{file, {}, {}, {}, {}};
  std::ifstream in(file);
  static const std::regex record(R"(^\s*file\s*=\s*"records/([^"]+)\")");
  for (std::string line; std::getline(in, line);) {
    const auto value = [&](const std::string& tag) { return line.substr(tag.size()); };
    if (line.rfind("# expect: ", 0) == 0) c.expect.push_back(value("# expect: "));
    if (line.rfind("# expect-not: ", 0) == 0) c.expect_not.push_back(value("# expect-not: "));
    if (line.rfind("# args: ", 0) == 0) {
      for (std::string& a : split_arguments(value("# args: "))) c.args.push_back(std::move(a));
    }
    std::smatch m;
    if (std::regex_search(line, m, record)) c.record = m[1];
  }
  return c;
}

std::vector<fs::path> case_files() {
  std::vector<fs::path> files;
  for (const auto& entry : fs::directory_iterator(kCases)) {
    if (entry.path().extension() == ".toml") files.push_back(entry.path());
  }
  std::sort(files.begin(), files.end());
  return files;
}


struct Outcome {
  int code = -1;  ///< Exit code; -1 when killed or crashed.
  std::string error;
  bool timed_out = false;
};

/// Runs `arguments` (argv[0] included) without a shell, stderr into `error_file`.
Outcome run(const std::vector<std::string>& arguments, const fs::path& error_file) {
  std::vector<char*> argv;
  for (const std::string& a : arguments) argv.push_back(const_cast<char*>(a.c_str()));
  argv.push_back(nullptr);
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, STDIN_FILENO, "/dev/null", O_RDONLY, 0);
  posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, "/dev/null", O_WRONLY, 0);
  posix_spawn_file_actions_addopen(&actions, STDERR_FILENO, error_file.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  pid_t pid = 0;
  const int spawned = posix_spawn(&pid, argv[0], &actions, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  Outcome o;
  if (spawned != 0) {
    o.error = "cannot start " + arguments[0];
    return o;
  }
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
  int status = 0;
  while (waitpid(pid, &status, WNOHANG) == 0) {
    if (std::chrono::steady_clock::now() > deadline) {
      kill(pid, SIGKILL);
      waitpid(pid, &status, 0);
      o.timed_out = true;
      break;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  o.code = !o.timed_out && WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  o.error = slurp(error_file);
  return o;
}

std::string cli() {
  const char* other = std::getenv("POUNDSIM_MALFORMED_CLI");
  return other != nullptr && *other != '\0' ? other : POUNDSIM_CLI;
}

class MalformedInput : public ::testing::TestWithParam<fs::path> {};

TEST_P(MalformedInput, ExitsWithCodeTwoNamingTheFileAndLeavesNothing) {
  const Case c = read_case(GetParam());
  ASSERT_FALSE(c.expect.empty()) << c.file << ": a case needs at least one '# expect:' line";
  const fs::path dir = fs::temp_directory_path() / ("poundsim_malformed_" + c.file.stem().string() + "_" +
                                                    std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  const fs::path out = dir / "out";
  std::vector<std::string> arguments{cli(), "run", c.file.string(), "--out", out.string()};
  arguments.insert(arguments.end(), c.args.begin(), c.args.end());
  const Outcome o = run(arguments, dir / "stderr.txt");

  EXPECT_FALSE(o.timed_out) << c.file.filename() << ": still running after 60 s";
  EXPECT_EQ(o.code, 2) << c.file.filename() << "\n" << o.error;
  for (const std::string& text : c.expect) {
    EXPECT_NE(o.error.find(text), std::string::npos) << "expected \"" << text << "\" in:\n" << o.error;
  }
  for (const std::string& text : c.expect_not) {
    EXPECT_EQ(o.error.find(text), std::string::npos) << "did not expect \"" << text << "\" in:\n" << o.error;
  }
  const bool names_case = o.error.find(c.file.filename().string()) != std::string::npos;
  const bool names_record = !c.record.empty() && o.error.find(fs::path(c.record).filename().string()) != std::string::npos;
  EXPECT_TRUE(names_case || names_record) << "the message names neither the case nor its record:\n" << o.error;
  if (fs::exists(out)) {
    for (const auto& entry : fs::recursive_directory_iterator(out)) {
      ADD_FAILURE() << "left behind: " << entry.path();
    }
  }
  fs::remove_all(dir);
}

INSTANTIATE_TEST_SUITE_P(Cases, MalformedInput, ::testing::ValuesIn(case_files()),
                         [](const ::testing::TestParamInfo<fs::path>& p) {
                           std::string name = p.param.stem().string();
                           for (char& ch : name) {
                             if (!std::isalnum(static_cast<unsigned char>(ch))) ch = '_';
                           }
                           return name;
                         });

TEST(MalformedSuite, HasTheCasesItPromises) {
  // ≥ 45 TOML and --set cases of the input reader, besides the record cases.
  std::size_t input_cases = 0;
  for (const fs::path& f : case_files()) input_cases += f.stem().string().rfind("record_", 0) != 0;
  EXPECT_GE(input_cases, 45u);
}

}  // namespace
