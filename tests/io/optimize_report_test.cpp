// The optimiser's report and evaluations.csv: the optimum and bare pounding compared by the same
// measure, the objective's; every CSV field (evaluations.csv, study.csv, export) readable back per
// RFC 4180.

#include <sys/wait.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "poundsim/optimize/optimize_run.hpp"
#include "poundsim/io/output_files.hpp"
#include "poundsim/io/study_run.hpp"
#include "../test_files.hpp"
#include "../test_models.hpp"

namespace poundsim::io {
namespace {

using optimize::OptimizationResult;
using optimize::run_optimization;

namespace fs = std::filesystem;
using poundsim::testing::slurp;

fs::path fresh(const std::string& name) { return poundsim::testing::fresh_folder("optimize_report_" + name); }



/// The records of a CSV text read per RFC 4180 (quoted fields, "" for a quote inside one).
std::vector<std::vector<std::string>> read_csv(const std::string& text) {
  std::vector<std::vector<std::string>> records;
  std::vector<std::string> record;
  std::string field;
  bool quoted = false, was_quoted = false;
  for (std::size_t i = 0; i < text.size(); ++i) {
    const char c = text[i];
    if (quoted) {
      if (c != '"') {
        field += c;
      } else if (i + 1 < text.size() && text[i + 1] == '"') {
        field += '"';
        ++i;
      } else {
        quoted = false;
      }
    } else if (c == '"') {
      EXPECT_TRUE(field.empty() && !was_quoted) << "a quote inside an unquoted field at byte " << i;
      quoted = was_quoted = true;
    } else if (c == ',' || c == '\n') {
      record.push_back(field);
      field.clear();
      was_quoted = false;
      if (c == '\n') {
        records.push_back(std::move(record));
        record.clear();
      }
    } else {
      EXPECT_FALSE(was_quoted) << "text after a closing quote at byte " << i;
      field += c;
    }
  }
  EXPECT_FALSE(quoted) << "an unterminated quoted field";
  return records;
}

std::string optimize_toml(const std::string& model, const std::string& objective, const std::string& variable) {
  return model + fmt::format(R"([analysis]
kind = "optimize"
[frf]
amplitude_g = 0.2
ratio_min = 0.4
ratio_max = 1.2
points = 9
[optimize]
each = "frf"
objective = "{}"
global = "GN_DIRECT_L"
local = "none"
global_evaluations = 8
threads = 2
[[optimize.variable]]
{}
)",
                             objective, variable);
}

TEST(OptimizeReport, ComparesTheOptimumWithBarePoundingByTheObjective) {
  const fs::path dir = fresh("ratio");
  std::ofstream(dir / "opt.toml") << optimize_toml(testing::model_toml("[1, 1]", testing::fig2('c')),
                                                   "max_ratio_to_free",
                                                   "key = \"model.dimensionless.mu\"\nmin = 0.0\nmax = 3.0\nstart = 0.1");
  const std::string command =
      fmt::format("{} run {} --out {} 2>&1", POUNDSIM_CLI, (dir / "opt.toml").string(), (dir / "out").string());
  std::FILE* pipe = popen(command.c_str(), "r");
  std::string output;
  char buffer[4096];
  while (std::fgets(buffer, sizeof buffer, pipe) != nullptr) output += buffer;
  const int status = pclose(pipe);
  ASSERT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << output;

  const nlohmann::json s = nlohmann::json::parse(slurp(dir / "out" / "optimize.json"));
  const nlohmann::json& c = s["comparison"];
  const double optimum = s["objective"].get<double>();
  const double bare = c["bare_pounding"]["max_ratio_to_free"].get<double>();
  // Measured as the objective, the optimum beats bare pounding; bare pounding's base shear
  // (max_peak_V_W) is another measure, and larger.
  EXPECT_LT(optimum, bare);
  EXPECT_GT(c["bare_pounding"]["max_peak_V_W"].get<double>(), bare);
  // The console says which measure, and prints that measure for both.
  EXPECT_NE(output.find("objective max_ratio_to_free: the larger of the frames' peak V/W divided by the same "
                        "frame's peak without gap elements"),
            std::string::npos)
      << output;
  EXPECT_NE(output.find(fmt::format("{}: max_ratio_to_free = {:.4f}\n", s["optimum"].dump(), optimum)),
            std::string::npos)
      << output;
  std::istringstream lines(output);
  int bare_lines = 0;
  for (std::string line; std::getline(lines, line);) {
    if (line.find("bare pounding") == std::string::npos) continue;
    ++bare_lines;
    EXPECT_NE(line.find(fmt::format(": max_ratio_to_free = {:.4f}", bare)), std::string::npos) << line;
    EXPECT_EQ(line.find(fmt::format("{:.4f}", c["bare_pounding"]["max_peak_V_W"].get<double>())), std::string::npos)
        << line;
  }
  EXPECT_EQ(bare_lines, 1) << output;

  // The summary carries the objective's value for both, next to the full metrics.
  ASSERT_TRUE(c.contains("objective")) << c.dump();
  EXPECT_EQ(c["objective"]["metric"], "max_ratio_to_free");
  EXPECT_EQ(c["objective"]["optimum"], s["objective"]);
  EXPECT_EQ(c["objective"]["optimum"], c["optimum"]["max_ratio_to_free"]);
  EXPECT_EQ(c["objective"]["bare_pounding"], c["bare_pounding"]["max_ratio_to_free"]);
  fs::remove_all(dir);
}

TEST(OptimizeReport, EvaluationsCsvEscapesQuotesInMessages) {
  // A stroke ε = 0 in the file rejects every η > 0 the optimiser tries, with a message that names
  // the file, whose name holds a quote and a comma.
  DimensionlessParameters p = testing::fig2('c');
  p.eta = p.mu = p.epsilon = 0.0;
  const std::string source = "my \"design\", v2.toml";
  const RunInput input = read_input_string(
      optimize_toml(testing::model_toml("[1, 1]", p), "max_peak",
                    "key = \"model.dimensionless.eta\"\nmin = 0.0\nmax = 1.0\nstart = 0.0"),
      source, ".", {});
  const fs::path dir = fresh("csv");
  run_optimization(input, dir);
  const std::vector<std::vector<std::string>> records = read_csv(slurp(dir / "evaluations.csv"));
  ASSERT_GE(records.size(), 3u);
  EXPECT_EQ(records[0], (std::vector<std::string>{"evaluation", "stage", "model.dimensionless.eta", "objective",
                                                   "status", "error"}));
  int rejected = 0;
  for (std::size_t k = 1; k < records.size(); ++k) {
    ASSERT_EQ(records[k].size(), 6u) << "row " << k;
    if (records[k][4] != "rejected") {
      EXPECT_EQ(records[k][5], "") << "row " << k;
      continue;
    }
    ++rejected;
    EXPECT_EQ(records[k][5].rfind(source + ":", 0), 0u) << records[k][5];
    EXPECT_NE(records[k][5].find("model.dimensionless.epsilon"), std::string::npos) << records[k][5];
  }
  EXPECT_GE(rejected, 1);
  fs::remove_all(dir);
}

TEST(StudyCsv, TextValuesWithQuotesAndCommasReadBack) {
  // A list study over the title (any key can vary): its values land in study.csv and the export.
  const std::string text = testing::model_toml("[1, 1]", testing::fig2('c')) + R"([analysis]
kind = "study"
duration = 0.05
dt = 0.01
[excitation]
kind = "harmonic"
amplitude_g = 0.2
ratio = 0.8
[study]
each = "time_history"
sampling = "list"
baseline = false
[[study.parameter]]
key = "title"
values = ['say "hi", then', "plain", "two, commas, here"]
)";
  const fs::path dir = fresh("study");
  run_study(read_input_string(text, "study.toml", ".", {}), dir);
  export_study(dir / "study.sqlite", dir / "export.csv");
  EXPECT_EQ(slurp(dir / "export.csv"), slurp(dir / "study.csv"));
  const auto records = read_csv(slurp(dir / "study.csv"));
  ASSERT_EQ(records.size(), 4u);
  const std::vector<std::string> titles{"say \"hi\", then", "plain", "two, commas, here"};
  ASSERT_GE(records[0].size(), 3u);
  EXPECT_EQ(records[0][2], "title");
  for (std::size_t k = 1; k < records.size(); ++k) {
    EXPECT_EQ(records[k].size(), records[0].size()) << "row " << k;
    EXPECT_EQ(records[k][1], "done");
    EXPECT_EQ(records[k][2], titles[k - 1]);  // the value itself (before: its TOML text, quoted)
  }
  fs::remove_all(dir);
}

TEST(OutputFile, CsvFieldsFollowRfc4180) {
  const fs::path dir = fresh("fields");
  const std::vector<std::string> fields{"plain", "", "a,b", "say \"hi\"", "two\nlines", "\"", "cr\r"};
  {
    OutputTransaction out(dir);
    OutputFile& f = out.open("f.csv");
    for (std::size_t i = 0; i < fields.size(); ++i) {
      if (i > 0) f.character(',');
      f.csv_field(fields[i]);
    }
    f.character('\n');
    out.commit();
  }
  const std::string text = slurp(dir / "f.csv");
  EXPECT_EQ(text, "plain,,\"a,b\",\"say \"\"hi\"\"\",\"two\nlines\",\"\"\"\",\"cr\r\"\n");
  const auto records = read_csv(text);
  ASSERT_EQ(records.size(), 1u);
  EXPECT_EQ(records[0], fields);
  fs::remove_all(dir);
}

}  // namespace
}  // namespace poundsim::io
