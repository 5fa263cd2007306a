// The optimiser's constraints and Pareto fronts (docs/studies.md) against a problem whose
// constrained optimum and trade-off are known in closed form, the inputs it refuses, and its
// search replayed: resumed from its database, and batched over ranks, the same bit for bit.
//
// Frame 2 (one storey, mass m, stiffness k: the design variables) is released with velocity v0,
// undamped, far from frame 1 (m₁ = 10 t, at rest). It swings u(t) = (v0/ω) sin ωt, so
//
//     peak_drift_2_m = v0 √(m/k)           peak_V2_W = k · v0/ω / (m₁ g) = v0 √(k m) / (m₁ g),
//
// which the exact integrator finds to round-off. Minimising the drift (small m, large k) with
// V2/W ≤ B: the drift √(m/k) = m / √(km) is least on the constraint √(km) = C = B m₁ g / v0 at
// the smallest mass, m = m_lo, k = C²/m_lo, where the drift is v0 m_lo / C. The Pareto front of
// the two figures is therefore the hyperbola drift · V2/W = v0² m_lo / (m₁ g).

#include <cmath>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include <SQLiteCpp/Database.h>
#include <gtest/gtest.h>

#include "poundsim/error.hpp"
#include "poundsim/io/input.hpp"
#include "poundsim/optimize/optimize_run.hpp"
#include "poundsim/units.hpp"
#include "../test_files.hpp"

namespace poundsim::io {
namespace {

using optimize::OptimizationResult;
using optimize::run_optimization;

constexpr double kV0 = 0.1, kMassLow = 1e4, kM1 = 1e4;

std::string problem(const std::string& optimize, const std::string& stiffness_scale = "") {
  return R"([[frames]]
storeys = 1
mass = 1.0e4
stiffness = 1.0e6
damping = 0.0

[[frames]]
storeys = 1
mass = 2.0e4
stiffness = 1.0e7
damping = 0.0

[gap_elements]
gap = 1.0
restitution = 1.0

[initial]
velocity = [[0.0], [0.1]]

[excitation]
kind = "none"

[analysis]
kind = "optimize"
integrator = "exact"
duration = 0.5
dt = 0.01

[[optimize.variable]]
key = "frames[2].mass"
min = 1.0e4
max = 4.0e4

[[optimize.variable]]
key = "frames[2].stiffness"
min = 1.0e6
max = 1.0e8
)" + stiffness_scale + "\n" + optimize;
}

RunInput read(const std::string& text) { return read_input_string(text, "optimize.toml", ".", {}); }

// The closed-form optimum with LN_COBYLA (which takes the constraint itself) and with LN_BOBYQA
// inside the augmented Lagrangian; the constraint holds at the optimum and is active there.
/// [optimize]: the least peak_drift_2_m with peak_V2_W ≤ `limit`, by the local algorithm alone.
std::string least_drift_under_a_shear_limit(const std::string& local, double limit) {
  return fmt::format(R"([optimize]
each = "time_history"
objective = "peak_drift_2_m"
global = "none"
local = "{}"
local_evaluations = 400
relative_tolerance = 1e-12

[[optimize.constraint]]
metric = "peak_V2_W"
max = {}
)",
                     local, limit);
}

TEST(Optimize, ConstrainedOptimumOfAKnownProblem) {
  const double limit = 0.5096839959225280;  // B: C = B m₁ g / v0 = 5e5, k* = C²/m_lo = 2.5e7
  const double c = limit * kM1 * standard_gravity / kV0;
  for (const char* local : {"LN_COBYLA", "LN_BOBYQA"}) {
    SCOPED_TRACE(local);
    const RunInput in = read(problem(least_drift_under_a_shear_limit(local, limit)));
    const auto dir = testing::fresh_folder(std::string("optimize_constrained_") + local);
    const OptimizationResult r = run_optimization(in, dir);
    EXPECT_EQ(r.stages[0].algorithm, std::string(local) == "LN_COBYLA" ? "LN_COBYLA" : "AUGLAG(LN_BOBYQA)");
    EXPECT_TRUE(r.feasible);
    ASSERT_EQ(r.constraints.size(), 1U);
    EXPECT_TRUE(r.constraints[0].holds);
    EXPECT_NEAR(*r.constraints[0].value, limit, 1e-4 * limit);  // active
    EXPECT_LE(*r.constraints[0].value, limit * (1 + in.optimize->constraint_tolerance));
    EXPECT_NEAR(r.optimum[0], kMassLow, 1e-3 * kMassLow);
    EXPECT_NEAR(r.optimum[1], c * c / kMassLow, 2e-3 * c * c / kMassLow);
    EXPECT_NEAR(r.objective, kV0 * kMassLow / c, 1e-3 * kV0 * kMassLow / c);
    // Unconstrained, the drift would go to the stiffest corner, k = 1e8: the constraint mattered.
    EXPECT_GT(r.objective, 1.5 * kV0 * std::sqrt(kMassLow / 1e8));
    const nlohmann::json j = to_json(r);
    EXPECT_EQ(j["constraints"][0]["metric"], "peak_V2_W");
    EXPECT_EQ(j["feasible"], true);
    EXPECT_EQ(nlohmann::json::parse(testing::slurp(dir / "optimize.json")), j);
    std::filesystem::remove_all(dir);
  }
}

// With a limit no design meets, the optimum is the design that breaks it least: the least
// √(km), at the lightest and softest corner.
TEST(Optimize, AnInfeasibleProblemReportsTheLeastBrokenDesign) {
  const RunInput in = read(problem(R"([optimize]
each = "time_history"
objective = "peak_drift_2_m"
global = "none"
local = "LN_COBYLA"
local_evaluations = 200

[[optimize.constraint]]
metric = "peak_V2_W"
max = 0.05
)"));
  const auto dir = testing::fresh_folder("optimize_infeasible");
  const OptimizationResult r = run_optimization(in, dir);
  EXPECT_FALSE(r.feasible);
  EXPECT_FALSE(r.constraints[0].holds);
  const double least = kV0 * std::sqrt(1e6 * kMassLow) / (kM1 * standard_gravity);
  EXPECT_NEAR(*r.constraints[0].value, least, 1e-2 * least);  // COBYLA, 200 evaluations
  EXPECT_NE(optimize::report(r, dir).find("no evaluation met the constraints"), std::string::npos);
  std::filesystem::remove_all(dir);
}

// Three points of the front between the anchors, and the front objective's own optimum: every
// point on the hyperbola drift · V2/W = v0² m_lo/(m₁ g), its limit met, none dominated, V2/W from
// the least reachable (the softest, lightest frame) to the one at the drift's optimum (k = 1e8).
// The main objective here is V2/W itself: its optimum is the least V2/W.
TEST(Optimize, ParetoFrontOfTwoFigures) {
  const RunInput in = read(problem(R"([optimize]
each = "time_history"
objective = "peak_V2_W"
global = "none"
local = "LN_COBYLA"
local_evaluations = 150
relative_tolerance = 1e-10

[optimize.pareto]
objective = "peak_drift_2_m"
metric = "peak_V2_W"
points = 4
)"));
  const auto dir = testing::fresh_folder("optimize_pareto");
  const OptimizationResult r = run_optimization(in, dir);
  ASSERT_TRUE(r.pareto);
  ASSERT_EQ(r.pareto->points.size(), 4U);
  const double product = kV0 * kV0 * kMassLow / (kM1 * standard_gravity);
  const double least = kV0 * std::sqrt(1e6 * kMassLow) / (kM1 * standard_gravity);
  const double most = kV0 * std::sqrt(1e8 * kMassLow) / (kM1 * standard_gravity);
  for (std::size_t j = 0; j < r.pareto->points.size(); ++j) {
    SCOPED_TRACE(j);
    const optimize::ParetoPoint& p = r.pareto->points[j];
    EXPECT_TRUE(p.feasible);
    EXPECT_FALSE(p.dominated);
    EXPECT_NEAR(p.objective * p.metric, product, 2e-3 * product);
    if (p.limit) {
      EXPECT_LE(p.metric, *p.limit * (1 + 1e-6));
    }
  }
  EXPECT_NEAR(*r.pareto->points[0].limit, least, 1e-3 * least);
  EXPECT_FALSE(r.pareto->points.back().limit);  // the objective's own optimum
  EXPECT_NEAR(r.pareto->points.back().metric, most, 1e-3 * most);
  EXPECT_NEAR(*r.pareto->points[2].limit, least + (most - least) * 2 / 3, 1e-3 * most);
  EXPECT_NEAR(r.objective, least, 1e-3 * least);
  EXPECT_EQ(r.stages[1].stage, "pareto_objective.local");
  EXPECT_EQ(r.stages[2].stage, "pareto_metric.local");
  const std::string csv = testing::slurp(dir / "pareto.csv");
  EXPECT_EQ(csv.substr(0, csv.find('\n')),
            "point,limit,peak_drift_2_m,peak_V2_W,feasible,dominated,frames[2].mass,frames[2].stiffness");
  EXPECT_EQ(to_json(r)["pareto"]["points"].size(), 4U);
  std::filesystem::remove_all(dir);
}

// Two figures that do not trade off (frame 1 stays at rest: the worse frame's drift is frame 2's)
// have one design for both anchors: the front is that design alone.
TEST(Optimize, FiguresThatDoNotTradeOffMakeAFrontOfOnePoint) {
  const RunInput in = read(problem(R"([optimize]
each = "time_history"
objective = "peak_drift_2_m"
global = "none"
local = "LN_COBYLA"
local_evaluations = 60

[optimize.pareto]
metric = "max_peak_drift_m"
points = 3
)"));
  const auto dir = testing::fresh_folder("optimize_no_trade_off");
  const OptimizationResult r = run_optimization(in, dir);
  ASSERT_TRUE(r.pareto);
  ASSERT_EQ(r.pareto->points.size(), 1U);
  EXPECT_EQ(r.pareto->points[0].objective, r.pareto->points[0].metric);
  EXPECT_FALSE(r.pareto->points[0].limit);
  std::filesystem::remove_all(dir);
}

void expect_refused(const std::string& optimize, const std::string& message) {
  SCOPED_TRACE(optimize);
  const auto dir = testing::fresh_folder("optimize_refused");
  try {
    const RunInput in = read(problem(optimize));
    static_cast<void>(run_optimization(in, dir));
    ADD_FAILURE() << "accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(message), std::string::npos) << e.what();
  }
  // Not even the database of the evaluations that ran before the refusal.
  EXPECT_TRUE(std::filesystem::is_empty(dir));
  std::filesystem::remove_all(dir);
}

TEST(Optimize, RefusesFiguresAnEvaluationDoesNotHaveAndIncompleteLimits) {
  const std::string head = "[optimize]\neach = \"time_history\"\nglobal = \"none\"\nlocal = \"LN_COBYLA\"\n";
  expect_refused(head + "objective = \"peak_drift_ratio_2\"\n",
                 "optimize.toml:43:13: optimize.objective: \"peak_drift_ratio_2\" is not a figure of an evaluation "
                 "(each = \"time_history\") of this model; its figures are: amp_acc_1_1, ");  // no storey heights
  expect_refused(head + "[[optimize.constraint]]\nmetric = \"max_stroke_use\"\nmax = 1.0\n",
                 "optimize.constraint[1].metric: \"max_stroke_use\" is not a figure");  // bare pounding has no stroke
  expect_refused(head + "[[optimize.constraint]]\nmetric = \"peak_V2_W\"\n", "optimize.constraint[1].metric: needs a limit");
  expect_refused(head + "[[optimize.constraint]]\nmetric = \"peak_V2_W\"\nmin = 1.0\nmax = 0.5\n",
                 "optimize.constraint[1].max: must be larger than min");
  expect_refused(head + "[[optimize.constraint]]\nmetric = \"peak_V2_W\"\nmax = 1.0\nlimit = 2.0\n", "limit");
  expect_refused(head + "[optimize.pareto]\nmetric = \"peak_V2_W\"\n", "optimize.pareto.metric: needs either limits or points");
  expect_refused(head + "[optimize.pareto]\nmetric = \"peak_V2_W\"\npoints = 3\nlimits = [1.0]\n",
                 "needs either limits or points");
  expect_refused(head + "[optimize.pareto]\nmetric = \"max_peak_V_W\"\npoints = 3\n", "is the front's objective");
  expect_refused(head + "[optimize.pareto]\nobjective = \"peak_V2_W\"\nmetric = \"peak_V2_W\"\npoints = 3\n",
                 "optimize.pareto.metric: is the front's objective, peak_V2_W");
  expect_refused(head + "[optimize.pareto]\nobjective = \"nope\"\nmetric = \"peak_V2_W\"\npoints = 3\n",
                 "optimize.pareto.objective: \"nope\" is not a figure");
  expect_refused(head + "[optimize.pareto]\nmetric = \"peak_V2_W\"\nlimits = [0.5, 0.2]\n", "optimize.pareto.limits: must increase");
  expect_refused(head + "[optimize.pareto]\nmetric = \"peak_V2_W\"\npoints = 1\n", "optimize.pareto.points");
  expect_refused(head + "[optimize.pareto]\nmetric = \"no_such\"\npoints = 2\n",
                 "optimize.pareto.metric: \"no_such\" is not a figure");
  // The paper's element (bare pounding here) impacts rigidly: an acceleration without
  // analysis.impact_duration would leave the impacts out.
  expect_refused(head + "[[optimize.constraint]]\nmetric = \"max_peak_abs_acc_g\"\nmax = 1.0\n",
                 "optimize.toml:44:10: optimize.constraint[1].metric: \"max_peak_abs_acc_g\" is a floor acceleration, and "
                 "this model's impacts are rigid");
  expect_refused(head + "objective = \"peak_abs_acc_2_g\"\n", "optimize.objective: \"peak_abs_acc_2_g\" is a floor acceleration");
  expect_refused(head + "[optimize.pareto]\nmetric = \"amp_acc_2_1\"\npoints = 2\n",
                 "optimize.pareto.metric: \"amp_acc_2_1\" is a floor acceleration");
}

// With the impacts' pulse duration the same constraint on an acceleration is taken, and steers
// by accelerations that include the impacts.
TEST(Optimize, AnAccelerationConstraintWithTheImpactsPulseDurationRuns) {
  RunInput in = read(problem(R"([optimize]
each = "time_history"
global = "none"
local = "LN_COBYLA"
local_evaluations = 5

[[optimize.constraint]]
metric = "max_peak_abs_acc_g"
max = 10.0
)"));
  in.analysis.options.impact_duration = 0.002;
  const auto dir = testing::fresh_folder("optimize_acceleration");
  const OptimizationResult r = run_optimization(in, dir);
  ASSERT_EQ(r.constraints.size(), 1U);
  EXPECT_TRUE(r.constraints[0].value.has_value());
  std::filesystem::remove_all(dir);
}

// On a log scale NLopt searches ln k: the constrained optimum is the same (k* = C²/m_lo), and
// the local stage's first steps are a tenth of the range in ln k — factors of 100^{±0.1} from the
// start at the geometric mean √(1e6 · 1e8) = 1e7 — where a linear scale steps by ±9.9e6.
TEST(Optimize, AVariableOnALogScaleIsSearchedInItsLogarithm) {
  const double limit = 0.5096839959225280;
  const double c = limit * kM1 * standard_gravity / kV0;
  const RunInput in = read(problem(least_drift_under_a_shear_limit("LN_COBYLA", limit), "scale = \"log\""));
  ASSERT_TRUE(in.optimize->variables[1].log);
  EXPECT_FALSE(in.optimize->variables[0].log);
  const auto dir = testing::fresh_folder("optimize_log_scale");
  const OptimizationResult r = run_optimization(in, dir);
  EXPECT_TRUE(r.feasible);
  EXPECT_NEAR(r.optimum[0], kMassLow, 1e-3 * kMassLow);
  EXPECT_NEAR(r.optimum[1], c * c / kMassLow, 2e-3 * c * c / kMassLow);
  // The evaluations' stiffnesses: the start 1e7, then COBYLA's first steps in ln k.
  const auto& table = r.evaluation_table;
  std::vector<double> k;
  for (const auto& column : table.columns()) {
    if (column.name == "frames[2].stiffness") k = std::get<io::TableColumn::Numbers>(column.values);
  }
  ASSERT_GE(k.size(), 3U);
  EXPECT_NEAR(k[0], 1e7, 1e-6 * 1e7);
  bool stepped_by_a_factor = false;
  for (std::size_t i = 1; i < std::min<std::size_t>(k.size(), 4); ++i) {
    const double factor = std::pow(100.0, 0.1);
    if (std::abs(k[i] / 1e7 - factor) < 1e-9 || std::abs(1e7 / k[i] - factor) < 1e-9) stepped_by_a_factor = true;
  }
  EXPECT_TRUE(stepped_by_a_factor) << k[1] << ", " << k[2];
  std::filesystem::remove_all(dir);
  // "log" needs a positive range.
  std::string zero_min = problem("[optimize]\neach = \"time_history\"\n", "scale = \"log\"");
  zero_min.replace(zero_min.find("min = 1.0e6"), 11, "min = 0.0");
  try {
    static_cast<void>(read(zero_min));
    ADD_FAILURE() << "accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("optimize.variable[2].min: must be > 0 with scale = \"log\""), std::string::npos)
        << e.what();
  }
}

/// A constrained search with a global stage (a population algorithm) and a local one.
RunInput search(const std::string& global, const std::string& local) {
  return read(problem(fmt::format(R"([optimize]
each = "time_history"
objective = "peak_drift_2_m"
global = "{}"
global_evaluations = 60
local = "{}"
local_evaluations = 40

[[optimize.constraint]]
metric = "peak_V2_W"
max = 0.5
)",
                                  global, local)));
}

/// Progress that stops the run (as Ctrl-C in Python does) once `after` evaluations are done.
std::function<void(int, int)> stop_after(int after) {
  return [after](int done, int) {
    if (done >= after) throw RunStopped();
  };
}

// Stopped after 17 evaluations (each stored as it was computed), the same run in the same folder
// replays the search from its database: the same evaluations in the same order and the same
// optimum, bit for bit, with the 17 read and only the rest computed. A third run computes nothing.
TEST(Optimize, AStoppedSearchResumesFromItsDatabaseWithNothingComputedTwice) {
  const RunInput in = search("GN_CRS2_LM", "LN_COBYLA");
  const auto whole = testing::fresh_folder("optimize_whole");
  const OptimizationResult all = run_optimization(in, whole);
  EXPECT_EQ(all.reused, 0);
  EXPECT_EQ(all.computed, all.evaluations);  // one process: every design computed is asked for

  const auto dir = testing::fresh_folder("optimize_resumed");
  EXPECT_THROW(static_cast<void>(run_optimization(in, dir, stop_after(17))), RunStopped);
  std::vector<std::string> left;
  for (const auto& entry : std::filesystem::directory_iterator(dir)) left.push_back(entry.path().filename().string());
  EXPECT_EQ(left, std::vector<std::string>{"optimize.sqlite"});  // no result, whole or in part
  const OptimizationResult resumed = run_optimization(in, dir);
  EXPECT_EQ(resumed.reused, 17);
  EXPECT_EQ(resumed.computed, all.evaluations - 17);
  EXPECT_EQ(resumed.optimum, all.optimum);
  EXPECT_EQ(resumed.objective, all.objective);
  EXPECT_EQ(testing::slurp(dir / "evaluations.csv"), testing::slurp(whole / "evaluations.csv"));
  const OptimizationResult again = run_optimization(in, dir);
  EXPECT_EQ(again.computed, 0);
  EXPECT_EQ(again.reused, all.evaluations);
  EXPECT_EQ(testing::slurp(dir / "evaluations.csv"), testing::slurp(whole / "evaluations.csv"));

  // Another input in the same folder is refused, and its database kept as it was.
  const RunInput other = search("GN_CRS2_LM", "LN_BOBYQA");
  try {
    static_cast<void>(run_optimization(other, dir));
    ADD_FAILURE() << "another input's database accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("optimize.sqlite: this database holds the results of a different"), std::string::npos)
        << e.what();
  }
  EXPECT_EQ(run_optimization(in, dir).computed, 0);

  // A damaged row is refused as such, naming the file.
  {
    SQLite::Database db((dir / "optimize.sqlite").string(), SQLite::OPEN_READWRITE);
    db.exec("UPDATE evaluations SET result = x'ff00' WHERE rowid = 3");
  }
  try {
    static_cast<void>(run_optimization(in, dir));
    ADD_FAILURE() << "a damaged database accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("optimize.sqlite: a damaged optimisation database (an evaluation does not read"),
              std::string::npos)
        << e.what();
  }
  std::filesystem::remove_all(whole);
  std::filesystem::remove_all(dir);
}

/// Ranks in one process: the coordinator computes every task of a phase itself, the last
/// first (results may come in any order), as if `ranks` processes shared them.
class RanksInOneProcess final : public PointDistribution {
 public:
  explicit RanksInOneProcess(int ranks) : ranks_(ranks) {}
  [[nodiscard]] int ranks() const override { return ranks_; }
  [[nodiscard]] bool is_coordinator() const override { return true; }
  bool run_phase(const std::vector<std::string>& tasks, const std::function<std::string(const std::string&)>& compute,
                 const std::function<void(std::size_t, const std::string&)>& store,
                 const std::function<bool()>& /*stop*/) override {
    ++phases;
    for (std::size_t t = tasks.size(); t-- > 0;) store(t, compute(tasks[t]));
    return false;
  }
  void serve_until_finished(const std::function<std::string(const std::string&)>& /*compute*/) override {}
  void finish() override { ++finished; }
  int phases = 0, finished = 0;

 private:
  int ranks_;
};

// On four ranks the search computes the designs NLopt will ask for in batches of four, guessing
// past the first unknown one; the evaluations, their order, the optimum and the front are those
// of one process bit for bit, with fewer rounds than evaluations (a population's designs do not
// depend on the values) and the guesses the search did not follow computed but not counted.
TEST(Optimize, BatchedOverRanksTheSearchIsTheSameBitForBit) {
  for (const auto& [global, local] : {std::pair{"GN_CRS2_LM", "LN_COBYLA"}, std::pair{"GN_DIRECT_L", "LN_BOBYQA"},
                                      std::pair{"GN_ISRES", "none"}}) {
    SCOPED_TRACE(fmt::format("{} then {}", global, local));
    const RunInput in = search(global, local);
    const auto one = testing::fresh_folder("optimize_one_process");
    const auto four = testing::fresh_folder("optimize_four_ranks");
    const OptimizationResult serial = run_optimization(in, one);
    RanksInOneProcess ranks(4);
    const OptimizationResult batched = run_optimization(in, four, {}, &ranks);
    EXPECT_EQ(testing::slurp(four / "evaluations.csv"), testing::slurp(one / "evaluations.csv"));
    EXPECT_EQ(batched.optimum, serial.optimum);
    EXPECT_EQ(batched.objective, serial.objective);
    EXPECT_EQ(batched.evaluations, serial.evaluations);
    EXPECT_GE(batched.computed, batched.evaluations);
    EXPECT_EQ(ranks.finished, 1);
    // Rounds: the start's, then one per batch.
    fmt::print("{} then {}: {} evaluations in {} rounds on 4 ranks, {} designs computed\n", global, local,
               batched.evaluations, ranks.phases, batched.computed);
    EXPECT_LT(ranks.phases, batched.evaluations);
    // The database of a batched run (its guesses included) resumed on one process: nothing to compute.
    const OptimizationResult again = run_optimization(in, four);
    EXPECT_EQ(again.computed, 0);
    EXPECT_EQ(testing::slurp(four / "evaluations.csv"), testing::slurp(one / "evaluations.csv"));
    std::filesystem::remove_all(one);
    std::filesystem::remove_all(four);
  }
}

// The same with a Pareto front (its anchors and limits come from the replayed search), stopped
// on four ranks and resumed on one; and an ensemble objective on eight ranks, whose batches hold
// two designs of four records each (tasks of different designs finishing in any order).
TEST(Optimize, BatchedFrontsAndEnsemblesAreTheSameBitForBit) {
  {
    const RunInput in = read(problem(R"([optimize]
each = "time_history"
objective = "peak_V2_W"
global = "GN_CRS2_LM"
global_evaluations = 30
local = "LN_COBYLA"
local_evaluations = 30

[optimize.pareto]
objective = "peak_drift_2_m"
metric = "peak_V2_W"
points = 3
)"));
    const auto one = testing::fresh_folder("optimize_front_one");
    const auto four = testing::fresh_folder("optimize_front_four");
    const OptimizationResult serial = run_optimization(in, one);
    RanksInOneProcess ranks(4);
    EXPECT_THROW(static_cast<void>(run_optimization(in, four, stop_after(50), &ranks)), RunStopped);
    const OptimizationResult resumed = run_optimization(in, four);
    EXPECT_GT(resumed.reused, 0);
    ASSERT_TRUE(serial.pareto && resumed.pareto);
    EXPECT_EQ(serial.pareto->points.size(), 3U);
    EXPECT_EQ(testing::slurp(four / "pareto.csv"), testing::slurp(one / "pareto.csv"));
    EXPECT_EQ(testing::slurp(four / "evaluations.csv"), testing::slurp(one / "evaluations.csv"));
    std::filesystem::remove_all(one);
    std::filesystem::remove_all(four);
  }
  {
    const std::vector<std::string> sets{"analysis.duration=3"};
    const RunInput in = read_input(std::filesystem::path(POUNDSIM_SOURCE_DIR) / "examples/optimize_ensemble.toml", sets);
    ASSERT_EQ(in.ensemble->records.size(), 4U);
    const auto one = testing::fresh_folder("optimize_ensemble_one");
    const auto eight = testing::fresh_folder("optimize_ensemble_eight");
    const OptimizationResult serial = run_optimization(in, one);
    RanksInOneProcess ranks(8);
    const OptimizationResult batched = run_optimization(in, eight, {}, &ranks);
    EXPECT_EQ(testing::slurp(eight / "evaluations.csv"), testing::slurp(one / "evaluations.csv"));
    EXPECT_EQ(nlohmann::json(to_json(batched)).at("optimum_metrics"), nlohmann::json(to_json(serial)).at("optimum_metrics"));
    EXPECT_LT(ranks.phases, batched.evaluations);
    std::filesystem::remove_all(one);
    std::filesystem::remove_all(eight);
  }
}

}  // namespace
}  // namespace poundsim::io
