// The echoed input (to_toml, DIR/input.toml): the input as run, written by one writer from the
// declared fields; reading it back gives the same input, and running it the same outputs.

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "poundsim/io/ground_motion.hpp"
#include "poundsim/io/input.hpp"
#include "poundsim/io/study_run.hpp"
#include "poundsim/io/time_history_run.hpp"
#include "../test_files.hpp"

namespace poundsim::io {
namespace {

namespace fs = std::filesystem;

std::vector<fs::path> example_files() {
  std::vector<fs::path> files;
  for (const char* folder : {"examples", "examples/paper", "examples/contact_laws"}) {
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
    EXPECT_EQ(a.frames[f].ground_damping, b.frames[f].ground_damping) << name;
    EXPECT_EQ(a.frames[f].modal_damping_ratios, b.frames[f].modal_damping_ratios) << name;
    EXPECT_EQ(a.frames[f].storey_law, b.frames[f].storey_law) << name;
  }
  ASSERT_EQ(a.gaps.size(), b.gaps.size()) << name;
  for (std::size_t k = 0; k < a.gaps.size(); ++k) {
    EXPECT_EQ(a.gaps[k].left_frame, b.gaps[k].left_frame) << name;
    EXPECT_EQ(a.gaps[k].floor, b.gaps[k].floor) << name;
    EXPECT_EQ(a.gaps[k].law, b.gaps[k].law) << name << " element " << k;  // its law and every parameter
  }
}

// Every example and paper figure: the echo reads back to an input whose echo is the same text
// (every value written is the value read, to the bit: doubles are written in their shortest
// exact form), with the same model, joints, excitation and settings.
TEST(InputEcho, EveryExampleReadsBackToTheInputThatRan) {
  const std::vector<fs::path> files = example_files();
  ASSERT_EQ(files.size(), 26u);  // 14 examples, the 7 figures and the 5 contact laws
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
        for (const GapElement& g : r.model.gaps) w.push_back(g.gap());
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

// A study's and an optimiser's echo is the file as written (to_toml_as_written): its axes and
// variables name keys of the dimensionless form, which to_toml would rewrite into the physical
// one. Read from another folder, every point has the model it had, with the --set applied.
TEST(InputEcho, StudiesAndOptimisationsEchoTheFileAsWritten) {
  const fs::path elsewhere = fs::temp_directory_path() / "poundsim_echo_as_written";
  fs::remove_all(elsewhere);
  fs::create_directories(elsewhere);
  for (const char* example : {"study_eta_mu.toml", "optimize_gap_elements.toml", "optimize_ensemble.toml"}) {
    const fs::path file = fs::path(POUNDSIM_SOURCE_DIR) / "examples" / example;
    const RunInput in = read_input(file, std::vector<std::string>{"model.dimensionless.xi=0.04"});
    const std::string text = to_toml_as_written(in);
    EXPECT_NE(text.find("[model.dimensionless]"), std::string::npos) << example;
    const fs::path echo = elsewhere / example;
    std::ofstream(echo) << text;
    const RunInput again = read_input(echo);
    expect_same_model(in.model, again.model, example);
    EXPECT_EQ(again.dimensionless->xi, 0.04) << example;
    if (in.ensemble) {
      EXPECT_EQ(in.ensemble->records, again.ensemble->records) << example;
    }
    // The points: each axis value applied to both gives the same model.
    std::vector<Setting> values;
    if (in.study) {
      values = study_points(*in.study).back();
    } else {
      for (const OptimizeVariable& v : in.optimize->variables) values.push_back(make_setting(v.key, {0.5 * (v.min + v.max)}));
    }
    expect_same_model(with_settings(in, values).model, with_settings(again, values).model, example);
  }
  fs::remove_all(elsewhere);
}

// A study axis over a path (ensemble.folder, excitation.file) names files relative to the study's
// file: the echo, written elsewhere, names them absolute, so that each point finds its records.
TEST(InputEcho, AStudyAxisOverAFolderIsEchoedAbsolute) {
  const fs::path elsewhere = fs::temp_directory_path() / "poundsim_echo_folder_axis";
  fs::remove_all(elsewhere);
  fs::create_directories(elsewhere);
  const fs::path examples = fs::path(POUNDSIM_SOURCE_DIR) / "examples";
  std::ifstream in_file(examples / "ensemble_fig2_frames.toml");
  std::string text((std::istreambuf_iterator<char>(in_file)), std::istreambuf_iterator<char>());
  text.replace(text.find("kind = \"ensemble\""), 17, "kind = \"study\"");
  text += "\n[study]\neach = \"ensemble\"\nsampling = \"list\"\n"
          "[[study.parameter]]\nkey = \"ensemble.folder\"\nvalues = [\"../data/ground_motions\", \"records\"]\n"
          "[[study.parameter]]\nkey = \"ensemble.pattern\"\nvalues = [\"*.AT2\", \"*.txt\"]\n";
  const RunInput in = read_input_string(text, (examples / "folder_study.toml").string(), examples);
  const fs::path echo = elsewhere / "input.toml";
  std::ofstream(echo) << to_toml_as_written(in);
  const RunInput again = read_input(echo);
  const std::vector<PointValues> points = study_points(*again.study);
  ASSERT_EQ(points.size(), 2U);
  for (std::size_t k = 0; k < points.size(); ++k) {
    const RunInput from_file = with_settings(in, study_points(*in.study)[k]);
    const RunInput from_echo = with_settings(again, points[k]);
    ASSERT_TRUE(from_echo.ensemble.has_value());
    EXPECT_EQ(from_echo.ensemble->records, from_file.ensemble->records) << "point " << k + 1;
  }
  EXPECT_EQ(with_settings(again, points[1]).ensemble->records.size(), 1U);  // examples/records/
  fs::remove_all(elsewhere);
}

/// What read_input_document says of `document` named `name`: its InputError, or "no error".
std::string document_error(const nlohmann::json& document, const std::string& name) {
  try {
    static_cast<void>(read_input_document(document, name, "."));
  } catch (const InputError& e) {
    return e.what();
  }
  return "no error";
}

// A model given as a document (the Python module's dicts, docs/python.md): every example's file
// as written, as JSON, reads to the same input — its echo is the file's echo, to the bit.
TEST(InputDocument, EveryExampleReadsFromItsDocument) {
  for (const fs::path& file : example_files()) {
    const RunInput in = read_input(file);
    const nlohmann::json document = input_document(in);
    RunInput again;
    try {
      again = read_input_document(document, "document", file.parent_path());
    } catch (const InputError& e) {
      ADD_FAILURE() << file << ": the document does not read back: " << e.what() << "\n" << document.dump(2);
      continue;
    }
    EXPECT_EQ(to_toml(again), to_toml(in)) << file;
    expect_same_model(in.model, again.model, file.string());
    EXPECT_EQ(input_document(again), document) << file;
  }
}

// The document's errors are a file's, naming the key (and `name` for the file); JSON values
// that are no TOML value are refused naming their path; an integer stays an integer.
TEST(InputDocument, ErrorsNameTheKeyAsForAFile) {
  nlohmann::json document = input_document(read_input(fs::path(POUNDSIM_SOURCE_DIR) / "examples/fig2c_ratio0.8.toml"));
  const auto message = [](const nlohmann::json& d) { return document_error(d, "built in Python"); };
  nlohmann::json bad = document;
  bad["analysis"]["dt"] = -0.001;
  EXPECT_NE(message(bad).find("built in Python: analysis.dt: must be > 0"), std::string::npos) << message(bad);
  bad = document;
  bad["analysis"]["dtt"] = 0.1;
  EXPECT_NE(message(bad).find("analysis.dtt"), std::string::npos) << message(bad);
  bad = document;
  bad["analysis"]["duration"] = nullptr;
  EXPECT_NE(message(bad).find("built in Python: analysis.duration: None (null) is not a value of a model file"),
            std::string::npos) << message(bad);
  EXPECT_NE(message(nlohmann::json::array()).find("a model is a table of tables"), std::string::npos);
  bad = document;
  bad["model"]["storeys"] = {1.0, 1};  // a float where a count goes, as in a file
  EXPECT_NE(message(bad).find("model.storeys"), std::string::npos) << message(bad);
}

// A record given as samples (excitation.acceleration with dt and units) is the record of a file
// of the same numbers: the same accelerations and scale; its echo writes the samples back.
TEST(InputDocument, ARecordAsSamplesIsTheFilesRecord) {
  const fs::path file = fs::path(POUNDSIM_SOURCE_DIR) / "examples/three_buildings_el_centro.toml";
  const RunInput from_file = read_input(file);
  const auto& recorded = std::get<RecordExcitation>(from_file.excitation);
  nlohmann::json document = input_document(from_file);
  nlohmann::json& e = document["excitation"];
  e.erase("file");
  e["dt"] = 0.01;
  // The file's own numbers (in g), which the reader scales as it scales the file's.
  e["acceleration"] = nlohmann::json::array();
  std::ifstream in(from_file.excitation_info.record_file);
  for (std::string line; std::getline(in, line);) {
    if (line.empty() || line[0] == '#') continue;
    std::istringstream fields(line);
    double t = 0, a = 0;
    fields >> t >> a;
    e["acceleration"].push_back(a);
  }
  const RunInput samples = read_input_document(document, "samples", ".");
  const auto& given = std::get<RecordExcitation>(samples.excitation);
  ASSERT_EQ(given.acceleration.size(), recorded.acceleration.size());
  EXPECT_EQ(given.acceleration, recorded.acceleration);  // the same numbers, scaled alike, to the bit
  for (std::size_t k = 0; k < given.time.size(); ++k) EXPECT_NEAR(given.time[k], recorded.time[k], 1e-12);
  EXPECT_EQ(samples.excitation_info.record_scale, from_file.excitation_info.record_scale);
  EXPECT_EQ(samples.excitation_info.record_pga_g, from_file.excitation_info.record_pga_g);
  EXPECT_EQ(samples.excitation_info.record_format, "samples");
  const RunInput echoed = read_input_string(to_toml(samples), "input.toml", ".");
  EXPECT_EQ(std::get<RecordExcitation>(echoed.excitation).acceleration, given.acceleration);

  const auto message = [](const nlohmann::json& d) { return document_error(d, "m"); };
  nlohmann::json bad = document;
  bad["excitation"]["file"] = "x.txt";
  EXPECT_NE(message(bad).find("excitation.file: not with acceleration"), std::string::npos) << message(bad);
  bad = document;
  bad["excitation"].erase("units");
  EXPECT_NE(message(bad).find("missing key: units"), std::string::npos) << message(bad);
  bad = document;
  bad["excitation"].erase("dt");
  EXPECT_NE(message(bad).find("missing key: dt"), std::string::npos) << message(bad);
  bad = document;
  bad["excitation"]["acceleration"] = {0.1};
  EXPECT_NE(message(bad).find("excitation.acceleration: expected an array of at least two"), std::string::npos)
      << message(bad);
  bad = document;
  bad["excitation"]["acceleration"][3] = "x";
  EXPECT_NE(message(bad).find("excitation.acceleration: item 4 must be a number"), std::string::npos) << message(bad);
}

}  // namespace
}  // namespace poundsim::io
