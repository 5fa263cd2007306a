// The study database on bad files and error paths: a file that is not a study is refused as bad
// input naming it, never changed; every refusal and every export closes the connection, so no
// -wal or -shm file is left beside the database.

#include "poundsim/io/study_database.hpp"

#include <sys/wait.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>
#include <string>

#include <SQLiteCpp/Database.h>
#include <gtest/gtest.h>

#include "poundsim/error.hpp"
#include "poundsim/io/study_run.hpp"
#include "../test_models.hpp"

namespace poundsim::io {
namespace {

namespace fs = std::filesystem;

class StudyDatabaseFiles : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("poundsim_database_" + std::string(::testing::UnitTest::GetInstance()->current_test_info()->name()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  [[nodiscard]] std::set<std::string> names() const {
    std::set<std::string> out;
    for (const auto& e : fs::directory_iterator(dir_)) out.insert(e.path().filename().string());
    return out;
  }
  static std::string slurp(const fs::path& p) {
    std::ifstream in(p, std::ios::binary);
    std::stringstream s;
    s << in.rdbuf();
    return s.str();
  }
  /// A finished study database of two points.
  [[nodiscard]] fs::path study(const std::string& fingerprint = "f1") const {
    const fs::path file = dir_ / "study.sqlite";
    StudyDatabase db(file, fingerprint, {{"parameters", {"a"}}});
    db.record(0, {{"a", 1.0}}, "done", "", {{"max_peak_V_W", 0.5}}, 0.1);
    db.record(1, {{"a", 2.0}}, "failed", "no convergence", nlohmann::json::object(), 0.2);
    return file;
  }
  /// The message of the InputError that opening `file` for the study `fingerprint` throws.
  static std::string refusal(const fs::path& file, const std::string& fingerprint = "f1") {
    try {
      StudyDatabase db(file, fingerprint, {{"parameters", {"a"}}});
    } catch (const InputError& e) {
      return e.what();
    }
    return "(accepted)";
  }
  static std::string export_refusal(const fs::path& file) {
    try {
      const StudyDatabase db(file);
    } catch (const InputError& e) {
      return e.what();
    }
    return "(accepted)";
  }
  fs::path dir_;
};

TEST_F(StudyDatabaseFiles, ATextFileIsBadInputAndStaysAsItWas) {
  const fs::path file = dir_ / "study.sqlite";
  std::ofstream(file) << "my notes, not a database\n";
  for (const std::string& message : {refusal(file), export_refusal(file)}) {
    EXPECT_NE(message.find(file.string() + ": not an SQLite database, or a damaged one"), std::string::npos) << message;
  }
  EXPECT_EQ(slurp(file), "my notes, not a database\n");
  EXPECT_EQ(names(), std::set<std::string>{"study.sqlite"});
}

TEST_F(StudyDatabaseFiles, ATruncatedDatabaseIsBadInput) {
  const fs::path file = study();
  const std::string whole = slurp(file);
  ASSERT_GT(whole.size(), 8192u);
  // Cut in the header, in the first page, in the middle, and by its last page.
  for (const std::size_t size : {std::size_t{50}, std::size_t{1000}, whole.size() / 2, whole.size() - 4096}) {
    std::ofstream(file, std::ios::binary | std::ios::trunc) << whole.substr(0, size);
    const std::string message = refusal(file), exported = export_refusal(file);
    EXPECT_EQ(message.rfind(file.string() + ": ", 0), 0u) << size << " bytes: " << message;
    EXPECT_NE(message.find("damaged"), std::string::npos) << size << " bytes: " << message;
    EXPECT_EQ(exported, message) << size << " bytes";
    EXPECT_EQ(slurp(file).size(), size);
    EXPECT_EQ(names(), std::set<std::string>{"study.sqlite"}) << size << " bytes";
  }
}

TEST_F(StudyDatabaseFiles, AnotherProgramsDatabaseIsRefusedUntouched) {
  const fs::path file = dir_ / "study.sqlite";
  {
    SQLite::Database other(file.string(), SQLite::OPEN_READWRITE | SQLite::OPEN_CREATE);
    other.exec("CREATE TABLE accounts (name TEXT, balance REAL); INSERT INTO accounts VALUES ('x', 1.5)");
  }
  const std::string before = slurp(file);
  for (const std::string& message : {refusal(file), export_refusal(file)}) {
    EXPECT_NE(message.find(file.string() + ": not a poundsim study database"), std::string::npos) << message;
  }
  EXPECT_EQ(slurp(file), before);
  EXPECT_EQ(names(), std::set<std::string>{"study.sqlite"});
}

TEST_F(StudyDatabaseFiles, AnotherStudysDatabaseIsRefusedAndClosed) {
  const fs::path file = study("f1");
  const std::string message = refusal(file, "f2");
  EXPECT_NE(message.find(file.string() + ": this database holds the results of a different study"), std::string::npos)
      << message;
  // The refused connection is closed: SQLite removes -wal and -shm when the last one closes.
  EXPECT_EQ(names(), std::set<std::string>{"study.sqlite"});
  EXPECT_EQ(StudyDatabase(file, "f1", {}).rows().size(), 2u);
}

TEST_F(StudyDatabaseFiles, ReadingAndExportingLeaveOnlyTheDatabase) {
  const fs::path file = study();
  {
    const StudyDatabase db(file);
    ASSERT_EQ(db.rows().size(), 2u);
    EXPECT_EQ(db.rows()[1].error, "no convergence");
  }
  EXPECT_EQ(names(), std::set<std::string>{"study.sqlite"});
  export_study(file, dir_ / "points.csv");
  EXPECT_EQ(names(), (std::set<std::string>{"points.csv", "points.csv-metadata.json", "study.sqlite"}));
  // An export that cannot write its file: an error, and still nothing beside the database.
  std::ofstream(dir_ / "plain") << "a file where the folder should be\n";
  EXPECT_THROW(export_study(file, dir_ / "plain" / "points.csv"), std::runtime_error);
  EXPECT_EQ(names(), (std::set<std::string>{"plain", "points.csv", "points.csv-metadata.json", "study.sqlite"}));
  EXPECT_NE(export_refusal(dir_ / "missing.sqlite").find("missing.sqlite: no such study database"), std::string::npos);
  EXPECT_FALSE(fs::exists(dir_ / "missing.sqlite"));
}

TEST_F(StudyDatabaseFiles, AnEmptyFileBecomesANewStudy) {
  // SQLite's own reading of a zero-length file: an empty database, which the study fills.
  const fs::path file = dir_ / "study.sqlite";
  std::ofstream{file};
  const nlohmann::json definition{{"parameters", {"a"}}};
  EXPECT_EQ(StudyDatabase(file, "f1", definition).finished().size(), 0u);
  EXPECT_EQ(StudyDatabase(file, "f1", definition).definition(), definition);
  EXPECT_EQ(names(), std::set<std::string>{"study.sqlite"});
}

struct Cli {
  int code;
  std::string output;
};

Cli cli(const std::string& arguments) {
  std::FILE* pipe = popen((std::string(POUNDSIM_CLI) + " " + arguments + " 2>&1").c_str(), "r");
  std::string output;
  char buffer[4096];
  while (std::fgets(buffer, sizeof buffer, pipe) != nullptr) output += buffer;
  const int status = pclose(pipe);
  return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, output};
}

TEST_F(StudyDatabaseFiles, TheProgramExitsWithCodeTwoOnAGarbageDatabase) {
  const std::string text = testing::model_toml("[1, 1]", testing::fig2('c')) + R"([analysis]
kind = "study"
[frf]
amplitude_g = 0.2
ratios = [0.8]
[study]
each = "frf"
[[study.parameter]]
key = "model.dimensionless.eta"
values = [0.0, 0.25]
)";
  std::ofstream(dir_ / "study.toml") << text;
  fs::create_directories(dir_ / "out");
  std::ofstream(dir_ / "out" / "study.sqlite") << "not a database\n";
  const Cli run = cli("run " + (dir_ / "study.toml").string() + " --out " + (dir_ / "out").string());
  EXPECT_EQ(run.code, 2) << run.output;
  EXPECT_NE(run.output.find((dir_ / "out" / "study.sqlite").string() + ": not an SQLite database, or a damaged one"), std::string::npos)
      << run.output;
  const Cli exported = cli("export " + (dir_ / "out" / "study.sqlite").string() + " --out " + (dir_ / "x.csv").string());
  EXPECT_EQ(exported.code, 2) << exported.output;
  EXPECT_NE(exported.output.find("study.sqlite: not an SQLite database, or a damaged one"), std::string::npos) << exported.output;
  std::set<std::string> left;
  for (const auto& e : fs::directory_iterator(dir_ / "out")) left.insert(e.path().filename().string());
  EXPECT_EQ(left, std::set<std::string>{"study.sqlite"});
  EXPECT_FALSE(fs::exists(dir_ / "x.csv"));
}

}  // namespace
}  // namespace poundsim::io
