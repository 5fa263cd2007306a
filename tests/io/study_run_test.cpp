// Parametric studies and the optimiser: sampling, resumption after a kill, determinism, reports.

#include "poundsim/io/study_run.hpp"

#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <csignal>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>
#include <thread>

#include <gtest/gtest.h>

#include "poundsim/error.hpp"
#include "poundsim/optimize/optimize_run.hpp"
#include "poundsim/io/study_database.hpp"
#include "../test_files.hpp"
#include "../test_models.hpp"

namespace poundsim::io {
namespace {

using optimize::OptimizationResult;
using optimize::run_optimization;

namespace fs = std::filesystem;
using poundsim::testing::slurp;

const std::string kStudy = testing::model_toml("[1, 1]", testing::fig2('c')) + R"([analysis]
kind = "study"
[frf]
amplitude_g = 0.2
ratio_min = 0.4
ratio_max = 1.2
points = 9
[study]
each = "frf"
threads = 2
[[study.parameter]]
key = "model.dimensionless.eta"
values = [0.0, 0.125, 0.25]
[[study.parameter]]
key = "model.dimensionless.mu"
min = 0.5
max = 2.0
points = 3
)";

RunInput read(const std::string& text, std::vector<std::string> overrides = {}) {
  return read_input_string(text, "study.toml", ".", overrides);
}

fs::path fresh(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / ("poundsim_study_" + name);
  fs::remove_all(dir);
  return dir;
}


TEST(StudyPoints, GridListAndRandomSampling) {
  const RunInput in = read(kStudy);
  const std::vector<PointValues> grid = study_points(*in.study);
  ASSERT_EQ(grid.size(), 9u);
  // The first parameter varies slowest; ranges are evenly spaced, values typed.
  const auto point = [](double eta, double mu) {
    return PointValues{make_setting("model.dimensionless.eta", {eta}), make_setting("model.dimensionless.mu", {mu})};
  };
  EXPECT_EQ(grid[0], point(0.0, 0.5));
  EXPECT_EQ(grid[1][1].text, "model.dimensionless.mu=1.25");
  EXPECT_EQ(grid[3][0].text, "model.dimensionless.eta=0.125");
  EXPECT_EQ(grid[8], point(0.25, 2.0));
  EXPECT_EQ(grid[8][1].text, "model.dimensionless.mu=2.0");  // a float stays a float

  StudySettings list = *in.study;
  list.sampling = Sampling::list;
  list.parameters[1].values = {{0.5}, {1.0}, {2.0}};
  const std::vector<PointValues> zipped = study_points(list);
  ASSERT_EQ(zipped.size(), 3u);
  EXPECT_EQ(zipped[2], point(0.25, 2.0));

  StudySettings random = *in.study;
  random.sampling = Sampling::random;
  random.samples = 50;
  random.seed = 7;
  random.parameters[0] = StudyParameter{};
  random.parameters[0].key = "model.dimensionless.eta";
  random.parameters[0].min = 0.01;
  random.parameters[0].max = 1.0;
  random.parameters[0].log = true;
  const std::vector<PointValues> a = study_points(random), b = study_points(random);
  ASSERT_EQ(a.size(), 50u);
  EXPECT_EQ(a, b);  // the same seed, the same points
  double smallest = 1, largest = 0;
  for (const PointValues& p : a) {
    const double eta = std::get<double>(p[0].value.value), mu = std::get<double>(p[1].value.value);
    EXPECT_GE(eta, 0.01);
    EXPECT_LE(eta, 1.0);
    EXPECT_GE(mu, 0.5);
    EXPECT_LE(mu, 2.0);
    smallest = std::min(smallest, eta);
    largest = std::max(largest, eta);
  }
  EXPECT_LT(smallest, 0.05);  // log-uniform: small values are as likely as large decades
  random.seed = 8;
  EXPECT_NE(study_points(random), a);
}

TEST(StudySettings, PointsAreTypedValuesOnTheParsedFile) {
  RunInput in = read(kStudy, {"frf.points=3"});
  // The point is built from the file as parsed: its text is never read again.
  in.text = "this is not TOML [";
  const double eta = 0.1 + 0.2;  // 0.30000000000000004: no short decimal reads back to it
  const std::vector<Setting> settings{make_setting("model.dimensionless.eta", {eta})};
  const RunInput point = with_settings(in, settings);
  EXPECT_EQ(point.dimensionless->eta, eta);  // the very double, not a decimal's rounding
  EXPECT_EQ(point.frf->ratios.size(), 3u);   // after the base's own --set
  ASSERT_EQ(point.settings.size(), 2u);
  EXPECT_EQ(point.settings[1].text, "model.dimensionless.eta=0.30000000000000004");
  // The same model as the command line's --set of that text, bit for bit.
  const RunInput typed = read(kStudy, {"frf.points=3", point.settings[1].text});
  ASSERT_EQ(point.model.gaps.size(), typed.model.gaps.size());
  for (std::size_t k = 0; k < point.model.gaps.size(); ++k) {
    EXPECT_EQ(parameters_of<PaperGap>(point.model.gaps[k]).stiffness, parameters_of<PaperGap>(typed.model.gaps[k]).stiffness);
    EXPECT_EQ(parameters_of<PaperGap>(point.model.gaps[k]).damping, parameters_of<PaperGap>(typed.model.gaps[k]).damping);
  }
  // A value the reader refuses names the setting; a key the file holds keeps its line and column.
  const auto error_of = [&](Setting setting) -> std::string {
    try {
      (void)with_settings(in, {&setting, 1});
    } catch (const InputError& e) {
      return e.what();
    }
    return "accepted";
  };
  const std::string negative = error_of(make_setting("model.dimensionless.mu", {-1.0}));
  EXPECT_EQ(negative.rfind("study.toml: --set model.dimensionless.mu=-1.0: model.dimensionless.mu:", 0), 0u) << negative;
  EXPECT_NE(error_of(make_setting("analysis.kind", {std::int64_t{3}})).find("--set analysis.kind=3: analysis.kind"),
            std::string::npos);
  EXPECT_NE(error_of(make_setting("frf.pionts", {std::int64_t{3}})).find("frf.pionts: unknown key"), std::string::npos);
}

TEST(StudyRun, ResumesWithoutLosingOrRepeatingPoints) {
  const RunInput in = read(kStudy);
  const fs::path whole = fresh("whole"), parts = fresh("parts");
  const nlohmann::json all = to_json(run_study(in, whole));
  EXPECT_TRUE(all["complete"].get<bool>());
  EXPECT_EQ(all["finished"], 9);

  StudyRunOptions some;
  some.max_points = 4;
  const nlohmann::json first = to_json(run_study(in, parts, some));
  EXPECT_FALSE(first["complete"].get<bool>());
  EXPECT_EQ(first["finished"], 4);
  const nlohmann::json rest = to_json(run_study(in, parts));
  EXPECT_TRUE(rest["complete"].get<bool>());
  EXPECT_EQ(rest["skipped_as_finished"], 4);
  EXPECT_EQ(rest["run_this_time"], 5);

  const StudyDatabase a(whole / "study.sqlite"), b(parts / "study.sqlite");
  const auto ra = a.rows(), rb = b.rows();
  ASSERT_EQ(ra.size(), 9u);
  ASSERT_EQ(rb.size(), 9u);
  for (std::size_t i = 0; i < ra.size(); ++i) {
    EXPECT_EQ(ra[i].id, rb[i].id);
    EXPECT_EQ(ra[i].parameters, rb[i].parameters);
    EXPECT_EQ(ra[i].metrics, rb[i].metrics);  // bit for bit: the same numbers, printed alike
  }
  // Gap elements beat bare pounding at some point of this grid, and every ratio is computed.
  double best = 10;
  for (const auto& r : ra) best = std::min(best, r.metrics["max_ratio_to_bare"].get<double>());
  EXPECT_LT(best, 0.9);
  fs::remove_all(whole);
  fs::remove_all(parts);
}

// A caller that asks a threaded study to stop (Ctrl-C in Python) gets RunStopped once the points
// running have finished: the database is whole (no -wal or -shm), holds those points, no table or
// summary is committed, and running again finishes the study with the uninterrupted one's numbers.
TEST(StudyRun, AStopRequestKeepsTheDatabaseWholeAndResumable) {
  const RunInput in = read(kStudy);
  const fs::path whole = fresh("stop_whole"), parts = fresh("stop_parts");
  static_cast<void>(run_study(in, whole));
  std::atomic<int> done{0};
  StudyRunOptions options;
  options.progress = [&](int count, int) {  // threads report out of order: keep the largest
    for (int seen = done; seen < count && !done.compare_exchange_weak(seen, count);) {
    }
  };
  options.stop_requested = [&] { return done >= 3; };  // no point starts once three are done
  EXPECT_THROW(static_cast<void>(run_study(in, parts, options)), RunStopped);
  EXPECT_FALSE(fs::exists(parts / "study.sqlite-wal"));
  EXPECT_FALSE(fs::exists(parts / "study.sqlite-shm"));
  EXPECT_FALSE(fs::exists(parts / "study.csv"));
  EXPECT_FALSE(fs::exists(parts / "summary.json"));
  std::size_t files = 0;
  for ([[maybe_unused]] const auto& entry : fs::directory_iterator(parts)) ++files;
  EXPECT_EQ(files, 1u);  // the database alone: no temporary left
  std::size_t stored = 0;
  {
    const StudyDatabase stopped(parts / "study.sqlite");
    stored = stopped.rows().size();  // three, or four when the other thread had started one
  }
  EXPECT_GE(stored, 3u);
  EXPECT_LE(stored, 4u);
  const StudyResult rest = run_study(in, parts);
  EXPECT_EQ(rest.skipped_as_finished, static_cast<long>(stored));
  EXPECT_TRUE(rest.complete());
  const StudyDatabase a(whole / "study.sqlite"), b(parts / "study.sqlite");
  const auto ra = a.rows(), rb = b.rows();
  ASSERT_EQ(rb.size(), ra.size());
  for (std::size_t i = 0; i < ra.size(); ++i) EXPECT_EQ(ra[i].metrics, rb[i].metrics);
  // A progress callback that throws RunStopped stops it the same way.
  const fs::path again = fresh("stop_progress");
  StudyRunOptions by_progress;
  by_progress.progress = [](int count, int) {
    if (count >= 2) throw RunStopped();
  };
  EXPECT_THROW(static_cast<void>(run_study(in, again, by_progress)), RunStopped);
  EXPECT_GE(StudyDatabase(again / "study.sqlite").rows().size(), 2u);
  EXPECT_FALSE(fs::exists(again / "study.sqlite-wal"));
  for (const fs::path& d : {whole, parts, again}) fs::remove_all(d);
}

// The study table is study.csv column for column: whole numbers as int64, numbers (NaN where a
// point has none), text; units from the names.
TEST(StudyRun, TheStudyTableIsTheCsvTyped) {
  const RunInput in = read(kStudy);
  const fs::path dir = fresh("table");
  const StudyResult r = run_study(in, dir);
  const Table table = study_table(r.parameters, r.rows);
  ASSERT_EQ(table.rows(), 9u);
  const auto column = [&](const std::string& name) -> const TableColumn& {
    for (const TableColumn& c : table.columns()) {
      if (c.name == name) return c;
    }
    throw std::logic_error(name);
  };
  EXPECT_EQ(std::get<TableColumn::Integers>(column("id").values).back(), 9);
  EXPECT_EQ(std::get<TableColumn::Numbers>(column("model.dimensionless.mu").values)[1], 1.25);
  EXPECT_EQ(column("max_peak_V_W").unit, "1");
  EXPECT_EQ(column("run_time_s").unit, "s");
  EXPECT_EQ(std::get<TableColumn::Texts>(column("status").values)[0], "done");
  // The CSV written from it is the file the study wrote.
  const fs::path again = dir / "again.csv";
  export_study(dir / "study.sqlite", again);
  EXPECT_EQ(slurp(again), slurp(dir / "study.csv"));
  fs::remove_all(dir);
}

TEST(StudyRun, PointsKeepTheOverridesOfTheirStudy) {
  // --set on the study applies to every point, under the point's own values.
  const RunInput in = read(kStudy, {"frf.points=3", "model.dimensionless.restitution=0.5"});
  const RunInput point = with_settings(in, study_points(*in.study)[4]);
  EXPECT_EQ(point.frf->ratios.size(), 3u);
  EXPECT_DOUBLE_EQ(parameters_of<PaperGap>(point.model.gaps[0]).restitution, 0.5);
  EXPECT_DOUBLE_EQ(parameters_of<PaperGap>(point.model.gaps[0]).stiffness, 0.125 * 200);
  const fs::path dir = fresh("overrides");
  StudyRunOptions one;
  one.max_points = 1;
  run_study(in, dir, one);
  EXPECT_EQ(StudyDatabase(dir / "study.sqlite").rows().at(0).metrics["points"], 3);
  fs::remove_all(dir);
}

TEST(StudyRun, SameResultsWhateverTheThreadCount) {
  const fs::path one = fresh("one"), two = fresh("two");
  run_study(read(kStudy, {"study.threads=1"}), one);
  run_study(read(kStudy, {"study.threads=3"}), two);
  const auto a = StudyDatabase(one / "study.sqlite").rows(), b = StudyDatabase(two / "study.sqlite").rows();
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t i = 0; i < a.size(); ++i) EXPECT_EQ(a[i].metrics, b[i].metrics);
  fs::remove_all(one);
  fs::remove_all(two);
}

TEST(StudyRun, RefusesTheDatabaseOfAnotherStudy) {
  const fs::path dir = fresh("other");
  StudyRunOptions one;
  one.max_points = 1;
  run_study(read(kStudy), dir, one);
  try {
    run_study(read(kStudy, {"frf.amplitude_g=0.3"}), dir);
    FAIL() << "a different study reused the database";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("different study"), std::string::npos) << e.what();
  }
  fs::remove_all(dir);
}

TEST(StudyRun, ABadParameterStopsTheStudyBeforeAnyPointRuns) {
  const fs::path dir = fresh("bad");
  std::string text = kStudy;
  text.replace(text.find("dimensionless.mu\""), 17, "dimensionless.muu\"");
  try {
    run_study(read(text), dir);
    FAIL() << "unknown key accepted";
  } catch (const InputError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("study point 1"), std::string::npos) << what;
    EXPECT_NE(what.find("model.dimensionless.muu: unknown key"), std::string::npos) << what;
  }
  EXPECT_FALSE(fs::exists(dir / "study.sqlite"));  // nothing written: the study can be fixed and rerun
  fs::remove_all(dir);
}

/// An example's time history as a study of `duration` over `axes` ([[study.parameter]] tables),
/// each point a time history without a baseline.
std::string as_study(const fs::path& example, const std::string& duration, const std::string& axes) {
  std::string text = slurp(example);
  const std::string analysis = "kind = \"time_history\"", whole = "duration = 20.0";
  text.replace(text.find(analysis), analysis.size(), "kind = \"study\"");
  text.replace(text.find(whole), whole.size(), "duration = " + duration);
  return text + "[study]\neach = \"time_history\"\nbaseline = false\n" + axes;
}

// The contact laws' and the frames' damping parameters are study axes like any key: a grid over
// Hertzdamp's restitution and damping model and a frame's modal damping runs every point, and
// each point's figures differ.
TEST(StudyRun, AxesOverContactLawAndDampingParameters) {
  const std::string text = as_study(fs::path(POUNDSIM_SOURCE_DIR) / "examples" / "contact_laws" / "hertzdamp.toml", "2.0",
                                    R"([[study.parameter]]
key = "gap_elements.restitution"
values = [0.5, 0.9]
[[study.parameter]]
key = "gap_elements.damping_model"
values = ["lankarani_nikravesh", "ye_li_zhu"]
[[study.parameter]]
key = "frames[1].modal_damping_ratios"
values = [0.0, 0.05]
)");
  const fs::path dir = fresh("laws");
  const nlohmann::json summary = to_json(run_study(read(text), dir));
  EXPECT_TRUE(summary["complete"].get<bool>());
  EXPECT_EQ(summary["finished"], 8);
  std::istringstream lines(slurp(dir / "study.csv"));
  std::string header;
  std::getline(lines, header);
  EXPECT_NE(header.find("gap_elements.restitution,gap_elements.damping_model,frames[1].modal_damping_ratios"),
            std::string::npos)
      << header;
  std::set<std::string> rows;
  for (std::string line; std::getline(lines, line);) rows.insert(line.substr(line.find(',') + 1));
  EXPECT_EQ(rows.size(), 8U);
  fs::remove_all(dir);
}

// The storeys' law and its parameters are axes like any key: a yield drift, and the law itself
// (both yielding laws read yield_drift and post_yield_ratio).
TEST(StudyRun, AxesOverStoreyLawsAndTheirParameters) {
  const std::string text = as_study(fs::path(POUNDSIM_SOURCE_DIR) / "examples" / "el_centro_5_and_8_storeys_bilinear.toml",
                                    "3.0", R"([[study.parameter]]
key = "frames[1].yield_drift"
values = [0.005, 0.02]
[[study.parameter]]
key = "frames[2].storey_law"
values = ["bilinear", "bouc_wen"]
)");
  const fs::path dir = fresh("storeys");
  const RunInput input = read_input_string(text, "study.toml", fs::path(POUNDSIM_SOURCE_DIR) / "examples");
  const nlohmann::json summary = to_json(run_study(input, dir));
  EXPECT_TRUE(summary["complete"].get<bool>());
  EXPECT_EQ(summary["finished"], 4);
  std::istringstream lines(slurp(dir / "study.csv"));
  std::string header;
  std::getline(lines, header);
  EXPECT_NE(header.find("frames[1].yield_drift,frames[2].storey_law"), std::string::npos) << header;
  std::set<std::string> rows;
  for (std::string line; std::getline(lines, line);) rows.insert(line.substr(line.find(',') + 1));
  EXPECT_EQ(rows.size(), 4U);  // four different responses
  fs::remove_all(dir);
}

// A study of buildings whose slabs strike columns, with its bare-pounding baseline: the elements
// between floors become rigid stops, the slabs on columns keep their contact law (a stop's impacts
// act between floors), and each facing pair has its own min_gap column (the right slab 4 and the
// left slab 5 share left floor 5: min_gap_1_5_3_m and min_gap_1_5_m).
TEST(StudyRun, SlabsOnColumnsKeepTheirContactLawInTheBareBaseline) {
  std::string text = as_study(fs::path(POUNDSIM_SOURCE_DIR) / "examples" / "slab_to_column.toml", "3.0",
                              "[[study.parameter]]\nkey = \"gap_elements.restitution\"\nvalues = [0.5, 0.8]\n");
  text.replace(text.find("baseline = false"), 16, "baseline = true");
  const RunInput input = read_input_string(text, "study.toml", fs::path(POUNDSIM_SOURCE_DIR) / "examples");
  const Model bare = bare_pounding_model(input);
  ASSERT_EQ(bare.gap_count(), 5);
  for (const GapElement& g : bare.gaps) {
    EXPECT_EQ(std::holds_alternative<Hertzdamp>(g.law), g.column.has_value()) << describe(g);
    EXPECT_EQ(g.gap(), 0.03) << describe(g);
  }
  EXPECT_NO_THROW(validate(bare));
  const fs::path dir = fresh("slabs");
  const nlohmann::json summary = to_json(run_study(input, dir));
  EXPECT_TRUE(summary["complete"].get<bool>());
  EXPECT_EQ(summary["finished"], 2);
  std::istringstream lines(slurp(dir / "study.csv"));
  std::string header;
  std::getline(lines, header);
  for (const char* column : {"min_gap_1_3_m", "min_gap_1_4_m", "min_gap_1_5_3_m", "min_gap_1_5_m", "min_gap_1_6_m",
                             "ratio_to_bare_1", "ratio_to_bare_2"}) {
    EXPECT_NE(header.find(column), std::string::npos) << column << " in " << header;
  }
  fs::remove_all(dir);
}

TEST(StudyRun, ExportWritesEveryPoint) {
  const fs::path dir = fresh("export");
  run_study(read(kStudy), dir);
  export_study(dir / "study.sqlite", dir / "again.csv");
  const std::string csv = slurp(dir / "again.csv");
  EXPECT_EQ(csv, slurp(dir / "study.csv"));
  std::istringstream lines(csv);
  std::string header;
  std::getline(lines, header);
  EXPECT_EQ(header.rfind("id,status,model.dimensionless.eta,model.dimensionless.mu,", 0), 0u) << header;
  EXPECT_NE(header.find(",max_ratio_to_bare,"), std::string::npos);
  int rows = 0;
  for (std::string line; std::getline(lines, line);) ++rows;
  EXPECT_EQ(rows, 9);
  EXPECT_THROW(export_study(dir / "missing.sqlite", dir / "x.csv"), InputError);
  fs::remove_all(dir);
}

TEST(StudyRun, AKilledStudyResumesWhereItStopped) {
  // A real SIGKILL in the middle of a study run by the command-line program.
  const fs::path dir = fresh("killed");
  fs::create_directories(dir);
  { std::ofstream(dir / "study.toml") << kStudy; }
  const std::string args = "run " + (dir / "study.toml").string() + " --quiet --out " + (dir / "out").string() +
                           " --set frf.points=41 --set frf.steps_per_period=256 --set study.threads=1";
  const pid_t child = fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    execl("/bin/sh", "sh", "-c", (std::string(POUNDSIM_CLI) + " " + args).c_str(), nullptr);
    _exit(127);
  }
  // Wait until some, not all, points are in the database, then kill.
  long seen = 0;
  for (int i = 0; i < 12000 && seen < 2; ++i) {  // up to 60 s: a sanitizer build on a loaded machine is slow
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
    if (fs::exists(dir / "out" / "study.sqlite")) {
      try {
        seen = static_cast<long>(StudyDatabase(dir / "out" / "study.sqlite").rows().size());
      } catch (const std::exception&) {
      }
    }
  }
  kill(child, SIGKILL);
  kill(-child, SIGKILL);
  int status = 0;
  waitpid(child, &status, 0);
  system(("pkill -9 -f '" + (dir / "study.toml").string() + "' 2>/dev/null").c_str());
  const long before = static_cast<long>(StudyDatabase(dir / "out" / "study.sqlite").rows().size());
  EXPECT_GE(before, 2);
  EXPECT_LT(before, 9) << "the study finished before the kill; make it slower";
  // Run again: the rest is computed, nothing is lost or repeated, and the results equal an
  // uninterrupted run's.
  ASSERT_EQ(system((std::string(POUNDSIM_CLI) + " " + args).c_str()), 0);
  const auto rows = StudyDatabase(dir / "out" / "study.sqlite").rows();
  ASSERT_EQ(rows.size(), 9u);
  for (std::size_t i = 0; i < rows.size(); ++i) EXPECT_EQ(rows[i].id, static_cast<long>(i));
  ASSERT_EQ(system((std::string(POUNDSIM_CLI) + " " + args.substr(0, args.find("--out")) + "--out " +
                    (dir / "clean").string() + args.substr(args.find(" --set"))).c_str()),
            0);
  const auto clean = StudyDatabase(dir / "clean" / "study.sqlite").rows();
  for (std::size_t i = 0; i < rows.size(); ++i) EXPECT_EQ(rows[i].metrics, clean[i].metrics);
  fs::remove_all(dir);
}

TEST(StudyRun, TimeHistoryPointsCompareWithFreeAndBareFrames) {
  // Each point a 5 s time history at ω̄/ω₁ = 0.8; the gap's width varies. Without contact
  // (a wide gap) the frames are the free ones: every ratio is exactly 1.
  std::string text = kStudy.substr(0, kStudy.find("[analysis]"));
  text += R"([analysis]
kind = "study"
duration = 5.0
dt = 0.002
[excitation]
kind = "harmonic"
amplitude_g = 0.2
ratio = 0.8
[study]
each = "time_history"
[[study.parameter]]
key = "model.dimensionless.delta"
values = [0.25, 100.0]
)";
  const fs::path dir = fresh("time_history");
  const StudyResult result = run_study(read(text), dir);
  const nlohmann::json s = to_json(result);
  EXPECT_EQ(s["finished"], 2);
  EXPECT_EQ(nlohmann::json::parse(std::ifstream(dir / "summary.json")), s);  // written from the result
  ASSERT_TRUE(result.lowest_max_peak);
  // The best point is the finished one with the lower larger peak V/W.
  EXPECT_EQ(result.lowest_max_peak->metrics["max_peak_V_W"].get<double>(),
            std::min(result.rows[0].metrics["max_peak_V_W"].get<double>(),
                     result.rows[1].metrics["max_peak_V_W"].get<double>()));
  const auto rows = StudyDatabase(dir / "study.sqlite").rows();
  ASSERT_EQ(rows.size(), 2u);
  const nlohmann::json& close = rows[0].metrics;
  const nlohmann::json& apart = rows[1].metrics;
  EXPECT_GT(close["max_gap_force_N"].get<double>(), 0.0);
  EXPECT_NE(close["ratio_to_free_1"].get<double>(), 1.0);
  EXPECT_EQ(apart["ratio_to_free_1"].get<double>(), 1.0);
  EXPECT_EQ(apart["ratio_to_free_2"].get<double>(), 1.0);
  EXPECT_EQ(apart["max_gap_force_N"].get<double>(), 0.0);
  EXPECT_LT(close["energy_residual"].get<double>(), 1e-11);
  EXPECT_TRUE(close.contains("ratio_to_bare_1"));
  fs::remove_all(dir);
}

TEST(Optimize, FindsGapElementsBetterThanBarePounding) {
  std::string text = kStudy.substr(0, kStudy.find("[analysis]"));
  text += R"([analysis]
kind = "optimize"
[frf]
amplitude_g = 0.2
ratio_min = 0.4
ratio_max = 1.2
points = 9
[optimize]
each = "frf"
global = "GN_DIRECT_L"
local = "LN_BOBYQA"
global_evaluations = 12
local_evaluations = 10
threads = 2
[[optimize.variable]]
key = "model.dimensionless.mu"
min = 0.0
max = 3.0
start = 0.1
)";
  const fs::path dir = fresh("optimize");
  const RunInput in = read(text);
  const OptimizationResult result = run_optimization(in, dir);
  const nlohmann::json s = to_json(result);
  EXPECT_EQ(nlohmann::json::parse(std::ifstream(dir / "optimize.json")), s);  // written from the result
  EXPECT_EQ(result.bare_objective(), s["comparison"]["objective"]["bare_pounding"].get<double>());
  const double best = s["objective"].get<double>();
  const double bare = s["comparison"]["bare_pounding"]["max_peak_V_W"].get<double>();
  EXPECT_LT(best, 0.8 * bare);
  EXPECT_LE(s["evaluations"].get<int>(), 1 + 12 + 10);
  // The evaluations start at the given point, and the optimum is the best of them.
  std::istringstream evaluations(slurp(dir / "evaluations.csv"));
  std::string line;
  std::getline(evaluations, line);
  EXPECT_EQ(line, "evaluation,stage,model.dimensionless.mu,objective,status,error");
  double lowest = 1e9;
  int count = 0;
  while (std::getline(evaluations, line)) {
    std::vector<std::string> fields;
    std::istringstream row(line);
    for (std::string field; std::getline(row, field, ',');) fields.push_back(field);
    ASSERT_GE(fields.size(), 5u) << line;
    if (count++ == 0) {
      EXPECT_EQ(fields[1] + " " + fields[2], "start 0.1");
    }
    EXPECT_EQ(fields[4], "done");
    lowest = std::min(lowest, std::stod(fields[3]));
  }
  EXPECT_EQ(count, s["evaluations"].get<int>());
  EXPECT_DOUBLE_EQ(lowest, best);
  EXPECT_TRUE(fs::exists(dir / "optimum_frf.csv"));
  EXPECT_TRUE(fs::exists(dir / "bare_frf.csv"));
  // Deterministic: the same optimum again.
  const nlohmann::json again = to_json(run_optimization(in, fresh("optimize_again")));
  EXPECT_EQ(again["optimum"], s["optimum"]);
  EXPECT_EQ(again["objective"], s["objective"]);
  fs::remove_all(dir);
  fs::remove_all(fresh("optimize_again"));
}

std::string study_error(const std::vector<std::string>& overrides) {
  try {
    read(kStudy, overrides);
  } catch (const InputError& e) {
    return e.what();
  }
  return "(no error)";
}

TEST(StudyInput, BandBaselineAndThreadsAreChecked) {
  EXPECT_EQ(read(kStudy, {"study.band=[0.6, 1.0]"}).study->band_min, 0.6);
  EXPECT_EQ(read(kStudy, {"study.band=[0.6, 1.0]"}).study->band_max, 1.0);
  EXPECT_FALSE(read(kStudy, {"study.baseline=false"}).study->baseline);
  EXPECT_EQ(read(kStudy, {"study.threads=0"}).study->threads, 0);
  const std::pair<std::string, std::string> cases[] = {
      {"study.band=[1.0, 0.6]", "study.band: expected [ratio_min, ratio_max] with 0 < ratio_min < ratio_max"},
      {"study.band=[0.6]", "study.band: expected [ratio_min, ratio_max]"},
      {"study.baseline=1", "study.baseline: expected true or false, got a integer"},
      {"study.threads=-1", "study.threads: must be ≥ 0 (got -1); 0 means all cores"},
      {"study.threads=4294967297", "study.threads: must be ≤ 1024 (got 4294967297)"},
  };
  for (const auto& [set, message] : cases) {
    const std::string error = study_error({set});
    EXPECT_NE(error.find(message), std::string::npos) << set << " → " << error;
  }
  const std::string error = study_error({"study.each=time_history", "study.band=[0.6, 1.0]"});
  EXPECT_NE(error.find("study.band: only for each = \"frf\""), std::string::npos) << error;
}

TEST(Optimize, RejectsUnknownAlgorithmsAndGradientMethods) {
  std::string text = kStudy.substr(0, kStudy.find("[analysis]"));
  text += "[analysis]\nkind = \"optimize\"\n[frf]\namplitude_g = 0.2\nratios = [1.0]\n[optimize]\neach = \"frf\"\n"
          "[[optimize.variable]]\nkey = \"model.dimensionless.mu\"\nmin = 0.0\nmax = 3.0\n";
  const fs::path dir = fresh("optimize_bad");
  try {
    run_optimization(read(text, {"optimize.global=GN_NONSENSE"}), dir);
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("not an NLopt algorithm"), std::string::npos) << e.what();
  }
  try {
    run_optimization(read(text, {"optimize.local=LD_MMA"}), dir);
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("needs gradients"), std::string::npos) << e.what();
  }
  fs::remove_all(dir);
}

}  // namespace
}  // namespace poundsim::io
