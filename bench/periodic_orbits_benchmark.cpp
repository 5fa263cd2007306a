// Periodic orbits, side by side with the brute force in one run: the paper's Fig. 2c
// response over 141 ratios by simulation with the exact integrator (every point from rest) and by
// continuation (every branch, stable and unstable); and the cost of one Newton iteration (a
// period of the exact integrator carrying the monodromy) as the frames grow from 2×1 to 2×20
// storeys, with the events per orbit.

#include <algorithm>
#include <array>
#include <chrono>
#include <string>
#include <vector>

#include <benchmark/benchmark.h>
#include <fmt/format.h>

#include "poundsim/analysis/periodic_orbits.hpp"
#include "poundsim/io/frequency_response_run.hpp"
#include "poundsim/io/input.hpp"
#include "poundsim/model/dimensionless.hpp"
#include "poundsim/units.hpp"

namespace {

using namespace poundsim;

DimensionlessParameters fig2c() {
  return DimensionlessParameters{.lambda2 = 200, .alpha = 0.25, .beta = 1, .gamma = 0.5, .xi = 0.05, .delta = 0.25,
                                 .eta = 0.125, .mu = 1, .epsilon = 0.5, .restitution = 0.75};
}

FrequencyResponseOptions options(FrfMethod method) {
  FrequencyResponseOptions o;
  o.amplitude = 0.2 * standard_gravity;
  for (int i = 0; i <= 140; ++i) o.ratios.push_back(0.2 + 0.01 * i);
  o.method = method;
  o.threads = 0;
  o.time_history.integrator = Integrator::exact;
  o.steady.steps_per_period = 16;
  return o;
}

void BM_Fig2c141(benchmark::State& state) {
  const Model model = make_model(fig2c(), {1, 1});
  const auto method = static_cast<FrfMethod>(state.range(0));
  const FrequencyResponseOptions o = options(method);
  std::size_t points = 0, unstable = 0;
  for (auto _ : state) {
    const std::vector<FrfPoint> result = frequency_response(model, o);
    points = result.size();
    unstable = static_cast<std::size_t>(std::count_if(result.begin(), result.end(), [](const FrfPoint& p) { return !p.stable; }));
  }
  state.SetLabel(method == FrfMethod::simulation ? "simulation (exact, from rest, all cores)"
                                                 : "continuation (pieces on all cores)");
  state.counters["points"] = static_cast<double>(points);
  state.counters["unstable_points"] = static_cast<double>(unstable);
}
BENCHMARK(BM_Fig2c141)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond)->UseRealTime();

/// One Newton iteration of a period-1 orbit at ω̄/ω₁ = 0.9: a period with the monodromy.
void BM_NewtonIteration(benchmark::State& state) {
  const auto storeys = static_cast<int>(state.range(0));
  DimensionlessParameters p = fig2c();
  p.lambda2 = 200.0 * storeys;  // keeps the first frequencies in the paper's range
  const Model model = make_model(p, {storeys, storeys});
  const double omega = 0.9 * reference_frequency(model);
  TimeHistoryOptions th;
  th.integrator = Integrator::exact;
  th.dt = 1.0;
  StroboscopicMap map(model, 0.2 * standard_gravity, omega, th, 16);
  const Eigen::VectorXd start = settled_state(map, Eigen::VectorXd::Zero(2 * map.dofs()), 30);
  const ShootingResult orbit = shoot(map, start, 1, ShootingOptions{});
  Eigen::VectorXd x(2 * map.dofs());
  x << orbit.orbit.u, orbit.orbit.v;
  Eigen::MatrixXd monodromy;
  for (auto _ : state) benchmark::DoNotOptimize(map.evaluate(x, 1, &monodromy));
  state.counters["events_per_orbit"] = static_cast<double>(orbit.orbit.events);
  state.counters["newton_iterations"] = orbit.orbit.iterations;
  state.counters["converged"] = orbit.converged ? 1 : 0;
  state.SetLabel(fmt::format("2x{} storeys", storeys));
}
BENCHMARK(BM_NewtonIteration)->Arg(1)->Arg(5)->Arg(10)->Arg(20)->Unit(benchmark::kMicrosecond);

/// One period of Fig. 2c's frames with `storeys` storeys each at ω̄/ω₁ = 0.9, from a settled state,
/// keeping the state alone or recording the responses: what carrying the monodromy costs, and
/// what a brute-force period (peaks and energy balance) costs.
void period(benchmark::State& state, StroboscopicMap::Responses responses) {
  const auto storeys = static_cast<int>(state.range(0));
  DimensionlessParameters p = fig2c();
  p.lambda2 = 200.0 * storeys;
  const Model model = make_model(p, {storeys, storeys});
  TimeHistoryOptions th;
  th.integrator = Integrator::exact;
  th.dt = 1.0;
  StroboscopicMap map(model, 0.2 * standard_gravity, 0.9 * reference_frequency(model), th, 16);
  const Eigen::VectorXd x = settled_state(map, Eigen::VectorXd::Zero(2 * map.dofs()), 30);
  for (auto _ : state) benchmark::DoNotOptimize(map.evaluate(x, 1, nullptr, responses));
  state.SetLabel(fmt::format("2x{} storeys", storeys));
}
void BM_PeriodWithoutMonodromy(benchmark::State& state) { period(state, StroboscopicMap::Responses::skip); }
BENCHMARK(BM_PeriodWithoutMonodromy)->Arg(1)->Arg(5)->Arg(10)->Arg(20)->Unit(benchmark::kMicrosecond);
void BM_RecordedPeriod(benchmark::State& state) { period(state, StroboscopicMap::Responses::record); }
BENCHMARK(BM_RecordedPeriod)->Arg(1)->Arg(5)->Arg(10)->Arg(20)->Unit(benchmark::kMicrosecond);

/// The target: the paper's seven figures (examples/paper), 141 ratios each, exact, one
/// after another on two threads each (simulation: points in parallel; continuation: its pieces of
/// ratios_per_segment ratios in parallel), by simulation from rest and by continuation, side by
/// side; each figure's seconds as a counter.
void BM_SevenPaperFigures(benchmark::State& state) {
  const auto& [method_name, method] = frf_method_names[static_cast<std::size_t>(state.range(0))];
  const std::array<const char*, 7> figures{"fig2a", "fig2b", "fig2c", "fig3a", "fig3b", "fig4a", "fig4b"};
  std::vector<FrequencyResponseOptions> options;
  std::vector<Model> models;
  for (const char* figure : figures) {
    const std::vector<std::string> settings{"frf.points=141", "frf.steps_per_period=16", "analysis.integrator=exact",
                                            fmt::format("frf.method={}", method_name)};
    const io::RunInput input =
        io::read_input(std::string(POUNDSIM_SOURCE_DIR) + "/examples/paper/" + figure + ".toml", settings);
    FrequencyResponseOptions o = io::frequency_response_options(input);
    o.threads = 2;
    options.push_back(o);
    models.push_back(input.model);
  }
  std::array<double, 7> seconds{};
  std::array<std::size_t, 7> points{};
  for (auto _ : state) {
    for (std::size_t i = 0; i < figures.size(); ++i) {
      const auto start = std::chrono::steady_clock::now();
      points[i] = frequency_response(models[i], options[i]).size();
      seconds[i] = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    }
  }
  for (std::size_t i = 0; i < figures.size(); ++i) {
    state.counters[fmt::format("{}_s", figures[i])] = seconds[i];
    state.counters[fmt::format("{}_points", figures[i])] = static_cast<double>(points[i]);
  }
  state.SetLabel(method == FrfMethod::simulation ? "simulation (exact, from rest)" : "continuation");
}
BENCHMARK(BM_SevenPaperFigures)->Arg(0)->Arg(1)->Iterations(1)->Unit(benchmark::kSecond)->UseRealTime();

}  // namespace
