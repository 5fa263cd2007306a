// The time-stepping loop allocates nothing: steps between events reuse the factorisation of
// their phase and preallocated work vectors. Counted by interposing malloc (glibc).

#include <array>
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <exception>

#include <gtest/gtest.h>

#include "poundsim/integrate/lockstep.hpp"
#include "poundsim/integrate/simulator.hpp"
#include "test_models.hpp"

extern "C" {
void* __libc_malloc(std::size_t);
void* __libc_calloc(std::size_t, std::size_t);
void* __libc_realloc(void*, std::size_t);
void* __libc_memalign(std::size_t, std::size_t);
}

namespace {
std::atomic<bool> counting{false};
std::atomic<long> allocations{0};
void count() {
  if (counting.load(std::memory_order_relaxed)) allocations.fetch_add(1, std::memory_order_relaxed);
}
}  // namespace

extern "C" {
void* malloc(std::size_t n) {
  count();
  return __libc_malloc(n);
}
void* calloc(std::size_t n, std::size_t size) {
  count();
  return __libc_calloc(n, size);
}
void* realloc(void* p, std::size_t n) {
  count();
  return __libc_realloc(p, n);
}
int posix_memalign(void** out, std::size_t alignment, std::size_t n) {
  count();
  *out = __libc_memalign(alignment, n);
  return *out != nullptr ? 0 : 12;
}
void* aligned_alloc(std::size_t alignment, std::size_t n) {
  count();
  return __libc_memalign(alignment, n);
}
}

namespace poundsim {
namespace {

long allocations_during(const std::function<void()>& work) {
  allocations = 0;
  counting = true;
  work();
  counting = false;
  return allocations.load();
}

TEST(Allocation, CounterSeesEigenAndStandardAllocations) {
  // The interposition works: a dynamic Eigen vector and a std::vector both count.
  const long n = allocations_during([] {
    Eigen::VectorXd v(1000);
    std::vector<int> w(10);
    v.setZero();
    EXPECT_EQ(v.sum() + static_cast<double>(w.size()), 10.0);
  });
  EXPECT_GE(n, 2);
}

TEST(Allocation, StepsWithoutEventsAllocateNothing) {
  DimensionlessParameters p = testing::fig2('c');
  p.delta = 1e6;  // never closes
  const Model model = make_model(p, {20, 20});
  Simulator sim(model, testing::harmonic(model, 0.2, 0.8), TimeHistoryOptions{.dt = 1e-3});
  sim.advance_to(0.1);
  const long n = allocations_during([&] {
    for (int k = 0; k < 2000; ++k) sim.step();
  });
  EXPECT_EQ(sim.statistics().events, 0);
  EXPECT_EQ(n, 0);
}

TEST(Allocation, LockstepStepsAllocateNothing) {
  // Two Fig. 2c systems in lockstep (integrate/lockstep.hpp), apart: once the batch has its shape,
  // gathering, stepping and writing back the lanes allocate nothing.
  DimensionlessParameters p = testing::fig2('c');
  p.delta = 1e6;
  const Model model = make_model(p, {1, 1});
  Simulator a(model, testing::harmonic(model, 0.2, 0.8), TimeHistoryOptions{.dt = 1e-3});
  Simulator b(model, testing::harmonic(model, 0.2, 1.1), TimeHistoryOptions{.dt = 2e-3});
  for (Simulator* sim : {&a, &b}) {
    sim->record_responses(false);
    sim->meter_energy(false);
  }
  const std::array<Simulator*, 2> lanes{&a, &b};
  std::array<std::exception_ptr, 2> errors;
  Lockstep batch;
  batch.step(lanes, 10, errors);
  const long n = allocations_during([&] {
    for (int k = 0; k < 20; ++k) batch.step(lanes, 100, errors);
  });
  // Every step in lockstep but those a guard sent back to step() (grazing checks: no event).
  EXPECT_EQ(batch.counts().lean + batch.counts().general, 2 * 2010);
  EXPECT_GT(batch.counts().lean, 2 * 2000);
  EXPECT_EQ(n, 0);
}

TEST(Allocation, ExactStepsWithoutEventsAllocateNothing) {
  // Sampling the exact trajectory, its peaks and its closed-form energy integrals.
  DimensionlessParameters p = testing::fig2('c');
  p.delta = 1e6;
  const Model model = make_model(p, {5, 5});
  Simulator sim(model, testing::harmonic(model, 0.2, 0.8),
                TimeHistoryOptions{.dt = 1e-3, .integrator = Integrator::exact});
  sim.advance_to(0.1);
  const long n = allocations_during([&] {
    for (int k = 0; k < 2000; ++k) sim.step();
  });
  EXPECT_EQ(sim.statistics().events, 0);
  EXPECT_EQ(n, 0);
}

TEST(Allocation, ExactContactsAndSeparationsInKnownPhasesAllocateNothing) {
  // Every event of the exact integrator starts a segment: the trajectory's particular solution
  // and modal coordinates, the guard expansion, the energy integrals. Once the phases are known
  // (the first 20 s meet them all), none of it allocates. ε so large that no stop is reached:
  // contacts and separations only (an impact's resolution still allocates its work vectors).
  DimensionlessParameters p = testing::fig2('c');
  p.epsilon = 1e6;
  const Model model = make_model(p, {3, 3});
  Simulator sim(model, testing::harmonic(model, 0.2, 0.8),
                TimeHistoryOptions{.dt = 1e-3, .integrator = Integrator::exact});
  sim.advance_to(20.0);
  const std::int64_t events = sim.statistics().events, phases = sim.statistics().phases_factorised;
  const long n = allocations_during([&] { sim.advance_to(40.0); });
  EXPECT_GE(sim.statistics().events - events, 50);  // 96 when written
  EXPECT_EQ(sim.statistics().phases_factorised, phases);
  EXPECT_EQ(n, 0);
}

TEST(Allocation, StepsInALockedPhaseAllocateNothing) {
  // Reduced coordinates, stop reactions and their guards are evaluated every step.
  const Model model =
      testing::two_oscillators(1, 25, 1, 1, 400, 4, GapProperties{.gap = 0.02, .restitution = 0.5});
  Simulator sim(model, RecordExcitation{{0.0, 1000.0}, {-2.0, -2.0}, "constant"},
                TimeHistoryOptions{.dt = 1e-3});
  sim.advance_to(20.0);
  ASSERT_EQ(PaperGap::gap_mode(sim.configuration()[0]), GapMode::locked);
  const auto events = sim.statistics().events;
  const long n = allocations_during([&] { sim.advance_to(30.0); });
  EXPECT_EQ(sim.statistics().events, events);
  EXPECT_EQ(n, 0);
}

TEST(Allocation, StepsWithModalAndGroundDampingAllocateNothing) {
  // Dashpots that are not links: their power in the energy balance every step.
  DimensionlessParameters p = testing::fig2('c');
  p.delta = 1e6;
  Model model = make_model(p, {6, 6});
  for (Frame& frame : model.frames) {
    frame.modal_damping_ratios.assign(6, 0.03);
    frame.ground_damping.assign(6, 0.1);
  }
  Simulator sim(model, testing::harmonic(model, 0.2, 0.8), TimeHistoryOptions{.dt = 1e-3});
  sim.advance_to(0.1);
  const long n = allocations_during([&] {
    for (int k = 0; k < 2000; ++k) sim.step();
  });
  EXPECT_EQ(sim.statistics().events, 0);
  EXPECT_GT(sim.energy().storey_damping, 0.0);
  EXPECT_EQ(n, 0);
}

/// A second of Newmark steps at 1e-3 s with every smooth contact of `model` pressed by a constant
/// push after 20 s: forces, tangents and the tangent factorisation, no events.
void expect_pressed_newton_steps_allocate_nothing(const Model& model) {
  Simulator sim(model, testing::constant_push(), TimeHistoryOptions{.dt = 1e-3});
  sim.advance_to(20.0);
  for (int p = 0; p < model.gap_count(); ++p) ASSERT_GT(sim.gap_force(p), 0.0) << describe(model.gaps[p]);
  const auto events = sim.statistics().events;
  const auto newton_steps = sim.statistics().newton_steps;
  const long n = allocations_during([&] { sim.advance_to(21.0); });
  EXPECT_EQ(sim.statistics().events, events);
  EXPECT_EQ(sim.statistics().newton_steps, newton_steps + 1000);
  EXPECT_EQ(n, 0);
}

TEST(Allocation, NewtonStepsWithSmoothContactsAllocateNothing) {
  // Ten Hertzdamp contacts pressed at once.
  expect_pressed_newton_steps_allocate_nothing(testing::pressed_hertzdamp_frames());
}

TEST(Allocation, NewtonStepsWithSlabsOnColumnsAllocateNothing) {
  // Hertzdamp slabs pressed on the neighbour's columns (three or four DOFs a link: the point's
  // interpolation, its forces shared by weights, its tangent in six entries), and the roofs.
  Frame soft = make_uniform_frame(4, 1e4, 2e7, 2e5, "soft");
  soft.storey_height = {3.0, 3.0, 3.0, 3.0};
  Frame stiff = make_uniform_frame(4, 1e4, 4e8, 4e6, "stiff");
  stiff.storey_height = {4.0, 4.0, 4.0, 4.0};
  std::vector<FloorPair> pairs;
  for (const double w : {0.75, 0.5, 0.25}) {  // slabs at 3, 6 and 9 m on the columns of 4 m storeys
    const int floor = static_cast<int>(pairs.size());
    pairs.push_back({.left_frame = 0, .left_floor = floor, .right_floor = floor,
                     .column = ColumnStrike{.struck = Side::right, .weight = w}});
  }
  pairs.push_back({.left_frame = 0, .left_floor = 3, .right_floor = 2});  // 12 m, slab on slab
  expect_pressed_newton_steps_allocate_nothing(make_model(
      {soft, stiff}, GapLaw(Hertzdamp{.parameters = {.stiffness = 1e10, .gap = 0.0, .restitution = 0.6}}), {}, pairs));
}

TEST(Allocation, StepsWithYieldingStoreysAllocateNothing) {
  // Newmark with bilinear storeys yielding and unloading (events, the phase's state loads), and
  // with Bouc–Wen storeys (Newton on every step, trial and commit). (The exact integrator's
  // segments allocate when an event starts one, ExactTrajectory::start, as with contacts; its
  // steps without events are ExactStepsWithoutEventsAllocateNothing's.)
  for (const int law : {0, 2}) {
    Frame frame = make_uniform_frame(3, 1e5, 1e8, 1e5);
    if (law == 2) {
      frame.storey_law = PerStorey<BoucWenStorey>{std::vector<BoucWenStorey::Parameters>(3, {.yield_drift = 0.002, .n = 4})};
    } else {
      frame.storey_law = PerStorey<BilinearStorey>{
          std::vector<BilinearStorey::Parameters>(3, {.yield_drift = 0.002, .post_yield_ratio = 0.1})};
    }
    Simulator sim(make_model({frame}, PaperGap{}), HarmonicExcitation{8.0, 20.0}, TimeHistoryOptions{.dt = 1e-3});
    sim.advance_to(3.0);  // every phase it will visit is factorised by now
    const auto yields = sim.statistics().floors[0].yield_excursions;
    const long n = allocations_during([&] { sim.advance_to(3.3); });
    if (law == 0) {
      EXPECT_GT(sim.statistics().floors[0].yield_excursions, yields) << "law " << law;  // it yields meanwhile
    } else {
      EXPECT_GT(sim.energy().storey_hysteretic, 0.0);
    }
    EXPECT_EQ(n, 0) << "law " << law;
  }
}

}  // namespace
}  // namespace poundsim
