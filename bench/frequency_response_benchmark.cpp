// Frequency-response cost: one point (steady state from rest) and a whole 141-point response of
// the paper's Fig. 2c system, with each integrator. The paper reproduction (7 figures × 71
// points, interacting and free, from rest) must take under 2 s on 2 cores.

#include <benchmark/benchmark.h>
#include <fmt/format.h>

#include "poundsim/model/dimensionless.hpp"
#include "poundsim/analysis/frequency_response.hpp"
#include "poundsim/units.hpp"

namespace {

using namespace poundsim;

Model fig2c() {
  return make_model(DimensionlessParameters{.lambda2 = 200, .alpha = 0.25, .beta = 1, .gamma = 0.5,
                                            .xi = 0.05, .delta = 0.25, .eta = 0.125, .mu = 1,
                                            .epsilon = 0.5, .restitution = 0.75},
                    {1, 1});
}

/// Newmark with 128 steps per period; the exact integrator sampled 16 times per period (its
/// accuracy does not depend on the sampling).
FrequencyResponseOptions options(bool exact, std::vector<double> ratios, int threads) {
  FrequencyResponseOptions o;
  o.amplitude = 0.2 * standard_gravity;
  o.ratios = std::move(ratios);
  o.threads = threads;
  o.time_history.integrator = exact ? Integrator::exact : Integrator::newmark;
  if (exact) o.steady.steps_per_period = 16;
  return o;
}

void BM_FrfPoint(benchmark::State& state) {
  const Model model = fig2c();
  const FrequencyResponseOptions o = options(state.range(0) == 1, {0.8}, 1);
  int periods = 0;
  for (auto _ : state) {
    const auto points = frequency_response(model, o);
    periods = points.front().transient_periods;
  }
  state.SetLabel(state.range(0) == 1 ? "exact" : "newmark");
  state.counters["transient_periods"] = periods;
}
BENCHMARK(BM_FrfPoint)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);

/// Args: integrator (0 Newmark, 1 exact), threads (0: all cores), lanes (Newmark from rest: 1
/// is one point at a time, the path before lockstep; 8 the default batches).
void BM_WholeFrf141(benchmark::State& state) {
  const Model model = fig2c();
  std::vector<double> ratios;
  for (int i = 0; i <= 140; ++i) ratios.push_back(0.2 + 0.01 * i);
  FrequencyResponseOptions o = options(state.range(0) == 1, ratios, static_cast<int>(state.range(1)));
  o.lanes = static_cast<int>(state.range(2));
  for (auto _ : state) benchmark::DoNotOptimize(frequency_response(model, o));
  state.SetLabel(std::string(state.range(0) == 1 ? "exact" : "newmark") +
                 (state.range(1) == 1 ? ", 1 thread" : ", all cores") +
                 (state.range(0) == 0 ? fmt::format(", {} lanes", o.lanes) : std::string()));
  state.SetItemsProcessed(state.iterations() * 141);
}
BENCHMARK(BM_WholeFrf141)
    ->Args({0, 1, 1})->Args({0, 1, 8})->Args({0, 0, 1})->Args({0, 0, 8})->Args({1, 1, 8})->Args({1, 0, 8})
    ->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace
