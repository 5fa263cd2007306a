// Reading model files: the two forms, overrides, and a clear message for every bad input.

#include "poundsim/io/input.hpp"

#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <regex>

#include <gtest/gtest.h>

#include "poundsim/error.hpp"
#include "poundsim/io/frequency_response_run.hpp"
#include "../test_models.hpp"

namespace poundsim::io {
namespace {

const std::string kDimensionless = "title = \"test\"\n" + testing::model_toml("[1, 3]", testing::fig2('c')) + R"([excitation]
kind = "harmonic"
amplitude_g = 0.2
ratio = 0.8
[analysis]
kind = "time_history"
duration = 2.0
dt = 0.001
)";

const std::string kPhysical = R"([[frames]]
mass = 2.0e5
stiffness = [4.0e7, 3.0e7]
damping = 1.0e5
[[frames]]
storeys = 1
mass = 1.0e5
stiffness = 1.0e7
damping_ratio = 0.05
[gap_elements]
gap = 0.02
restitution = 0.65
[excitation]
kind = "none"
[analysis]
kind = "time_history"
duration = 1
dt = 0.002
output_dt = 0.01
separation = "force"
)";

RunInput read(const std::string& text, std::vector<std::string> overrides = {}) {
  return read_input_string(text, "model.toml", ".", overrides);
}

/// The message of the InputError that reading `text` throws.
std::string error_of(const std::string& text, std::vector<std::string> overrides = {}) {
  try {
    read(text, std::move(overrides));
  } catch (const InputError& e) {
    return e.what();
  }
  return "(no error)";
}

std::string replace(std::string text, const std::string& from, const std::string& to) {
  const auto at = text.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  return text.replace(at, from.size(), to);
}

TEST(InputDimensionless, MapsToThePhysicalModel) {
  const RunInput in = read(kDimensionless);
  ASSERT_EQ(in.model.frame_count(), 2);
  EXPECT_EQ(in.model.frames[1].storeys(), 3);
  EXPECT_EQ(in.model.gap_count(), 1);
  EXPECT_DOUBLE_EQ(in.model.frames[0].stiffness[0], 200.0);
  EXPECT_DOUBLE_EQ(in.model.frames[1].stiffness[2], 50.0);
  EXPECT_DOUBLE_EQ(parameters_of<PaperGap>(in.model.gaps[0]).gap, 0.25 * 9.81 / 200);
  const auto& h = std::get<HarmonicExcitation>(in.excitation);
  EXPECT_DOUBLE_EQ(h.amplitude, 0.2 * 9.81);
  EXPECT_DOUBLE_EQ(h.omega, 0.8 * std::sqrt(200.0));
  EXPECT_DOUBLE_EQ(in.analysis.output_dt, 0.001);  // default: every step
  EXPECT_DOUBLE_EQ(in.analysis.options.event_tolerance, 1e-10);
  EXPECT_EQ(in.analysis.options.separation, SeparationCriterion::displacement);
}

TEST(InputPhysical, BroadcastsScalarsAndConvertsDampingRatio) {
  const RunInput in = read(kPhysical);
  ASSERT_EQ(in.model.frames[0].storeys(), 2);
  EXPECT_EQ(in.model.frames[0].mass, (std::vector<double>{2.0e5, 2.0e5}));
  EXPECT_EQ(in.model.frames[0].damping, (std::vector<double>{1.0e5, 1.0e5}));
  const Frame& f2 = in.model.frames[1];
  EXPECT_NEAR(f2.damping[0] / (2 * f2.mass[0] * std::sqrt(1.0e7 / 1.0e5)), 0.05, 1e-14);
  EXPECT_DOUBLE_EQ(parameters_of<PaperGap>(in.model.gaps[0]).restitution, 0.65);
  EXPECT_EQ(in.analysis.options.separation, SeparationCriterion::force);
  EXPECT_TRUE(std::holds_alternative<NoExcitation>(in.excitation));
}

/// Two frames of two storeys, one element overridden.
const std::string kOverriddenElement = R"([[frames]]
mass = 1
stiffness = 100
damping = 0
storeys = 2
[[frames]]
mass = 1
stiffness = 100
damping = 0
storeys = 2
[gap_elements]
gap = 0.01
restitution = 1.0
[[gap_elements.override]]
frames = [1, 2]
floor = 2
gap = 0.03
stiffness = 10
shortening = 0.01
[excitation]
kind = "none"
[analysis]
kind = "time_history"
duration = 1
dt = 0.01
)";

TEST(InputPhysical, OverridesOfSingleElements) {
  const std::string text = kOverriddenElement;
  const RunInput in = read(text);
  EXPECT_DOUBLE_EQ(parameters_of<PaperGap>(in.model.gaps[0]).gap, 0.01);
  EXPECT_DOUBLE_EQ(parameters_of<PaperGap>(in.model.gaps[1]).gap, 0.03);
  EXPECT_DOUBLE_EQ(parameters_of<PaperGap>(in.model.gaps[1]).restitution, 1.0);  // inherited
  EXPECT_NE(error_of(replace(text, "floor = 2", "floor = 3")).find("share floors 1..2"),
            std::string::npos);
}

// The law is chosen by its name (`law = "..."`, the first of GapLaw by default) and then exactly
// its parameters are read: an unknown name lists the laws, a key of no law is unknown.
TEST(InputPhysical, GapElementLawIsChosenByItsName) {
  // The same file with the law named in both tables.
  const std::string text =
      replace(replace(replace(kOverriddenElement, "restitution = 1.0", "restitution = 0.5"), "gap = 0.01",
                      "law = \"paper\"\ngap = 0.01"),
              "floor = 2\ngap = 0.03", "floor = 2\nlaw = \"paper\"");
  const RunInput in = read(text);
  ASSERT_EQ(in.model.gaps.size(), 2U);
  EXPECT_EQ(key_of(in.model.gaps[1].law), "paper");
  // Naming the law it inherits keeps the inherited values.
  EXPECT_DOUBLE_EQ(parameters_of<PaperGap>(in.model.gaps[1]).restitution, 0.5);
  EXPECT_DOUBLE_EQ(parameters_of<PaperGap>(in.model.gaps[1]).gap, 0.01);
  EXPECT_DOUBLE_EQ(parameters_of<PaperGap>(in.model.gaps[1]).stiffness, 10.0);
  EXPECT_EQ(read(replace(text, "law = \"paper\"\ngap", "gap")).model.gaps[1].law, in.model.gaps[1].law);
  const std::string unknown = error_of(replace(text, "law = \"paper\"\ngap", "law = \"herz\"\ngap"));
  EXPECT_NE(unknown.find("gap_elements.law"), std::string::npos) << unknown;
  EXPECT_NE(unknown.find("\"herz\" is not one of: \"paper\", \"kelvin_voigt\", \"hertz\", \"hertzdamp\", \"jankowski\""),
            std::string::npos)
      << unknown;
  const std::string stray = error_of(replace(text, "restitution = 0.5", "restitution = 0.5\nbeta = 2"));
  EXPECT_NE(stray.find("gap_elements.beta"), std::string::npos) << stray;
  EXPECT_NE(stray.find("unknown key"), std::string::npos) << stray;
  // The rule between a law's parameters blames the key the table gave.
  const std::string rule = error_of(replace(text, "shortening = 0.01", "shortening = 0"));
  EXPECT_NE(rule.find("gap_elements.override[1].shortening"), std::string::npos) << rule;
  EXPECT_NE(rule.find("rigid stop"), std::string::npos) << rule;
}

// A frame's storey law is chosen by its name, the linear storey by default; its storeys are
// then the links make_links gives that law.
TEST(InputPhysical, StoreyLawIsChosenByItsName) {
  const std::string text = replace(kOverriddenElement, "storeys = 2\n[gap_elements]",
                                   "storeys = 2\nstorey_law = \"linear\"\n[gap_elements]");
  const RunInput in = read(text);
  EXPECT_EQ(key_of(in.model.frames[1].storey_law), "linear");
  EXPECT_EQ(in.model.frames[1].storey_law, read(kOverriddenElement).model.frames[1].storey_law);
  const std::vector<Link> links = make_links(in.model, DofLayout(in.model));
  ASSERT_TRUE(std::holds_alternative<LinearStorey>(links[3].law));
  EXPECT_EQ(std::get<LinearStorey>(links[3].law).stiffness, 100.0);
  const std::string unknown = error_of(replace(text, "storey_law = \"linear\"", "storey_law = \"trilinear\""));
  EXPECT_NE(unknown.find("frames[2].storey_law"), std::string::npos) << unknown;
  EXPECT_NE(unknown.find("\"trilinear\" is not one of: \"linear\", \"bilinear\", \"bouc_wen\""), std::string::npos) << unknown;
  // A parameter of no law of this frame is an unknown key.
  const std::string stray = error_of(replace(text, "storey_law = \"linear\"", "storey_law = \"linear\"\nyield_force = 3"));
  EXPECT_NE(stray.find("frames[2].yield_force"), std::string::npos) << stray;
  EXPECT_NE(stray.find("unknown key"), std::string::npos) << stray;
}

TEST(InputHarmonic, RatioOmegaAndHertzAgree) {
  const double w1 = std::sqrt(200.0);
  const auto omega = [](const RunInput& in) { return std::get<HarmonicExcitation>(in.excitation).omega; };
  EXPECT_DOUBLE_EQ(omega(read(replace(kDimensionless, "ratio = 0.8", "omega = 11.0"))), 11.0);
  EXPECT_DOUBLE_EQ(omega(read(replace(kDimensionless, "ratio = 0.8", "frequency_hz = 2.0"))),
                   4 * std::numbers::pi);
  EXPECT_DOUBLE_EQ(omega(read(kDimensionless)), 0.8 * w1);
  EXPECT_NE(error_of(replace(kDimensionless, "ratio = 0.8", "ratio = 0.8\nomega = 3")).find("exactly one"),
            std::string::npos);
}

TEST(InputOverrides, SetReplacesAndCreatesKeys) {
  const RunInput in = read(kDimensionless, {"model.dimensionless.eta=0.5", "analysis.separation=force",
                                            "analysis.output_dt=0.01"});
  EXPECT_DOUBLE_EQ(parameters_of<PaperGap>(in.model.gaps[0]).stiffness, 0.5 * 200);
  EXPECT_EQ(in.analysis.options.separation, SeparationCriterion::force);
  EXPECT_DOUBLE_EQ(in.analysis.output_dt, 0.01);
  const RunInput phys = read(kPhysical, {"frames[2].mass=3.0e5"});
  EXPECT_DOUBLE_EQ(phys.model.frames[1].mass[0], 3.0e5);
}

TEST(InputOverrides, FloatValuesReadBackExactlyAndStayFloats) {
  EXPECT_EQ(toml_float(1.0), "1.0");
  EXPECT_EQ(toml_float(-3.0), "-3.0");
  EXPECT_EQ(toml_float(0.1), "0.1");
  EXPECT_EQ(toml_float(1e300), "1e+300");
  for (const double x : {0.1, 1.0 / 3.0, 6.02214076e23, 2.5e-300, 1.0}) {
    const RunInput in = read(kDimensionless, {"excitation.amplitude_g=" + toml_float(x)});
    EXPECT_EQ(in.excitation_info.amplitude_g, x);
  }
}

TEST(InputOverrides, BadOverridesNameTheSetOption) {
  EXPECT_NE(error_of(kDimensionless, {"analysis.bogus=1"}).find("--set analysis.bogus=1"),
            std::string::npos);
  EXPECT_NE(error_of(kDimensionless, {"analysis.bogus=1"}).find("unknown key"), std::string::npos);
  EXPECT_NE(error_of(kDimensionless, {"analysis.dt=-1"}).find("--set analysis.dt=-1: analysis.dt: must be > 0"),
            std::string::npos);
  EXPECT_NE(error_of(kDimensionless, {"novalue"}).find("expected key=value"), std::string::npos);
  EXPECT_NE(error_of(kPhysical, {"frames[3].mass=1"}).find("only 2"), std::string::npos);
  EXPECT_NE(error_of(kDimensionless, {"title.x=1"}).find("not a table"), std::string::npos);
}

struct BadInput {
  const char* name;
  std::string text;
  const char* expected;  ///< A regular expression the message must match.
};

class InputErrors : public ::testing::TestWithParam<BadInput> {};

TEST_P(InputErrors, MessageNamesTheFileTheKeyAndTheLine) {
  const BadInput& c = GetParam();
  const std::string message = error_of(c.text);
  EXPECT_TRUE(std::regex_search(message, std::regex(c.expected))) << message;
  EXPECT_EQ(message.rfind("model.toml", 0), 0u) << message;
}

INSTANTIATE_TEST_SUITE_P(
    Cases, InputErrors,
    ::testing::Values(
        BadInput{"MissingKey", replace(kDimensionless, "eta = 0.125\n", ""),
                 R"(^model\.toml:4:1: model\.dimensionless\.eta: missing key$)"},
        BadInput{"UnknownKey", replace(kDimensionless, "dt = 0.001", "dt = 0.001\nstep = 2"),
                 R"(^model\.toml:23:\d+: analysis\.step: unknown key for kind = "time_history"$)"},
        BadInput{"UnknownTopLevelKey", kDimensionless + "\n[outputs]\nx = 1\n",
                 R"(^model\.toml:2\d:1: outputs: unknown table; did you mean 'output'\?$)"},
        BadInput{"WrongType", replace(kDimensionless, "dt = 0.001", "dt = \"fast\""),
                 R"(^model\.toml:22:6: analysis\.dt: expected a number, got a string$)"},
        BadInput{"NonPositiveMass", replace(kPhysical, "mass = 2.0e5", "mass = [2.0e5, 0.0]"),
                 R"(^model\.toml:2:\d+: frames\[1\]\.mass: floor 2: must be > 0 \(got 0\)$)"},
        BadInput{"NegativeMassDimensionless", replace(kDimensionless, "beta = 1.0", "beta = -1.0"),
                 R"(model\.dimensionless\.beta: must be > 0 \(got -1\))"},
        BadInput{"NonPositiveStiffness", replace(kPhysical, "stiffness = 1.0e7", "stiffness = -1.0e7"),
                 R"(^model\.toml:8:\d+: frames\[2\]\.stiffness: storey 1: must be > 0)"},
        BadInput{"NegativeDamping", replace(kPhysical, "damping = 1.0e5", "damping = -3"),
                 R"(frames\[1\]\.damping: storey 1: must be ≥ 0 \(got -3\))"},
        BadInput{"NegativeXi", replace(kDimensionless, "xi = 0.05", "xi = -0.05"),
                 R"(:9:\d+: model\.dimensionless\.xi: must be ≥ 0)"},
        BadInput{"RestitutionAboveOne", replace(kDimensionless, "restitution = 0.75", "restitution = 1.5"),
                 R"(model\.dimensionless\.restitution: must be in \[0, 1\] \(got 1\.5\))"},
        BadInput{"RestitutionBelowZero", replace(kPhysical, "restitution = 0.65", "restitution = -0.1"),
                 R"(:12:\d+: gap_elements\.restitution: must be in \[0, 1\])"},
        BadInput{"ZeroStep", replace(kDimensionless, "dt = 0.001", "dt = 0.0"),
                 R"(:22:\d+: analysis\.dt: must be > 0 \(got 0\))"},
        BadInput{"NegativeStep", replace(kDimensionless, "dt = 0.001", "dt = -0.001"),
                 R"(analysis\.dt: must be > 0)"},
        BadInput{"SyntaxError", replace(kDimensionless, "alpha = 0.25", "alpha = = 0.25"),
                 R"(^model\.toml:6:\d+: )"},
        BadInput{"BothForms", kDimensionless + "[[frames]]\nmass = 1\nstiffness = 1\ndamping = 0\n",
                 R"(frames: give either \[model\])"},
        BadInput{"NoStructure", "[analysis]\nkind = \"time_history\"\n",
                 R"(missing the structure)"},
        BadInput{"UnknownKind", replace(kDimensionless, "kind = \"harmonic\"", "kind = \"sine\""),
                 R"(excitation\.kind: "sine" is not one of: "harmonic", "record", "none")"},
        BadInput{"KeyOfAnotherKind", replace(kDimensionless, "kind = \"harmonic\"", "kind = \"none\""),
                 R"(excitation\.amplitude_g: unknown key for kind = "none")"},
        BadInput{"OutputNotAMultiple", replace(kDimensionless, "dt = 0.001", "dt = 0.001\noutput_dt = 0.0015"),
                 R"(analysis\.output_dt: 0\.0015 s must be a positive multiple of dt)"},
        BadInput{"SpringWithoutStroke", replace(kDimensionless, "epsilon = 0.5", "epsilon = 0.0"),
                 R"(model\.dimensionless\.epsilon: is 0 but eta or mu is not)"},
        BadInput{"ThreeFramesDimensionless", replace(kDimensionless, "storeys = [1, 3]", "storeys = [1, 3, 2]"),
                 R"(model\.storeys: the dimensionless form describes two frames)"},
        BadInput{"DampingTwice", replace(kPhysical, "damping_ratio = 0.05", "damping_ratio = 0.05\ndamping = 1"),
                 R"(frames\[2\]: give either damping or damping_ratio)"},
        BadInput{"MissingRecordFile",
                 replace(replace(kDimensionless, "kind = \"harmonic\"\namplitude_g = 0.2\nratio = 0.8",
                                 "kind = \"record\"\nfile = \"no_such_record.txt\""), "", ""),
                 R"(^model\.toml:17:\d+: excitation\.file: \./no_such_record\.txt: cannot open the record file$)"},
        BadInput{"InitialOverlap", kPhysical + "[initial]\ndisplacement = [[0.05, 0.0], [0.0]]\n",
                 R"(initial\.displacement: frames 1 and 2 overlap at floor 1)"},
        BadInput{"InitialWrongShape", kPhysical + "[initial]\nvelocity = [[0.05], [0.0]]\n",
                 R"(initial\.velocity: frame 1 has 2 floors, 1 values given)"}),
    [](const ::testing::TestParamInfo<BadInput>& p) { return p.param.name; });

const std::string kFrf = testing::model_toml("[1, 1]", testing::fig2('a')) + R"([analysis]
kind = "frf"
integrator = "exact"
[frf]
amplitude_g = 0.2
ratio_min = 0.5
ratio_max = 1.5
points = 5
sweep = "both"
steps_per_period = 32
)";

TEST(InputFrf, ReadsTheSweep) {
  const RunInput in = read(kFrf);
  ASSERT_TRUE(in.frf.has_value());
  EXPECT_EQ(in.frf->ratios, (std::vector<double>{0.5, 0.75, 1.0, 1.25, 1.5}));
  EXPECT_EQ(in.frf->sweep, SweepMode::both);
  EXPECT_EQ(in.frf->steady.steps_per_period, 32);
  EXPECT_DOUBLE_EQ(in.frf->steady.tolerance, 1e-6);
  EXPECT_EQ(in.analysis.options.integrator, Integrator::exact);
  const RunInput listed = read(replace(kFrf, "ratio_min = 0.5\nratio_max = 1.5\npoints = 5", "ratios = [1.2, 0.7]"));
  EXPECT_EQ(listed.frf->ratios, (std::vector<double>{0.7, 1.2}));
}

TEST(InputFrf, LanesAreThoseOfPointsFromRestWithNewmark) {
  const std::string rest = replace(replace(kFrf, "sweep = \"both\"", "sweep = \"rest\""), "integrator = \"exact\"",
                                   "integrator = \"newmark\"");
  EXPECT_EQ(read(rest).frf->lanes, 8);
  EXPECT_EQ(read(rest, {"frf.lanes=3"}).frf->lanes, 3);
  EXPECT_EQ(io::frequency_response_options(read(rest, {"frf.lanes=3"})).lanes, 3);
  EXPECT_NE(error_of(rest, {"frf.lanes=9"}).find("frf.lanes: must be ≤ 8 (got 9)"), std::string::npos);
  EXPECT_NE(error_of(rest, {"frf.lanes=0"}).find("frf.lanes: must be ≥ 1 (got 0)"), std::string::npos);
  // Nothing to step together: a sweep, the exact integrator.
  EXPECT_NE(error_of(replace(rest, "sweep = \"rest\"", "sweep = \"up\""), {"frf.lanes=4"})
                .find("frf.lanes: only for method = \"simulation\" with sweep = \"rest\""),
            std::string::npos);
  EXPECT_NE(error_of(kFrf, {"frf.sweep=\"rest\"", "frf.method=\"simulation\"", "frf.lanes=4"})
                .find("analysis.integrator = \"newmark\""),
            std::string::npos);
}

TEST(InputFrf, RejectsWhatAFrequencyResponseDoesNotUse) {
  EXPECT_NE(error_of(kFrf + "[excitation]\nkind = \"none\"\n").find("excitation: a frequency response sets its own"),
            std::string::npos);
  EXPECT_NE(error_of(replace(kFrf, "kind = \"frf\"", "kind = \"frf\"\nduration = 3")).find(
                "analysis.duration: unknown key for kind = \"frf\""),
            std::string::npos);
  EXPECT_NE(error_of(replace(kFrf, "points = 5", "points = 5\nratios = [1.0]")).find("give either ratios"),
            std::string::npos);
  EXPECT_NE(error_of(replace(kFrf, "steps_per_period = 32", "steps_per_period = 4")).find(
                "frf.steps_per_period: must be ≥ 8"),
            std::string::npos);
  EXPECT_NE(error_of(replace(kFrf, "sweep = \"both\"", "sweep = \"sideways\"")).find("frf.sweep"),
            std::string::npos);
  EXPECT_NE(error_of(replace(kFrf, "[frf]", "[frf]\ncolour = 1")).find("frf.colour: unknown key"),
            std::string::npos);
}

TEST(InputRecord, ReadsAndScalesARecordBesideTheModel) {
  const auto dir = std::filesystem::temp_directory_path() / "poundsim_input_record";
  std::filesystem::create_directories(dir);
  {
    std::ofstream f(dir / "quake.txt");
    f << "# time [s], acceleration [g]\n0.0 0.0\n0.01, 0.1\n0.02 -0.2\n";
  }
  const std::string text = replace(kDimensionless, "kind = \"harmonic\"\namplitude_g = 0.2\nratio = 0.8",
                                   "kind = \"record\"\nfile = \"quake.txt\"\nscale = 2.0\nunits = \"g\"");
  const RunInput in = read_input_string(text, "model.toml", dir);
  const auto& r = std::get<RecordExcitation>(in.excitation);
  ASSERT_EQ(r.time.size(), 3u);
  EXPECT_DOUBLE_EQ(r.acceleration[2], -0.2 * 2.0 * 9.81);
  EXPECT_DOUBLE_EQ(ground_acceleration(in.excitation, 0.015), 0.5 * (0.1 - 0.2) * 2.0 * 9.81);
  std::filesystem::remove_all(dir);
}

/// `message` contains `part`; a failure shows both.
::testing::AssertionResult has(const std::string& message, const std::string& part) {
  if (message.find(part) != std::string::npos) return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure() << "\"" << part << "\" not in \"" << message << "\"";
}

const std::string kTwoStoreys = R"([[frames]]
storeys = 2
mass = 1.0e5
stiffness = 1.0e8
damping_ratio = 0.05
[[frames]]
storeys = 2
mass = 1.0e5
stiffness = 2.0e8
damping_ratio = 0.05
[gap_elements]
gap = 0.02
restitution = 0.5
[excitation]
kind = "none"
[analysis]
kind = "time_history"
duration = 1.0
dt = 0.001
)";

// Defect 2: TOML integers are 64-bit; every one is range-checked before it is narrowed.
TEST(InputIntegers, SixtyFourBitValuesAreCheckedBeforeNarrowing) {
  EXPECT_TRUE(has(error_of(replace(kDimensionless, "storeys = [1, 3]", "storeys = [4294967297, 1]")),
                  "model.toml:3:11: model.storeys: frame 1: must be ≤ 1000 (got 4294967297)"));
  EXPECT_TRUE(has(error_of(replace(kDimensionless, "storeys = [1, 3]", "storeys = [2147483648, 1]")),
                  "model.storeys: frame 1: must be ≤ 1000 (got 2147483648)"));
  EXPECT_TRUE(has(error_of(replace(kDimensionless, "storeys = [1, 3]", "storeys = [1, -4294967295]")),
                  "model.storeys: frame 2: must be ≥ 1 (got -4294967295)"));
  EXPECT_TRUE(has(error_of(replace(kTwoStoreys, "storeys = 2", "storeys = 4294967297")),
                  "model.toml:2:11: frames[1].storeys: must be ≤ 1000 (got 4294967297)"));
  EXPECT_TRUE(has(error_of(kTwoStoreys + "[[gap_elements.override]]\nframes = [1, 2]\nfloor = 4294967297\n"),
                  "gap_elements.override[1].floor: must be ≤ 2 (got 4294967297): frames 1 and 2 share floors 1..2"));
  EXPECT_TRUE(has(error_of(kTwoStoreys + "[[gap_elements.override]]\nframes = [4294967297, 4294967298]\nfloor = 1\n"),
                  "gap_elements.override[1].frames: item 1: must be ≤ 2 (got 4294967297)"));
  EXPECT_TRUE(has(error_of(kFrf, {"frf.points=4294967297"}),
                  "model.toml: --set frf.points=4294967297: frf.points: must be ≤ 1000000 (got 4294967297)"));
  EXPECT_TRUE(has(error_of(kFrf, {"frf.steps_per_period=4294967304"}), "frf.steps_per_period: must be ≤ 1000000"));
  EXPECT_TRUE(has(error_of(kFrf, {"frf.threads=4294967297"}), "frf.threads: must be ≤ 1024 (got 4294967297)"));
  EXPECT_TRUE(has(error_of(kDimensionless, {"model.storeys=[4294967297, 1]"}),
                  "--set model.storeys=[4294967297, 1]: model.storeys: frame 1: must be ≤ 1000"));
  // The values the bounds allow still read exactly.
  EXPECT_EQ(read(kFrf, {"frf.points=1000000", "analysis.max_steps=1e15"}).frf->ratios.size(), 1000000u);
  EXPECT_EQ(read(replace(kDimensionless, "storeys = [1, 3]", "storeys = [1, 1000]")).model.frames[1].storeys(), 1000);
}

// Defect 5: sizes that would allocate without bound are refused, naming the key, before any
// allocation.
TEST(InputLimits, SizesAreBoundedBeforeAnythingIsAllocated) {
  EXPECT_TRUE(has(error_of(replace(kDimensionless, "storeys = [1, 3]", "storeys = [100000, 1]")),
                  "model.storeys: frame 1: must be ≤ 1000 (got 100000)"));
  EXPECT_TRUE(has(error_of(replace(kFrf, "points = 5", "points = 2147483647")),
                  "frf.points: must be ≤ 1000000 (got 2147483647)"));
  std::string three = replace(replace(kTwoStoreys, "storeys = 2", "storeys = 1000"), "storeys = 2", "storeys = 1000");
  three = replace(three, "[gap_elements]", "[[frames]]\nstoreys = 1\nmass = 1.0\nstiffness = 1.0\ndamping = 0.0\n[gap_elements]");
  EXPECT_TRUE(has(error_of(three), "frames[3]: the frames up to this one have 2001 floors: at most 2000 in all"));
  std::string many;
  for (int i = 0; i < 101; ++i) many += "[[frames]]\nstoreys = 1\nmass = 1.0\nstiffness = 1.0\ndamping = 0.0\n";
  EXPECT_TRUE(has(error_of(many + "[gap_elements]\ngap = 0.0\nrestitution = 1.0\n"), "frames: 101 frames: at most 100"));
  EXPECT_TRUE(has(error_of(kFrf, {"frf.max_periods=2000000000"}), "frf.max_periods: must be ≤ 1000000 (got 2000000000)"));
}

// Defect 4: a run's steps, and history rows, are bounded by analysis.max_steps (default 1e8).
TEST(InputWork, StepsBeyondMaxStepsAreRejectedUnlessRaised) {
  EXPECT_TRUE(has(error_of(kDimensionless, {"analysis.duration=1e300", "analysis.dt=1.0"}),
                  "model.toml: --set analysis.duration=1e300: analysis.duration: dt = 1 s over the duration 1e+300 s "
                  "makes 1e+300 steps, more than analysis.max_steps = 1e+08"));
  EXPECT_TRUE(has(error_of(replace(kDimensionless, "dt = 0.001", "dt = 1e-9"), {"analysis.duration=100.0"}),
                  "makes 1e+11 steps, more than analysis.max_steps = 1e+08"));
  // 1e9 steps: refused by default, accepted (only read here) when the file raises the bound.
  const std::string long_run = replace(kDimensionless, "dt = 0.001", "dt = 1e-7");
  EXPECT_TRUE(has(error_of(long_run, {"analysis.duration=100.0"}), "more than analysis.max_steps"));
  EXPECT_DOUBLE_EQ(read(long_run, {"analysis.duration=100.0", "analysis.max_steps=1e9"}).analysis.max_steps, 1e9);
  EXPECT_TRUE(has(error_of(kDimensionless, {"analysis.max_steps=1000"}), "makes 2000 steps, more than analysis.max_steps = 1000"));
  EXPECT_TRUE(has(error_of(kDimensionless, {"analysis.max_steps=0"}), "analysis.max_steps: must be in [1, 1e+15] (got 0)"));
  EXPECT_TRUE(has(error_of(kDimensionless, {"analysis.max_steps=1e300"}), "analysis.max_steps: must be in [1, 1e+15]"));
  // A frequency response's worst case: 2 branches × 5 points × (600 + 64) periods × 32 steps.
  EXPECT_TRUE(has(error_of(kFrf, {"analysis.max_steps=212479"}),
                  "frf: 5 frequencies × 2 branch(es) × (600 max_periods + 64 window_periods) × 32 steps_per_period "
                  "may take 2.125e+05 steps, more than analysis.max_steps = 2.125e+05"));
  EXPECT_NO_THROW(read(kFrf, {"analysis.max_steps=212480"}));
}

// Defect 6: event_tolerance = 1e-20 used to pass and fail at run time; its floor is 64 spacings of
// doubles within the longest step.
TEST(InputEventTolerance, HasAFloorOfSixtyFourSpacingsWithinTheStep) {
  EXPECT_TRUE(has(error_of(kDimensionless, {"analysis.event_tolerance=1e-20"}),
                  "analysis.event_tolerance: 1e-20 s is finer than doubles can resolve within a step of 0.001 s "
                  "(analysis.dt): at least 1.42e-17 s"));
  const double floor = 64 * std::numeric_limits<double>::epsilon() * 0.001;
  EXPECT_EQ(read(kDimensionless, {"analysis.event_tolerance=" + toml_float(floor)}).analysis.options.event_tolerance, floor);
  EXPECT_TRUE(has(error_of(kDimensionless, {"analysis.event_tolerance=" + toml_float(std::nextafter(floor, 0.0))}),
                  "is finer than doubles can resolve"));
  // A frequency response: the longest step is the lowest frequency's period over steps_per_period.
  EXPECT_TRUE(has(error_of(kFrf, {"analysis.event_tolerance=1e-20"}), "finer than doubles can resolve within a step of"));
}

// Defect 6: messages name the place that is wrong, and never an empty key.
TEST(InputMessages, NameThePlaceThatIsWrong) {
  const std::string empty = error_of("");
  EXPECT_EQ(empty.rfind("model.toml: missing the structure: [model]", 0), 0u) << empty;
  EXPECT_EQ(empty.find(": :"), std::string::npos) << empty;
  EXPECT_EQ(error_of(kDimensionless, {"a.b=1"}), "model.toml: --set a.b=1: a: unknown table");
  EXPECT_TRUE(has(error_of(kDimensionless, {"model.x=1e309"}),
                  "model.toml: --set model.x=1e309: model.x: the value is not valid TOML"));
  EXPECT_TRUE(has(error_of(kDimensionless, {"model.dimensionless.eta=1e309"}), "the value is not valid TOML"));
  EXPECT_TRUE(has(error_of(kDimensionless, {"model.storeys=[1,"}), "--set model.storeys=[1,: model.storeys: the value is not valid TOML"));
  EXPECT_EQ(error_of(kDimensionless, {"analysis.dt=0.01\nanalysis.duration=-1"}),
            "model.toml: --set analysis.dt=0.01\\nanalysis.duration=-1: the override contains a line break");
  EXPECT_TRUE(has(error_of(kDimensionless, {std::string("title=a\x01", 8) + "b"}), "the override contains a control character"));
  EXPECT_TRUE(has(error_of(kPhysical, {"frames[2][3].mass=1.0"}), "'2][3' is not an index"));
  EXPECT_TRUE(has(error_of(kDimensionless, {"analysis.dt.=1"}), "--set analysis.dt.=1: empty key segment"));
  // A setting is a value, never a whole table (it would silently drop the table's other keys).
  EXPECT_EQ(error_of(kDimensionless, {"excitation={kind=\"none\"}"}),
            "model.toml: --set excitation={kind=\"none\"}: excitation: a table cannot be set as a whole: set its keys one by one");
  // Bare words are strings; quoted strings keep their blanks.
  EXPECT_EQ(read(kDimensionless, {"analysis.separation=force"}).analysis.options.separation, SeparationCriterion::force);
  EXPECT_EQ(read(kDimensionless, {"title=\"a b\""}).title, "a b");
  EXPECT_TRUE(has(error_of(kDimensionless, {"title=a b"}), "--set title=a b: title: the value is not valid TOML"));
}

// Defect 6: a record scaled beyond the range of a double names excitation.scale.
TEST(InputRecord, ScaleThatOverflowsNamesTheKey) {
  const auto dir = std::filesystem::temp_directory_path() / "poundsim_input_scale";
  std::filesystem::create_directories(dir);
  std::ofstream(dir / "quake.txt") << "0.0 0.0\n0.01 0.1\n0.02 -0.2\n";
  const std::string text = replace(kDimensionless, "kind = \"harmonic\"\namplitude_g = 0.2\nratio = 0.8",
                                   "kind = \"record\"\nfile = \"quake.txt\"\nunits = \"g\"\nscale = 1e308");
  std::string message;
  try {
    read_input_string(text, "model.toml", dir);
  } catch (const InputError& e) {
    message = e.what();
  }
  EXPECT_TRUE(has(message, "model.toml:19:9: excitation.scale:"));
  EXPECT_TRUE(has(message, "quake.txt"));
  EXPECT_THROW(read_input_string(replace(text, "scale = 1e308", "scale = 0.0"), "model.toml", dir), InputError);
  EXPECT_EQ(read_input_string(replace(text, "scale = 1e308", "scale = -2.0"), "model.toml", dir).excitation_info.record_scale, -2.0);
  std::filesystem::remove_all(dir);
}

// Defect 5: only a regular model file of at most 16 MiB is read, and never more than that.
TEST(InputFile, OnlyRegularFilesOfBoundedSizeAreRead) {
  const auto dir = std::filesystem::temp_directory_path() / "poundsim_input_file";
  std::filesystem::create_directories(dir / "model.toml");
  const auto message = [](const std::filesystem::path& p) {
    try {
      read_input(p);
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("(no error)");
  };
  EXPECT_EQ(message(dir / "model.toml"), (dir / "model.toml").string() + ": cannot read the model file: a directory");
  EXPECT_EQ(message("/dev/zero"), "/dev/zero: cannot read the model file: not a regular file");
  {
    std::ofstream big(dir / "big.toml");
    big << "title = \"" << std::string((16u << 20) - 10, 'x') << "\"\n";
  }
  EXPECT_EQ(message(dir / "big.toml"), (dir / "big.toml").string() + ": the model file is larger than 16 MiB");
  std::filesystem::remove_all(dir);
}

// Defect 12: the joint between the buildings can be wider than the element's gap.
TEST(InputJoint, WidthDefaultsToTheGapAndMustHoldTheElement) {
  const RunInput plain = read(kTwoStoreys);
  EXPECT_EQ(plain.joint_widths, (std::vector<double>{0.02, 0.02}));  // the gap: results as before
  const std::string bumper = replace(kTwoStoreys, "restitution = 0.5",
                                     "restitution = 0.5\nstiffness = 1.0e7\nshortening = 0.01\njoint_width = 0.04");
  EXPECT_EQ(read(bumper).joint_widths, (std::vector<double>{0.04, 0.04}));
  EXPECT_EQ(parameters_of<PaperGap>(read(bumper).model.gaps[0]).gap, 0.02);  // the element itself is unchanged
  // An override inherits the joint, or gives its own.
  const RunInput over = read(bumper + "[[gap_elements.override]]\nframes = [1, 2]\nfloor = 2\njoint_width = 0.05\n");
  EXPECT_EQ(over.joint_widths, (std::vector<double>{0.04, 0.05}));
  // 0.1 + 0.2 rounds above 0.3: a joint of exactly the stroke written in decimals still fits.
  const std::string exact = replace(replace(replace(bumper, "gap = 0.02", "gap = 0.1"), "shortening = 0.01", "shortening = 0.2"),
                                    "joint_width = 0.04", "joint_width = 0.3");
  EXPECT_EQ(read(exact).joint_widths[0], 0.3);
  EXPECT_TRUE(has(error_of(replace(bumper, "joint_width = 0.04", "joint_width = 0.025")),
                  "gap_elements.joint_width: the joint width 0.025 m is narrower than gap + shortening = 0.03 m"));
  EXPECT_TRUE(has(error_of(bumper + "[[gap_elements.override]]\nframes = [1, 2]\nfloor = 2\nshortening = 0.03\n"),
                  "gap_elements.override[1].shortening: the joint width 0.04 m is narrower than gap + shortening = 0.05 m"));
  // Dimensionless: w̄ = w λ²/g like δ̄, at least δ̄ + ε̄.
  const RunInput d = read(replace(kDimensionless, "restitution = 0.75", "restitution = 0.75\njoint_width = 1.0"));
  EXPECT_DOUBLE_EQ(d.joint_widths[0], 1.0 * 9.81 / 200);
  EXPECT_EQ(read(kDimensionless).joint_widths[0], parameters_of<PaperGap>(read(kDimensionless).model.gaps[0]).gap);
  EXPECT_TRUE(has(error_of(replace(kDimensionless, "restitution = 0.75", "restitution = 0.75\njoint_width = 0.5")),
                  "model.dimensionless.joint_width: 0.5 is narrower than delta + epsilon = 0.75"));
}

// Defect 13: gap elements join floors at the same height; frames whose floors stand at different
// heights are refused until such contact is modelled.
TEST(InputHeights, JoinedFloorsMustStandAtTheSameHeight) {
  const auto heights = [&](const std::string& left, const std::string& right) {
    std::string text = kTwoStoreys;
    text = replace(text, "damping_ratio = 0.05\n[[frames]]", "damping_ratio = 0.05\n" + left + "[[frames]]");
    return replace(text, "damping_ratio = 0.05\n[gap_elements]", "damping_ratio = 0.05\n" + right + "[gap_elements]");
  };
  EXPECT_NO_THROW(read(heights("storey_height = 3.0\n", "storey_height = [3.0, 3.0]\n")));
  EXPECT_NO_THROW(read(heights("storey_height = 3.0\n", "storey_height = 3.000000000001\n")));  // rounding
  EXPECT_TRUE(has(error_of(heights("storey_height = 3.0\n", "storey_height = 3.5\n")),
                  "frames[2].storey_height: floor 1 stands 3.5 m above the ground, floor 1 of frame 1 3 m"));
  EXPECT_TRUE(has(error_of(heights("storey_height = [3.0, 3.0]\n", "storey_height = [3.0, 3.5]\n")),
                  "floor 2 stands 6.5 m above the ground"));
  EXPECT_TRUE(has(error_of(heights("storey_height = 3.0\n", "")),
                  "model.toml:7:1: frames[2]: missing key: storey_height (frame 1 has one)"));
  EXPECT_NO_THROW(read(heights("", "")));  // no heights: taken as level
}


TEST(InputIntegration, RestVelocityRatioReachesTheSimulatorAndIsBounded) {
  EXPECT_EQ(read(kPhysical).analysis.options.rest_velocity_ratio, 1e-4);  // the documented default
  EXPECT_EQ(read(kPhysical, {"analysis.rest_velocity_ratio=0"}).analysis.options.rest_velocity_ratio, 0.0);
  EXPECT_EQ(read(kPhysical, {"analysis.rest_velocity_ratio=0.01"}).analysis.options.rest_velocity_ratio, 0.01);
  const std::string message = error_of(kPhysical, {"analysis.rest_velocity_ratio=-1e-3"});
  EXPECT_NE(message.find("rest_velocity_ratio"), std::string::npos) << message;
  EXPECT_NE(message.find("must be in [0, 1)"), std::string::npos) << message;
}

}  // namespace
}  // namespace poundsim::io
