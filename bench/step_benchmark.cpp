// Time-history cost: one Newmark step (no event in it) and whole runs with pounding, for two
// frames of 1 to 200 storeys (2×1, 2×10, 2×20, 2×50, 2×100, 2×200). Cost per step must grow linearly with the storeys (banded
// matrices, interleaved DOFs) and a 2 × 1 step must stay well under 1 µs.

#include <cmath>
#include <numbers>
#include <vector>

#include <benchmark/benchmark.h>

#include "poundsim/model/dimensionless.hpp"
#include "poundsim/integrate/simulator.hpp"
#include "poundsim/units.hpp"

namespace {

using namespace poundsim;

/// The paper's Fig. 2c frames (per storey), `storeys` high, gap δ̄ = `delta`.
Model paper_model(int storeys, double delta) {
  DimensionlessParameters p{.lambda2 = 200, .alpha = 0.25, .beta = 1, .gamma = 0.5, .xi = 0.05,
                            .delta = delta, .eta = 0.125, .mu = 1, .epsilon = 0.5,
                            .restitution = 0.75};
  return make_model(p, {storeys, storeys});
}

HarmonicExcitation excitation_for(const Model& m, double ratio) {
  return {0.2 * standard_gravity, ratio * fundamental_frequency(m.frames[0])};
}

/// One grid step without events: the gap is so wide that the frames never touch.
void BM_StepWithoutContact(benchmark::State& state) {
  const int storeys = static_cast<int>(state.range(0));
  const Model m = paper_model(storeys, 1e6);
  Simulator sim(m, excitation_for(m, 0.8), TimeHistoryOptions{.dt = 1e-3});
  for (auto _ : state) {
    sim.step();
  }
  state.SetItemsProcessed(state.iterations());
  state.counters["dofs"] = 2.0 * storeys;
  state.counters["ns_per_step_per_dof"] = benchmark::Counter(
      static_cast<double>(state.iterations()) * 2.0 * storeys,
      benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}
BENCHMARK(BM_StepWithoutContact)->Arg(1)->Arg(10)->Arg(20)->Arg(50)->Arg(100)->Arg(200);

/// One grid step of `m` with its Hertzdamp contacts pressed (a soft frame left of a stiff one, no
/// gap, a varying ground push), with Newton's iterations per step.
void step_pressed(benchmark::State& state, const Model& m) {
  // A push of −3 ± 1 m/s² at 1.5 Hz: the contacts stay pressed, and their forces keep changing
  // (a constant push would settle into a static state that converges in one iteration).
  std::vector<double> time, acceleration;
  // Sampled every 10 ms for 10⁴ s: longer than any benchmark run (which would else end in free
  // vibration, with contacts opening).
  for (int i = 0; i <= 1000000; ++i) {
    time.push_back(1e-2 * i);
    acceleration.push_back(-3.0 + std::sin(2 * std::numbers::pi * 1.5 * 1e-2 * i));
  }
  Simulator sim(m, RecordExcitation{time, acceleration, "pressing"}, TimeHistoryOptions{.dt = 1e-3});
  sim.advance_to(20.0);
  const auto steps0 = sim.statistics().newton_steps, iterations0 = sim.statistics().newton_iterations;
  const auto events0 = sim.statistics().events;
  for (auto _ : state) {
    sim.step();
  }
  const auto& stats = sim.statistics();
  state.SetItemsProcessed(state.iterations());
  state.counters["newton_iterations_per_step"] =
      static_cast<double>(stats.newton_iterations - iterations0) / static_cast<double>(stats.newton_steps - steps0);
  state.counters["events"] = static_cast<double>(stats.events - events0);
}

const Hertzdamp kPressedContact{.parameters = {.stiffness = 1e10, .gap = 0.0, .restitution = 0.6}};

/// Two 10-storey frames pressed together at every floor: ten smooth contacts solved by Newton
/// iterations at each step, against BM_StepWithoutContact/10 (it should stay within 3×).
void BM_StepWithHertzdampAtEveryFloor(benchmark::State& state) {
  step_pressed(state, make_model({make_uniform_frame(10, 1e4, 2e7, 2e5, "soft"), make_uniform_frame(10, 1e4, 4e8, 4e6, "stiff")},
                                 GapLaw(kPressedContact)));
}
BENCHMARK(BM_StepWithHertzdampAtEveryFloor);

/// The same frames with each slab of the left one pressed on the right one's column at mid-height
/// of the storey below the facing floor (docs/model.md#slab-to-column): ten contacts of three DOFs
/// each (the first storey's with the ground), against BM_StepWithHertzdampAtEveryFloor.
void BM_StepWithHertzdampSlabsOnColumns(benchmark::State& state) {
  std::vector<FloorPair> pairs;
  for (int i = 0; i < 10; ++i) {
    pairs.push_back({.left_frame = 0, .left_floor = i, .right_floor = i,
                     .column = ColumnStrike{.struck = Side::right, .weight = 0.5}});
  }
  step_pressed(state, make_model({make_uniform_frame(10, 1e4, 2e7, 2e5, "soft"), make_uniform_frame(10, 1e4, 4e8, 4e6, "stiff")},
                                 GapLaw(kPressedContact), {}, pairs));
}
BENCHMARK(BM_StepWithHertzdampSlabsOnColumns);

/// A whole 20 s run of one 10-storey frame under a harmonic ground motion that makes its lower
/// storeys yield again and again: linear storeys (0), bilinear (1, Newmark, yield and unload
/// events), bilinear with the exact integrator (2), Bouc–Wen (3, Newton at every step) — the
/// cost of inelastic storeys against the linear frame.
void BM_WholeRunWithYieldingStoreys(benchmark::State& state) {
  const int law = static_cast<int>(state.range(0));
  Frame frame = make_uniform_frame(10, 1e5, 2e8, 2e5, "frame");
  if (law == 1 || law == 2) {
    frame.storey_law = PerStorey<BilinearStorey>{
        std::vector<BilinearStorey::Parameters>(10, {.yield_drift = 0.004, .post_yield_ratio = 0.05})};
  } else if (law == 3) {
    frame.storey_law = PerStorey<BoucWenStorey>{std::vector<BoucWenStorey::Parameters>(10, {.yield_drift = 0.004, .post_yield_ratio = 0.05, .n = 4})};
  }
  const Model m = make_model({frame}, PaperGap{});
  TimeHistoryOptions options{.dt = 1e-3, .integrator = law == 2 ? Integrator::exact : Integrator::newmark};
  std::int64_t steps = 0, yields = 0;
  for (auto _ : state) {
    Simulator sim(m, HarmonicExcitation{6.0, 9.0}, options);
    sim.advance_to(10.0);
    steps += sim.statistics().steps;
    for (const FloorResponse& f : sim.statistics().floors) yields += f.yield_excursions;
  }
  state.SetItemsProcessed(steps);
  state.counters["yield_excursions_per_run"] = static_cast<double>(yields) / static_cast<double>(state.iterations());
  state.counters["ns_per_step"] =
      benchmark::Counter(static_cast<double>(steps), benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}
BENCHMARK(BM_WholeRunWithYieldingStoreys)->DenseRange(0, 3)->Unit(benchmark::kMillisecond);

/// A whole 20 s run of the Fig. 2c system scaled to `storeys`, with contacts and impacts.
void BM_WholeRunWithPounding(benchmark::State& state) {
  const int storeys = static_cast<int>(state.range(0));
  const Model m = paper_model(storeys, 0.25);
  std::int64_t steps = 0, events = 0, trial_substeps = 0, grazing_checks = 0;
  for (auto _ : state) {
    Simulator sim(m, excitation_for(m, 0.8), TimeHistoryOptions{.dt = 1e-3});
    sim.advance_to(20.0);
    steps += sim.statistics().steps;
    events += sim.statistics().events;
    trial_substeps += sim.statistics().guard_evaluations - sim.statistics().grazing_checks;
    grazing_checks += sim.statistics().grazing_checks;
  }
  state.SetItemsProcessed(steps);
  state.counters["events_per_run"] =
      static_cast<double>(events) / static_cast<double>(state.iterations());
  // About 3 on average with pounding at many floors: the sub-steps that locate events,
  // and apart from them the sub-steps that check a step for a guard rising and falling inside it.
  const double per_event = events > 0 ? 1.0 / static_cast<double>(events) : 0.0;
  state.counters["location_substeps_per_event"] = static_cast<double>(trial_substeps) * per_event;
  state.counters["grazing_checks_per_event"] = static_cast<double>(grazing_checks) * per_event;
  state.counters["ns_per_step"] = benchmark::Counter(
      static_cast<double>(steps), benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}
BENCHMARK(BM_WholeRunWithPounding)->Arg(1)->Arg(10)->Arg(20)->Arg(50)->Arg(100)->Arg(200)->Unit(benchmark::kMillisecond);

/// The same 20 s run with the exact integrator, sampled every 1e-3 s.
void BM_WholeRunExact(benchmark::State& state) {
  const int storeys = static_cast<int>(state.range(0));
  const Model m = paper_model(storeys, 0.25);
  std::int64_t samples = 0;
  for (auto _ : state) {
    Simulator sim(m, excitation_for(m, 0.8),
                  TimeHistoryOptions{.dt = 1e-3, .integrator = Integrator::exact});
    sim.advance_to(20.0);
    samples += sim.statistics().steps;
  }
  state.SetItemsProcessed(samples);
}
BENCHMARK(BM_WholeRunExact)->Arg(1)->Arg(3)->Arg(10)->Unit(benchmark::kMillisecond);

}  // namespace

/// 1 s of the harmonic response of a frame beside a neighbour `range(0)` times its frequency
/// (ratio 10⁶: a wall), exact integrator, no contact. The cost must not grow with the ratio
/// (energy integrals by quadrature took 6.9 s at 8·10⁴; the closed forms do not grow).
void BM_ExactBesideAWall(benchmark::State& state) {
  const double ratio = static_cast<double>(state.range(0));
  const double k = 200.0;
  const Model m = make_model({make_uniform_frame(1, 1.0, k, 1.4, "frame"),
                              make_uniform_frame(1, 1.0, k * ratio * ratio, 0.0, "wall")},
                             GapProperties{.gap = 0.1, .restitution = 0.5});
  for (auto _ : state) {
    Simulator sim(m, HarmonicExcitation{.amplitude = 2.0, .omega = 0.8 * std::sqrt(k)},
                  TimeHistoryOptions{.dt = 1e-3, .integrator = Integrator::exact});
    sim.advance_to(1.0);
    benchmark::DoNotOptimize(sim.state().u(0));
  }
}
BENCHMARK(BM_ExactBesideAWall)->Arg(1)->Arg(100)->Arg(10000)->Arg(80000)->Arg(1000000)
    ->Unit(benchmark::kMillisecond);
