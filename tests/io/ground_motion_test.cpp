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

/// Whether `text` contains `part`, showing both when not.
::testing::AssertionResult Contains(const std::string& text, const std::string& part) {
  if (text.find(part) != std::string::npos) return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure() << "\n  " << text << "\ndoes not contain\n  " << part;
}

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
  // A folder per test: ctest runs the tests of this suite in parallel processes.
  static fs::path dir() {
    return fs::temp_directory_path() /
           ("poundsim_records_" + std::string(::testing::UnitTest::GetInstance()->current_test_info()->name()));
  }
  fs::path write(const std::string& name, const std::string& text) {
    fs::create_directories(dir());
    std::ofstream(dir() / name, std::ios::binary) << text;
    return dir() / name;
  }
  std::string error_of(const fs::path& file, RecordOptions o = {}) {
    try {
      read_ground_motion(file, o);
    } catch (const InputError& e) {
      return e.what();
    }
    return "(no error)";
  }
  std::string error_of_text(const std::string& text, const std::string& name) {
    try {
      parse_ground_motion(text, name, {});
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
  EXPECT_TRUE(
      Contains(error_of(write("short.V2c", short_data)),
               "short.V2c:53: 42000 acceleration points announced: the 53 bytes after this line hold at most 26"));
  std::string v1 = text;
  v1.replace(0, 22, "Uncorrected acceleration");
  EXPECT_NE(error_of(write("v1.V2c", v1)).find("v1.V2c:1: not corrected acceleration"), std::string::npos);
}

// The real COSMOS file cut to its header and four values, as lines (1-based numbers in the
// comments below are the file's own: 1–13 text, 14 integer-header line, 15–24 integers, 25
// real-header line, 26–45 reals, #62 the second value of line 38, 46 comment count, 47–52
// comments, 53 data header).
std::vector<std::string> cosmos_lines() {
  std::ifstream in(kRecords / "us1000hyfh_akbmrp_AKBMR--n.1000hyfh.BNZ.--.acc.V2c", std::ios::binary);
  std::vector<std::string> lines;
  for (std::string line; std::getline(in, line) && lines.size() < 57;) lines.push_back(line);
  lines[52].replace(0, 8, "       4");
  lines.push_back("End-of-data for ChanBNZ acceleration");
  return lines;
}

std::string joined(const std::vector<std::string>& lines) {
  std::string text;
  for (const std::string& line : lines) text += line + "\n";
  return text;
}

// A file read again (a study's points, an ensemble's records) comes from the cache with its own
// scale, to the bit of a fresh reading; a file rewritten since is read again.
TEST_F(MalformedRecords, ARecordReadAgainIsTheSameAndARewrittenOneIsReadAgain) {
  const std::string text = at2("NPTS=    4, DT= .0100 SEC", "0.1 -0.2 0.3 -0.4\n");
  const fs::path file = write("cached.AT2", text);
  RecordOptions twice;
  twice.scale = 2.0;
  const GroundMotionRecord once = read_ground_motion(file, {});
  const GroundMotionRecord scaled = read_ground_motion(file, twice);
  EXPECT_EQ(once.excitation.acceleration, parse_ground_motion(text, file, {}).excitation.acceleration);
  EXPECT_EQ(scaled.excitation.acceleration, parse_ground_motion(text, file, twice).excitation.acceleration);
  EXPECT_DOUBLE_EQ(scaled.excitation.acceleration[3], -0.8 * 9.81);
  EXPECT_EQ(scaled.scale, 2.0);
  // Rewritten with one sample more: its size (and time) change, so it is read again.
  write("cached.AT2", at2("NPTS=    5, DT= .0100 SEC", "0.1 -0.2 0.3 -0.4 0.5\n"));
  const GroundMotionRecord rewritten = read_ground_motion(file, twice);
  ASSERT_EQ(rewritten.points, 5);
  EXPECT_DOUBLE_EQ(rewritten.excitation.acceleration[4], 1.0 * 9.81);
  // The same file by another path (a relative one with ..) is the same reading.
  const fs::path roundabout = file.parent_path() / ".." / file.parent_path().filename() / file.filename();
  EXPECT_EQ(read_ground_motion(roundabout, twice).excitation.acceleration, rewritten.excitation.acceleration);
  EXPECT_EQ(read_ground_motion(roundabout, twice).excitation.source, roundabout.string());
}

TEST_F(MalformedRecords, ParsedFromMemoryAsFromTheFile) {
  std::ifstream in(kRecords / "elCentro.AT2", std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  const GroundMotionRecord file = read_ground_motion(kRecords / "elCentro.AT2", {});
  const GroundMotionRecord memory = parse_ground_motion(s.str(), "memory.AT2", {});
  EXPECT_EQ(memory.excitation.acceleration, file.excitation.acceleration);
  EXPECT_EQ(memory.excitation.time, file.excitation.time);
  EXPECT_EQ(memory.excitation.source, "memory.AT2");
  EXPECT_TRUE(Contains(error_of_text("NPTS= 3", "memory.AT2"), "memory.AT2:1: an AT2 file has four header lines"));
}

TEST_F(MalformedRecords, CosmosCutToFourPointsReads) {
  const GroundMotionRecord r = read_ground_motion(write("four.V2c", joined(cosmos_lines())), {});
  EXPECT_EQ(r.points, 4);
  EXPECT_DOUBLE_EQ(r.dt, 0.005);
  EXPECT_DOUBLE_EQ(r.excitation.acceleration[0], 3.437285e-04 * 0.01);
  EXPECT_DOUBLE_EQ(r.duration, 0.015);
}

// A real header of fewer than 62 values must not be read past its end (#62 taken from beyond
// the array would be a heap-buffer-overflow under ASan, a garbage dt otherwise).
TEST_F(MalformedRecords, CosmosRealHeaderWithoutValue62IsAnError) {
  std::vector<std::string> lines = cosmos_lines();
  lines[24] = " 50 Real-header values follow on  10 lines, Format= (5F15.6)";
  lines.erase(lines.begin() + 35, lines.begin() + 45);  // the reals after #50
  EXPECT_EQ(
      error_of(write("short_real.V2c", joined(lines))),
      (dir() / "short_real.V2c").string() + ":25: the real header has 50 values: the sampling interval is value #62");
}

// Every count in a COSMOS header is checked against what the file holds before it is used.
TEST_F(MalformedRecords, CosmosCountsThatLieAreErrors) {
  const auto error = [&](const std::string& name, std::size_t line, const std::string& text) {
    std::vector<std::string> lines = cosmos_lines();
    lines[line - 1] = text;
    return error_of(write(name, joined(lines)));
  };
  // Text-line counts: 23 digits (was a bare "stoul"), beyond the file, zero.
  EXPECT_TRUE(Contains(
      error("text23.V2c", 1, "Corrected acceleration    (Format v01.20 with 12345678901234567890123 text lines)"),
      "text23.V2c:1: 12345678901234567890123 text lines announced: the file has 58 lines"));
  EXPECT_TRUE(Contains(error("text99.V2c", 1, "Corrected acceleration    (Format v01.20 with 99 text lines)"),
                       "text99.V2c:1: 99 text lines announced: the file has 58 lines"));
  EXPECT_TRUE(Contains(error("text12.V2c", 1, "Corrected acceleration    (Format v01.20 with 12 text lines)"),
                       "text12.V2c:13: expected the integer-header line"));
  // Integer header: more lines than the file, a count its lines do not hold.
  EXPECT_TRUE(Contains(
      error("int_lines.V2c", 14, " 100 Integer-header values follow on  99999999999999999999999 lines, Format= (10I8)"),
      "int_lines.V2c:14: 99999999999999999999999 integer-header lines announced: 44 lines follow"));
  EXPECT_TRUE(Contains(error("int_count.V2c", 14, " 101 Integer-header values follow on  10 lines, Format= (10I8)"),
                       "int_count.V2c:14: 101 integer-header values announced: lines 15–24 hold 100"));
  EXPECT_TRUE(Contains(
      error("int_text.V2c", 15, "       2       1       4     120       1    -999    -999      11    -999    x"),
      "int_text.V2c:15: 'x' is not an integer (integer header)"));
  // Real header: a count its lines do not hold, #62 not finite or unknown.
  EXPECT_TRUE(Contains(error("real_count.V2c", 25, " 99 Real-header values follow on  20 lines, Format= (5F15.6)"),
                       "real_count.V2c:25: 99 real-header values announced: lines 26–45 hold 100"));
  EXPECT_TRUE(
      Contains(error("dt_nan.V2c", 38, "    -999.000000            nan     210.000000      -6.851512      76.215000"),
               "dt_nan.V2c:38: no sampling interval: real header #62 is nan ms, not a finite number > 0"));
  EXPECT_TRUE(
      Contains(error("dt_inf.V2c", 38, "    -999.000000         1e999     210.000000      -6.851512      76.215000"),
               "dt_inf.V2c:38: no sampling interval: real header #62 is 1e999 ms"));
  // Comments: a count larger than the comment lines.
  EXPECT_TRUE(Contains(error("comments.V2c", 46, "   7 Comment line(s) follow, each starting with a \"|\":"),
                       "comments.V2c:53: comment line 7 of 7 does not start with '|'"));
  // Point counts of 11 and 23 digits (were a bare "stoul" or std::bad_alloc), more than the file.
  EXPECT_TRUE(Contains(
      error("pts11.V2c", 53, "   99999999999 acceleration pts, approx  210 secs, units=cm/sec2(04),Format=(1E15.6)"),
      "pts11.V2c:53: 99999999999 acceleration points announced: the 101 bytes after this line hold at most 50"));
  EXPECT_TRUE(
      Contains(error("pts23.V2c", 53, "   12345678901234567890123 acceleration pts, units=cm/sec2(04),Format=(1E15.6)"),
               "pts23.V2c:53: 12345678901234567890123 acceleration points announced: the 101 bytes"));
  EXPECT_TRUE(
      Contains(error("pts5.V2c", 53, "   5 acceleration pts, approx  210 secs, units=cm/sec2(04),Format=(1E15.6)"),
               "pts5.V2c:57: truncated: 4 values where the header announces 5"));
  EXPECT_TRUE(Contains(error("nounits.V2c", 53, "   4 acceleration pts, approx  210 secs"),
                       "nounits.V2c:53: the data header gives no units="));
}

// NPTS = 9999999999 (a std::bad_alloc if believed) and a 400-digit NPTS (a bare "stod" error)
// are both errors at line 4 before anything is allocated.
TEST_F(MalformedRecords, At2NptsLargerThanTheFileIsAnError) {
  EXPECT_TRUE(Contains(error_of(write("big.AT2", at2("NPTS= 9999999999, DT= .01 SEC", "0.1 0.2 0.3\n"))),
                       "big.AT2:4: NPTS = 9999999999 announced: the 12 bytes after the header hold at most 6 values"));
  const std::string digits(400, '7');
  EXPECT_TRUE(Contains(error_of(write("digits.AT2", at2("NPTS= " + digits + ", DT= .01 SEC", "0.1 0.2 0.3\n"))),
                       "digits.AT2:4: NPTS = 7777777777777777777777777777777777777777… (400 characters) announced: "
                       "the 12 bytes after the header hold at most 6 values"));
  EXPECT_TRUE(
      Contains(error_of(write("unlabelled.AT2", at2("1e300 0.01", "0.1 0.2 0.3\n"))),
               "unlabelled.AT2:4: NPTS = 1E300 announced: the 12 bytes after the header hold at most 6 values"));
  EXPECT_TRUE(Contains(error_of(write("fraction.AT2", at2("NPTS, DT: 2.5 0.01", "0.1 0.2 0.3\n"))),
                       "fraction.AT2:4: NPTS = 2.5 must be an integer ≥ 2"));
}

// DT = INF would pass a header check and fail later without naming the file; DT = 1E308 gives
// times that overflow. Both are errors at line 4.
TEST_F(MalformedRecords, At2DtMustBeFiniteAndItsTimesToo) {
  EXPECT_TRUE(Contains(error_of(write("inf.AT2", at2("NPTS= 3, DT= INF", "0.1 0.2 0.3\n"))),
                       "inf.AT2:4: DT = INF s must be a finite number > 0"));
  EXPECT_TRUE(Contains(error_of(write("nan.AT2", at2("NPTS= 3, DT= NAN SEC", "0.1 0.2 0.3\n"))),
                       "nan.AT2:4: DT = NAN s must be a finite number > 0"));
  EXPECT_TRUE(Contains(error_of(write("under.AT2", at2("3 1E-400", "0.1 0.2 0.3\n"))),
                       "under.AT2:4: DT = 1E-400 s must be a finite number > 0"));
  EXPECT_TRUE(Contains(error_of(write("huge.AT2", at2("NPTS= 3, DT= 1E308 SEC", "0.1 0.2 0.3\n"))),
                       "huge.AT2:4: the record's length (NPTS − 1) × DT = 2 × 1E308 s is not a finite number"));
  // A huge but finite DT is read; its length is finite (the step bound is the input's business).
  const GroundMotionRecord r =
      read_ground_motion(write("big_dt.AT2", at2("NPTS= 3, DT= 1E300 SEC", "0.1 0.2 0.3\n")), {});
  EXPECT_DOUBLE_EQ(r.duration, 2e300);
}

TEST_F(MalformedRecords, ValuesOutOfRangeAndEmptyFilesNameTheFileAndLine) {
  EXPECT_TRUE(Contains(error_of(write("overflow.AT2", at2("NPTS= 3, DT= .01 SEC", "0.1\n1e999 0.3\n"))),
                       "overflow.AT2:6: 1e999 is beyond the range of a double"));
  EXPECT_TRUE(Contains(error_of(write("empty.AT2", "")), "empty.AT2: the file is empty"));
  EXPECT_TRUE(Contains(error_of(write("header.AT2", at2("NPTS= 3, DT= .01 SEC", ""))),
                       "header.AT2:4: an AT2 file has four header lines before the data"));
  EXPECT_TRUE(Contains(error_of(write("time.txt", "0 0\n1e309 0.1\n"), in_g()),
                       "time.txt:2: 1e309 is beyond the range of a double"));
  EXPECT_TRUE(Contains(error_of(write("tiny.txt", "0 0\n0.1 1e-400\n"), in_g()),
                       "tiny.txt:2: 1e-400 is beyond the range of a double"));
  EXPECT_TRUE(
      Contains(error_of(write("nan_time.txt", "0 0\nnan 0.1\n"), in_g()), "nan_time.txt:2: nan is not a finite value"));
  EXPECT_TRUE(Contains(error_of(write("one.txt", "# t a\n0 0\n"), in_g()),
                       "one.txt:2: a record needs at least two samples, found 1"));
  // A line of a million digits where NPTS is looked for (a recursive regex overflowed its stack).
  EXPECT_TRUE(Contains(error_of(write("long.AT2", at2("DT= .01 NPTS= " + std::string(1000000, '1'), "0.1 0.2\n"))),
                       "long.AT2:4: NPTS = 1111111111111111111111111111111111111111… (1000000 characters) announced"));
  // Control characters are escaped and long tokens cut in messages.
  EXPECT_TRUE(
      Contains(error_of(write("binary.AT2",
                              at2("NPTS= 2, DT= .01", std::string("0.1 \x01\x02") + std::string(100, 'z') + "\n"))),
               "binary.AT2:5: '\\x01\\x02zzzzzzzzzzzzzzzzzzzzzzzzzzzzzzzzzzzzzz… (102 characters)' is not a number"));
}

TEST_F(MalformedRecords, OnlyRegularFilesOfBoundedSize) {
  fs::create_directories(dir());
  EXPECT_TRUE(Contains(error_of(dir()), dir().string() + ": a directory, not a record file"));
  EXPECT_TRUE(Contains(error_of("/dev/zero", in_g()), "/dev/zero: larger than 64 MiB: not a ground-motion record"));
}

// A scale that makes the accelerations overflow is an error naming the file and the scale, not
// "sample 1 is not finite" later; its own type lets the input blame the scale key.
TEST_F(MalformedRecords, ScaleThatOverflowsIsAnError) {
  RecordOptions huge;
  huge.scale = 1e308;
  EXPECT_THROW(read_ground_motion(kRecords / "elCentro.AT2", huge), RecordScaleError);
  RecordOptions tiny_peak = in_g();
  tiny_peak.target_pga_g = 1.0;
  EXPECT_THROW(read_ground_motion(write("tiny_peak.txt", "0 1e-320\n0.01 0\n"), tiny_peak), RecordScaleError);
  RecordOptions o;
  o.scale = 1e308;
  EXPECT_TRUE(
      Contains(error_of(kRecords / "elCentro.AT2", o), "elCentro.AT2: the scale 1e+308 overflows in m/s² per g"));
  o.units = "cm/s2";  // 1e308 × 0.01 m/s² is finite, and so is 100 cm/s² scaled; 200 cm/s² is not
  EXPECT_TRUE(Contains(error_of(write("cms2.txt", "0 100\n0.01 200\n"), o),
                       "cms2.txt: the scale 1e+308 makes sample 2 (200 cm/s2 in the file) overflow"));
  RecordOptions single = in_g();
  single.format = RecordFormat::single;
  single.dt = 1e308;
  EXPECT_TRUE(Contains(error_of(write("single_dt.acc", "0.1\n0.2\n0.3\n"), single),
                       "single_dt.acc:3: time 2 × 1e+308 s is not a finite number"));
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
  // A header naming PEER as its source is a column file's (AT2 files open with PEER's banner).
  const GroundMotionRecord peer =
      read_ground_motion(write("northridge.dat", "Source: PEER Strong Motion Database\nTime[s] Accel[g]\n0.0\t-0.0012\n"
                                                 "0.01\t-0.0007\n"),
                         in_g());
  EXPECT_EQ(peer.format, "columns");
  EXPECT_EQ(peer.points, 2);
  EXPECT_EQ(read_ground_motion(write("banner.txt", at2("NPTS= 2, DT= .01", "0.1 0.2\n")), {}).format, "at2");
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
