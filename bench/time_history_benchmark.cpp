// Whole time histories as a user runs them: the pounding run and the free frames' comparison
// (analysis/time_history.hpp). Without contact the run is its own free run; points of a study
// that differ in their gap elements alone share one free run (FreeRunMemo), which
// BM_GapElementStudy measures with the memo off (what every point paid before) and on.

#include <vector>

#include <benchmark/benchmark.h>

#include "poundsim/analysis/time_history.hpp"
#include "poundsim/model/dimensionless.hpp"
#include "poundsim/units.hpp"

namespace {

using namespace poundsim;

/// Two Fig. 2c frames of `storeys` storeys with gap δ̄ = `delta`, 0.2 g at ω̄/ω₁ = 0.8, Newmark
/// dt = 1 ms, outputs at the start and the end only (a study point's).
TimeHistoryProblem fig2c_problem(int storeys, double delta, double duration) {
  const DimensionlessParameters p{.lambda2 = 200, .alpha = 0.25, .beta = 1, .gamma = 0.5, .xi = 0.05,
                                  .delta = delta, .eta = 0.125, .mu = 1, .epsilon = 0.5,
                                  .restitution = 0.75};
  const Model m = make_model(p, {storeys, storeys});
  return TimeHistoryProblem{.model = m,
                            .excitation = HarmonicExcitation{0.2 * standard_gravity, 0.8 * fundamental_frequency(m.frames[0])},
                            .options = TimeHistoryOptions{.dt = 1e-3},
                            .initial = {},
                            .duration = duration,
                            .output_dt = duration};
}

/// 20 s of two frames of range(0) storeys, pounding (range(1) = 1, δ̄ = 0.25) or never in contact
/// (0, δ̄ = 10⁴: the run is its own free run).
void BM_TimeHistory(benchmark::State& state) {
  const bool contact = state.range(1) != 0;
  const TimeHistoryProblem problem = fig2c_problem(static_cast<int>(state.range(0)), contact ? 0.25 : 1e4, 20.0);
  bool from_this_run = false;
  for (auto _ : state) {
    const TimeHistoryAnalysis result = analyse_time_history(problem);
    from_this_run = result.free_from_this_run;
    benchmark::DoNotOptimize(result.free->floors.front().displacement.value);
  }
  state.counters["free_from_this_run"] = from_this_run ? 1 : 0;
}
BENCHMARK(BM_TimeHistory)->ArgsProduct({{1, 10, 50}, {0, 1}})->Unit(benchmark::kMillisecond);

/// A study of eight points that differ in the gap elements' stiffness (η̄ = 0.125 … 1), two
/// 10-storey frames pounding, 10 s each: range(0) = 1 shares the free run (FreeRunMemo), 0 makes
/// it at every point.
void BM_GapElementStudy(benchmark::State& state) {
  const bool shared = state.range(0) != 0;
  const TimeHistoryProblem base = fig2c_problem(10, 0.25, 10.0);
  std::vector<TimeHistoryProblem> points;
  for (int k = 0; k < 8; ++k) {
    TimeHistoryProblem point = base;
    for (GapElement& g : point.model.gaps) parameters_of<PaperGap>(g).stiffness *= 1.0 + k;
    points.push_back(point);
  }
  for (auto _ : state) {
    FreeRunMemo memo;
    for (const TimeHistoryProblem& point : points) {
      const TimeHistoryAnalysis result = analyse_time_history(point, {}, shared ? &memo : nullptr);
      benchmark::DoNotOptimize(result.free->floors.front().displacement.value);
    }
  }
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(points.size()));
}
BENCHMARK(BM_GapElementStudy)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);

}  // namespace
