// Readers of ground-motion records: the real files in data/ground_motions (values from its
// SOURCES.md), every header spelling, and every kind of malformed file.

#include "poundsim/io/ground_motion.hpp"

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include <gtest/gtest.h>

#include "poundsim/error.hpp"

namespace poundsim::io {
namespace {

namespace fs = std::filesystem;

const fs::path kRecords = fs::path(POUNDSIM_SOURCE_DIR) / "data" / "ground_motions";

double peak_time(const GroundMotionRecord& r) {
  std::size_t k = 0;
  for (std::size_t i = 0; i < r.excitation.acceleration.size(); ++i) {
    if (std::abs(r.excitation.acceleration[i]) > std::abs(r.excitation.acceleration[k])) k = i;
  }
  return r.excitation.time[k];
}

struct Reference {
  const char* file;
  const char* format;
  int points;
  double dt, pga_g, at;
};

class RealRecords : public ::testing::TestWithParam<Reference> {};

TEST_P(RealRecords, MatchTheirVerifiedValues) {
  const Reference& ref = GetParam();
  const GroundMotionRecord r = read_ground_motion(kRecords / ref.file, RecordOptions{});
  EXPECT_EQ(r.format, ref.format);
  EXPECT_EQ(r.points, ref.points);
  EXPECT_EQ(r.excitation.time.size(), static_cast<std::size_t>(ref.points));
  EXPECT_NEAR(r.dt, ref.dt, 1e-12);
  EXPECT_NEAR(r.pga_g, ref.pga_g, 5e-5);
  EXPECT_NEAR(peak_time(r), ref.at, 0.006);
  EXPECT_NEAR(r.duration, (ref.points - 1) * ref.dt, 1e-9);
  EXPECT_EQ(r.file_units, std::string(ref.format) == "cosmos" ? "cm/s2" : "g");
}

INSTANTIATE_TEST_SUITE_P(
    SharedFolder, RealRecords,
    ::testing::Values(Reference{"RSN6_IMPVALL.I_I-ELC180.AT2", "at2", 5372, 0.01, 0.2808, 2.18},
                      Reference{"elCentro.AT2", "at2", 1559, 0.02, 0.3188, 2.02},
                      Reference{"RSN1084_NORTHR_SCS142.AT2", "at2", 8773, 0.005, 0.9234, 7.00},
                      Reference{"RSN758_LOMAP_EMY260.AT2", "at2", 7849, 0.005, 0.2525, 12.46},
                      // The COSMOS header gives the peak: −6.851512 cm/s² at 76.215 s.
                      Reference{"us1000hyfh_akbmrp_AKBMR--n.1000hyfh.BNZ.--.acc.V2c", "cosmos", 42000, 0.005,
                                0.06851512 / 9.81, 76.215}));

RecordOptions in_g() {
  RecordOptions o;
  o.units = "g";
  return o;
}

class MalformedRecords : public ::testing::Test {
 protected:
  fs::path write(const std::string& name, const std::string& text) {
    const fs::path dir = fs::temp_directory_path() / "poundsim_records";
    fs::create_directories(dir);
    std::ofstream(dir / name, std::ios::binary) << text;
    return dir / name;
  }
  std::string error_of(const fs::path& file, RecordOptions o = {}) {
    try {
      read_ground_motion(file, o);
    } catch (const InputError& e) {
      return e.what();
    }
    return "(no error)";
  }
  static std::string at2(const std::string& npts_line, const std::string& data) {
    return "PEER NGA STRONG MOTION DATABASE RECORD\nTest, 1/1/2000, Station, 090\n"
           "ACCELERATION TIME SERIES IN UNITS OF G\n" + npts_line + "\n" + data;
  }
  static std::string original() {
    std::ifstream in(kRecords / "RSN6_IMPVALL.I_I-ELC180.AT2", std::ios::binary);
    std::stringstream s;
    s << in.rdbuf();
    return s.str();
  }
};

TEST_F(MalformedRecords, EveryNptsAndDtSpelling) {
  const std::string data = "  .1E-01  -.2E-01   .3E-01\n   .4D-01   0.0\n";
  for (const char* line : {"NPTS=   5, DT=   .0100 SEC,", "NPTS=   5, DT=  0.01000 SEC", "NPTS=   5 DT=   .0100 SEC",
                           "DT=   .0100 SEC, NPTS=   5,", "NPTS   5   DT   .0100", "5    0.0100    NPTS, DT",
                           "5    0.0100    NPTS DT", "0.0100    5    DT, NPTS", "5    0.0100",
                           "NPTS=   5, DT=   .0100 SEC,   4 POLE @    30.00000 HZ,  -5 POLE @      .23000"}) {
    const GroundMotionRecord r = read_ground_motion(write("spelling.AT2", at2(line, data)), {});
    EXPECT_EQ(r.points, 5) << line;
    EXPECT_DOUBLE_EQ(r.dt, 0.01) << line;
    EXPECT_DOUBLE_EQ(r.excitation.acceleration[3], 0.04 * 9.81) << line;  // D exponent
  }
  // CRLF endings and no final newline.
  const GroundMotionRecord crlf =
      read_ground_motion(write("crlf.AT2", at2("NPTS=   3, DT= .02 SEC\r", "0.1 0.2\r\n0.3")), {});
  EXPECT_EQ(crlf.points, 3);
  EXPECT_DOUBLE_EQ(crlf.excitation.time[2], 0.04);
}

TEST_F(MalformedRecords, ErrorsNameTheFileAndTheLine) {
  std::string text = original();
  // Truncated: the last data line removed.
  std::string truncated = text.substr(0, text.rfind('\n', text.size() - 2) + 1);
  EXPECT_NE(error_of(write("truncated.AT2", truncated)).find("truncated: 5370 values where the header announces 5372"),
            std::string::npos)
      << error_of(write("truncated.AT2", truncated));
  // NPTS smaller than the data.
  std::string fewer = text;
  fewer.replace(fewer.find("NPTS=   5372"), 12, "NPTS=   5370");
  const std::string fewer_error = error_of(write("fewer.AT2", fewer));
  EXPECT_NE(fewer_error.find("fewer.AT2:1079: more values than the 5370 the header announces"), std::string::npos)
      << fewer_error;
  // Text in the numbers, and NaN.
  std::string text_in = text;
  text_in.replace(text_in.find(".1000757E-02"), 12, "  abc       ");
  EXPECT_NE(error_of(write("text.AT2", text_in)).find("text.AT2:5: 'abc' is not a number"), std::string::npos);
  EXPECT_NE(error_of(write("nan.AT2", at2("NPTS= 3, DT= .01 SEC", "0.1 NaN 0.3\n"))).find("nan.AT2:5: NaN is not a finite value"),
            std::string::npos);
  // No DT, no NPTS.
  EXPECT_NE(error_of(write("nodt.AT2", at2("NPTS=   3", "0.1 0.2 0.3\n"))).find("nodt.AT2:4: no DT"), std::string::npos);
  EXPECT_NE(error_of(write("nonpts.AT2", at2("DT= .01 SEC", "0.1 0.2 0.3\n"))).find("nonpts.AT2:4: no NPTS"),
            std::string::npos);
  // A velocity file is not an acceleration.
  std::string velocity = at2("NPTS= 2, DT= .01", "1 2\n");
  velocity.replace(velocity.find("ACCELERATION"), 12, "VELOCITY    ");
  velocity.replace(velocity.find("UNITS OF G"), 10, "UNITS OF CM/S");
  EXPECT_NE(error_of(write("vel.AT2", velocity)).find("vel.AT2:3: this is a velocity or displacement record"),
            std::string::npos);
  // Declared units must agree with the file.
  RecordOptions wrong;
  wrong.units = "cm/s2";
  EXPECT_NE(error_of(kRecords / "elCentro.AT2", wrong).find("the file says its accelerations are in g, the input says cm/s2"),
            std::string::npos);
  EXPECT_NE(error_of("/no/such/record.AT2").find("/no/such/record.AT2: cannot open"), std::string::npos);
}

TEST_F(MalformedRecords, CosmosWithoutSamplingIntervalOrData) {
  std::ifstream in(kRecords / "us1000hyfh_akbmrp_AKBMR--n.1000hyfh.BNZ.--.acc.V2c", std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  std::string text = s.str();
  std::string no_dt = text;
  no_dt.replace(no_dt.find("       5.000000     210.000000"), 30, "    -999.000000     210.000000");
  EXPECT_NE(error_of(write("nodt.V2c", no_dt)).find("no sampling interval"), std::string::npos);
  std::string short_data = text.substr(0, text.find("   3.438810e-04")) + "End-of-data for ChanBNZ acceleration\n";
  EXPECT_NE(error_of(write("short.V2c", short_data)).find("truncated: 1 values where the header announces 42000"),
            std::string::npos);
  std::string v1 = text;
  v1.replace(0, 22, "Uncorrected acceleration");
  EXPECT_NE(error_of(write("v1.V2c", v1)).find("v1.V2c:1: not corrected acceleration"), std::string::npos);
}

TEST_F(MalformedRecords, ColumnFilesNeedTheirUnitsAndIncreasingTimes) {
  const fs::path file = write("record.txt", "Time[s] Accel[g]\n# comment\n0.0\t-0.0012\n0.01;0.5;7\n0.02,  0.25, 9\n");
  EXPECT_NE(error_of(file).find("the units of the accelerations are not in the file: declare them"), std::string::npos);
  RecordOptions o;
  o.units = "cm/s2";
  const GroundMotionRecord r = read_ground_motion(file, o);
  EXPECT_EQ(r.format, "columns");
  EXPECT_EQ(r.points, 3);
  EXPECT_DOUBLE_EQ(r.excitation.acceleration[1], 0.005);
  EXPECT_DOUBLE_EQ(r.dt, 0.01);
  o.column = 3;
  EXPECT_NE(error_of(file, o).find("record.txt:3: expected at least 3 columns"), std::string::npos);
  EXPECT_NE(error_of(write("back.txt", "0 0\n0.2 1\n0.1 2\n"), in_g())
                .find("back.txt:3: time 0.1 s does not increase"),
            std::string::npos);
  EXPECT_NE(error_of(write("text.txt", "0 0\n0.1 oops\n"), in_g()).find("text.txt:2: text among the numbers"),
            std::string::npos);
  // One column with its dt; a target PGA replaces the scale.
  RecordOptions single = in_g();
  single.format = RecordFormat::single;
  single.target_pga_g = 0.3;
  single.dt = 0.02;
  const GroundMotionRecord s = read_ground_motion(write("single.acc", "0.1\n-0.2\n0.05\n"), single);
  EXPECT_DOUBLE_EQ(s.excitation.time[2], 0.04);
  EXPECT_DOUBLE_EQ(s.scale, 1.5);
  EXPECT_NEAR(s.pga_g, 0.3, 1e-15);
  EXPECT_DOUBLE_EQ(s.pga_file_g, 0.2);
}

}  // namespace
}  // namespace poundsim::io
