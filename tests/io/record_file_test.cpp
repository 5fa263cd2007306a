#include "poundsim/io/record_file.hpp"

#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>

#include "poundsim/error.hpp"

namespace poundsim::io {
namespace {

class RecordFile : public ::testing::Test {
 protected:
  std::filesystem::path write(const std::string& text) {
    const auto path = std::filesystem::temp_directory_path() /
                      ("poundsim_record_" + std::to_string(counter_++) + ".txt");
    std::ofstream(path) << text;
    files_.push_back(path);
    return path;
  }
  std::string error_of(const std::string& text) {
    try {
      read_two_column_record(write(text), 1.0);
    } catch (const InputError& e) {
      return e.what();
    }
    return "(no error)";
  }
  void TearDown() override {
    for (const auto& f : files_) std::filesystem::remove(f);
  }

 private:
  int counter_ = 0;
  std::vector<std::filesystem::path> files_;
};

TEST_F(RecordFile, ReadsBlankAndCommaSeparatedColumns) {
  const RecordExcitation r = read_two_column_record(write("# header\n\n0 1e-2\n0.5,\t-2.5E-1\n1.0 +3\n"), 9.81);
  ASSERT_EQ(r.time.size(), 3u);
  EXPECT_DOUBLE_EQ(r.time[1], 0.5);
  EXPECT_DOUBLE_EQ(r.acceleration[1], -0.25 * 9.81);
  EXPECT_DOUBLE_EQ(r.acceleration[2], 3 * 9.81);
}

TEST_F(RecordFile, ErrorsNameTheLine) {
  EXPECT_NE(error_of("0 0\n0.1 abc\n").find(":2: expected two numbers"), std::string::npos);
  EXPECT_NE(error_of("0 0\n0.1 0.2 0.3\n").find(":2: unexpected text"), std::string::npos);
  EXPECT_NE(error_of("0 0\n0.1 nan\n").find(":2: time and acceleration must be finite"),
            std::string::npos);
  EXPECT_NE(error_of("0 0\n0.2 1\n0.1 2\n").find(":3: time 0.1 s does not increase"), std::string::npos);
  EXPECT_NE(error_of("-1 0\n0.1 1\n").find(":1: the first time -1 s is negative"), std::string::npos);
  EXPECT_NE(error_of("# only a header\n0 1\n").find("at least two samples"), std::string::npos);
  try {
    read_two_column_record("/no/such/file.txt", 1.0);
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("/no/such/file.txt: cannot open"), std::string::npos);
  }
}

}  // namespace
}  // namespace poundsim::io
