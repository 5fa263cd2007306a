#include "poundsim/io/output_files.hpp"

#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include <unistd.h>

#include <fmt/format.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "../test_files.hpp"

namespace poundsim::io {
namespace {

namespace fs = std::filesystem;

std::size_t entries(const fs::path& dir) {
  return static_cast<std::size_t>(std::distance(fs::directory_iterator(dir), fs::directory_iterator{}));
}

TEST(OutputTransaction, FilesAppearOnlyOnCommit) {
  const fs::path dir = fs::temp_directory_path() / "poundsim_output_commit";
  fs::remove_all(dir);
  {
    OutputTransaction out(dir);
    out.open("a.csv").print("x,{}\n", 1.5);
    out.open("b.json").text("{}\n");
    EXPECT_FALSE(fs::exists(dir / "a.csv"));
    out.commit();
  }
  std::ifstream in(dir / "a.csv");
  std::stringstream s;
  s << in.rdbuf();
  EXPECT_EQ(s.str(), "x,1.5\n");
  EXPECT_EQ(entries(dir), 2u);
  fs::remove_all(dir);
}

TEST(OutputTransaction, AbandonedRunLeavesNothing) {
  const fs::path dir = fs::temp_directory_path() / "poundsim_output_abandon";
  fs::remove_all(dir);
  fs::create_directories(dir);
  std::ofstream(dir / "a.csv") << "previous\n";
  try {
    OutputTransaction out(dir);
    OutputFile& f = out.open("a.csv");
    for (int i = 0; i < 100000; ++i) f.print("{},{}\n", i, 0.1 * i);  // flushes to the temporary
    throw std::runtime_error("the simulation failed");
  } catch (const std::runtime_error&) {
  }
  std::ifstream in(dir / "a.csv");
  std::stringstream s;
  s << in.rdbuf();
  EXPECT_EQ(s.str(), "previous\n");
  EXPECT_EQ(entries(dir), 1u);  // no temporary left
  fs::remove_all(dir);
}

TEST(OutputTransaction, RemovesTheTemporariesOfProcessesNoLongerRunning) {
  // A run that crashed left its hidden temporaries; the next run into the folder removes them,
  // but never those of a process still running (pid 1) or its own.
  const fs::path dir = poundsim::testing::fresh_folder("stale_temporaries");
  const std::string own = fmt::format(".events.csv.{}.tmp", static_cast<long>(::getpid()));
  for (const std::string name : {".history.csv.999999999.tmp", ".summary.json.999999998.tmp", ".x.1.tmp", own.c_str(),
                                 "history.csv", ".hidden.tmp", ".a.12x.tmp"}) {
    std::ofstream(dir / name) << "x";
  }
  {
    OutputTransaction out(dir);
    out.commit();
  }
  std::set<std::string> left;
  for (const auto& e : fs::directory_iterator(dir)) left.insert(e.path().filename().string());
  EXPECT_EQ(left, (std::set<std::string>{".x.1.tmp", own, "history.csv", ".hidden.tmp", ".a.12x.tmp"}));
  fs::remove_all(dir);
}

TEST(OutputFolderLock, ATransactionOfTheSameProcessSharesItsLock) {
  // A run holds its folder and opens transactions in it; another process could not take it.
  const fs::path dir = poundsim::testing::fresh_folder("folder_lock") / "new";
  {
    const OutputFolderLock held(dir);
    EXPECT_TRUE(fs::is_directory(dir));
    OutputTransaction out(dir);
    out.open("a.txt").text("a");
    out.commit();
  }
  EXPECT_TRUE(fs::exists(dir / "a.txt"));
  // A folder the lock created and nothing was written into is removed again.
  const fs::path empty = dir.parent_path() / "empty";
  { const OutputFolderLock held(empty); }
  EXPECT_FALSE(fs::exists(empty));
  fs::remove_all(dir.parent_path());
}

TEST(OutputTransaction, WritesJsonIndentedWithAFinalNewline) {
  const fs::path dir = fs::temp_directory_path() / "poundsim_output_json";
  fs::remove_all(dir);
  {
    OutputTransaction out(dir);
    out.write_json("s.json", nlohmann::json{{"peak", 0.1}, {"frames", {1, 2}}});
    EXPECT_FALSE(fs::exists(dir / "s.json"));
    out.commit();
  }
  std::ifstream in(dir / "s.json");
  std::stringstream s;
  s << in.rdbuf();
  EXPECT_EQ(s.str(), "{\n  \"frames\": [\n    1,\n    2\n  ],\n  \"peak\": 0.1\n}\n");
  EXPECT_EQ(nlohmann::json::parse(s.str())["peak"].get<double>(), 0.1);
  fs::remove_all(dir);
}

TEST(OutputFile, NumbersReadBackExactly) {
  const fs::path dir = fs::temp_directory_path() / "poundsim_output_numbers";
  fs::remove_all(dir);
  const double values[] = {0.1, 1.0 / 3.0, -2.5e-300, 6.02214076e23, 0.0};
  {
    OutputTransaction out(dir);
    OutputFile& f = out.open("n.txt");
    for (const double v : values) {
      f.number(v);
      f.character('\n');
    }
    out.commit();
  }
  std::ifstream in(dir / "n.txt");
  for (const double v : values) {
    std::string line;
    std::getline(in, line);
    EXPECT_EQ(std::stod(line), v) << line;
  }
  fs::remove_all(dir);
}

TEST(OutputFile, NumbersAreWhatFormatWritesByteForByte) {
  // number() formats with a compiled "{}": it must write exactly what fmt::format("{}", x) does
  // (the golden outputs' checksums were taken with the latter) — integers, exponents both ways,
  // −0, subnormals, and a spread of random bit patterns.
  const fs::path dir = fs::temp_directory_path() / "poundsim_output_numbers_format";
  fs::remove_all(dir);
  std::vector<double> values{0.0, -0.0, 1.0, -3.0, 1e15, 1e16, 1e17, 123456789012.0, 1e-4, 1e-5, 0.1,
                             5e-324, -2.2250738585072014e-308, 1.7976931348623157e308, 9.87654321e-7};
  std::uint64_t bits = 0x9E3779B97F4A7C15ULL;
  while (values.size() < 2000) {
    bits ^= bits << 13;
    bits ^= bits >> 7;
    bits ^= bits << 17;
    double x = 0.0;
    std::memcpy(&x, &bits, sizeof x);
    if (std::isfinite(x)) values.push_back(x);
  }
  std::string expected;
  {
    OutputTransaction out(dir);
    OutputFile& f = out.open("n.txt");
    for (const double v : values) {
      f.number(v);
      f.character('\n');
      expected += fmt::format("{}\n", v);
    }
    out.commit();
  }
  std::ifstream in(dir / "n.txt", std::ios::binary);
  const std::string written((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  EXPECT_EQ(written, expected);
  fs::remove_all(dir);
}

// Every CSV goes through CsvWriter (RFC 4180): commas between fields, a line feed after each row,
// text quoted only when it must be (a comma, a double quote — doubled — or a line break).
TEST(CsvWriter, WritesRfc4180Rows) {
  const fs::path dir = fs::temp_directory_path() / "poundsim_output_csv";
  fs::remove_all(dir);
  {
    OutputTransaction out(dir);
    CsvWriter csv(out.open("t.csv"));
    csv.texts({"id", "name", "x", "note"}).end_row();
    csv.integer(-7).text("frame \"A\", left").number(0.1).empty().end_row();
    csv.integer(8).text("two\nlines").number(-2.5e-300).text("plain").end_row();
    out.commit();
  }
  std::ifstream in(dir / "t.csv");
  std::stringstream text;
  text << in.rdbuf();
  EXPECT_EQ(text.str(), "id,name,x,note\n-7,\"frame \"\"A\"\", left\",0.1,\n8,\"two\nlines\",-2.5e-300,plain\n");
  fs::remove_all(dir);
}

}  // namespace
}  // namespace poundsim::io
