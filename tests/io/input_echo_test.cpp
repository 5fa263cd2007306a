// The echoed input (to_toml, DIR/input.toml): the input as run, written by one writer from the
// declared fields; reading it back gives the same input, and running it the same outputs.

#include <algorithm>
#include <filesystem>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "poundsim/io/input.hpp"
#include "poundsim/io/time_history_run.hpp"
#include "../test_files.hpp"

namespace poundsim::io {
namespace {

namespace fs = std::filesystem;

std::vector<fs::path> example_files() {
  std::vector<fs::path> files;
  for (const char* folder : {"examples", "examples/paper"}) {
    for (const auto& entry : fs::directory_iterator(fs::path(POUNDSIM_SOURCE_DIR) / folder)) {
      if (entry.path().extension() == ".toml") files.push_back(entry.path());
    }
  }
  std::sort(files.begin(), files.end());
  return files;
}

void expect_same_model(const Model& a, const Model& b, const std::string& name) {
  ASSERT_EQ(a.frames.size(), b.frames.size()) << name;
  for (std::size_t f = 0; f < a.frames.size(); ++f) {
    EXPECT_EQ(a.frames[f].mass, b.frames[f].mass) << name;
    EXPECT_EQ(a.frames[f].stiffness, b.frames[f].stiffness) << name;
    EXPECT_EQ(a.frames[f].damping, b.frames[f].damping) << name;
    EXPECT_EQ(a.frames[f].storey_height, b.frames[f].storey_height) << name;
  }
  ASSERT_EQ(a.gaps.size(), b.gaps.size()) << name;
  for (std::size_t k = 0; k < a.gaps.size(); ++k) {
    const GapProperties &p = parameters_of<PaperGap>(a.gaps[k]), &q = parameters_of<PaperGap>(b.gaps[k]);
    EXPECT_EQ(a.gaps[k].left_frame, b.gaps[k].left_frame) << name;
    EXPECT_EQ(a.gaps[k].floor, b.gaps[k].floor) << name;
    EXPECT_EQ(p.gap, q.gap) << name;
    EXPECT_EQ(p.stiffness, q.stiffness) << name;
    EXPECT_EQ(p.damping, q.damping) << name;
    EXPECT_EQ(p.shortening, q.shortening) << name;
    EXPECT_EQ(p.restitution, q.restitution) << name;
  }
}

// Every example and paper figure: the echo reads back to an input whose echo is the same text
// (every value written is the value read, to the bit: doubles are written in their shortest
// exact form), with the same model, joints, excitation and settings.
TEST(InputEcho, EveryExampleReadsBackToTheInputThatRan) {
  const std::vector<fs::path> files = example_files();
  ASSERT_EQ(files.size(), 15u);  // 8 examples and the 7 figures
  for (const fs::path& file : files) {
    const RunInput in = read_input(file);
    const std::string text = to_toml(in);
    RunInput again;
    try {
      again = read_input_string(text, "input.toml", file.parent_path());
    } catch (const InputError& e) {
      ADD_FAILURE() << file << ": the echo does not read back: " << e.what() << "\n" << text;
      continue;
    }
    EXPECT_EQ(to_toml(again), text) << file;
    expect_same_model(in.model, again.model, file.string());
    const auto joints = [](const RunInput& r) {
      std::vector<double> w = r.joint_widths;
      if (w.empty()) {
        for (const GapElement& g : r.model.gaps) w.push_back(parameters_of<PaperGap>(g).gap);
      }
      return w;
    };
    EXPECT_EQ(joints(in), joints(again)) << file;
    EXPECT_EQ(in.analysis.kind, again.analysis.kind) << file;
    EXPECT_EQ(in.analysis.duration, again.analysis.duration) << file;
    EXPECT_EQ(in.analysis.options.dt, again.analysis.options.dt) << file;
    EXPECT_EQ(in.excitation_info.kind, again.excitation_info.kind) << file;
    EXPECT_EQ(in.excitation_info.omega, again.excitation_info.omega) << file;
    EXPECT_EQ(in.excitation_info.record_pga_g, again.excitation_info.record_pga_g) << file;
    EXPECT_EQ(in.frf.has_value(), again.frf.has_value()) << file;
    if (in.frf && again.frf) {
      EXPECT_EQ(in.frf->ratios, again.frf->ratios) << file;
    }
    EXPECT_EQ(in.study.has_value(), again.study.has_value()) << file;
    if (in.study && again.study) {
      EXPECT_EQ(in.study->parameters.size(), again.study->parameters.size()) << file;
    }
    EXPECT_EQ(in.ensemble.has_value(), again.ensemble.has_value()) << file;
    if (in.ensemble && again.ensemble) {
      EXPECT_EQ(in.ensemble->records, again.ensemble->records) << file;
    }
  }
}

// The echo of a run with --set: the settings are in it, and running it gives the same files.
TEST(InputEcho, RunningTheEchoGivesTheSameOutputs) {
  const fs::path example = fs::path(POUNDSIM_SOURCE_DIR) / "examples" / "three_buildings_el_centro.toml";
  const std::vector<std::string> settings{"analysis.duration=2.0", "gap_elements.stiffness=3.0e7",
                                          "gap_elements.shortening=0.01"};
  const RunInput in = read_input(example, settings);
  const fs::path first = fs::temp_directory_path() / "poundsim_echo_first";
  const fs::path second = fs::temp_directory_path() / "poundsim_echo_second";
  fs::remove_all(first);
  fs::remove_all(second);
  (void)run_time_history(in, first);
  ASSERT_TRUE(fs::exists(first / "input.toml"));
  const RunInput echo = read_input(first / "input.toml");
  EXPECT_EQ(echo.analysis.duration, 2.0);
  EXPECT_EQ(parameters_of<PaperGap>(echo.model.gaps.at(0)).stiffness, 3.0e7);
  (void)run_time_history(echo, second);
  for (const char* file : {"history.csv", "events.csv", "input.toml"}) {
    EXPECT_EQ(testing::slurp(first / file), testing::slurp(second / file)) << file;
  }
  fs::remove_all(first);
  fs::remove_all(second);
}

}  // namespace
}  // namespace poundsim::io
