#pragma once
// Small models shared by the tests.

#include <bit>
#include <cmath>
#include <cstdint>
#include <numbers>
#include <string>
#include <utility>
#include <vector>

#include <fmt/format.h>
#include <gtest/gtest.h>

#include "poundsim/analysis/frequency_response.hpp"
#include "poundsim/model/dimensionless.hpp"
#include "poundsim/io/input.hpp"
#include "poundsim/model/model.hpp"
#include "poundsim/integrate/simulator.hpp"

namespace poundsim::testing {

/// Two single-storey frames: floor mass [kg], storey stiffness [N/m] and dashpot [N·s/m] of
/// each, joined by one gap element.
inline Model two_oscillators(double m1, double k1, double c1, double m2, double k2, double c2,
                             GapProperties gap) {
  return make_model({make_uniform_frame(1, m1, k1, c1, "1"), make_uniform_frame(1, m2, k2, c2, "2")},
                    gap);
}

/// Two 10-storey frames pressed together at every floor by Hertzdamp contacts: a soft frame
/// (10 t, 2e7 N/m per storey) left of a stiff one (4e8 N/m) with no gap, under a constant ground
/// acceleration of −2 m/s² (run it to 20 s to settle). Its steps are Newton steps of 10 contacts.
inline Model pressed_hertzdamp_frames() {
  return make_model({make_uniform_frame(10, 1e4, 2e7, 2e5, "soft"), make_uniform_frame(10, 1e4, 4e8, 4e6, "stiff")},
                    GapLaw(Hertzdamp{.parameters = {.stiffness = 1e10, .gap = 0.0, .restitution = 0.6}}));
}
inline RecordExcitation constant_push() { return RecordExcitation{{0.0, 1e4}, {-2.0, -2.0}, "constant"}; }

/// The paper's dimensionless systems (captions of Figs. 2–4).
inline DimensionlessParameters fig2(char panel) {
  DimensionlessParameters p{.lambda2 = 200, .alpha = 0.25, .beta = 1, .gamma = 0.5, .xi = 0.05,
                            .delta = 0.25};
  if (panel == 'a') p.restitution = 1.0;
  if (panel == 'b') p.restitution = 0.75;
  if (panel == 'c') {
    p.restitution = 0.75;
    p.eta = 0.125;
    p.mu = 1;
    p.epsilon = 0.5;
  }
  return p;
}

inline DimensionlessParameters fig4(char panel) {
  DimensionlessParameters p{.lambda2 = 200, .alpha = 2, .beta = 1, .gamma = 1, .xi = 0.05,
                            .delta = 0, .restitution = 1.0};
  if (panel == 'b') {
    p.eta = 0.5;
    p.mu = 1;
    p.epsilon = 0.5;
  }
  return p;
}

/// The `[model]` table of an input file for the two frames of `storeys` floors (TOML array text,
/// e.g. "[1, 3]") with the dimensionless parameters `p`, one key per line as the docs write it.
inline std::string model_toml(const std::string& storeys, const DimensionlessParameters& p) {
  using io::toml_float;
  return fmt::format(
      "[model]\nstoreys = {}\n[model.dimensionless]\nlambda2 = {}\nalpha = {}\nbeta = {}\ngamma = {}\n"
      "xi = {}\ndelta = {}\neta = {}\nmu = {}\nepsilon = {}\nrestitution = {}\n",
      storeys, toml_float(p.lambda2), toml_float(p.alpha), toml_float(p.beta), toml_float(p.gamma),
      toml_float(p.xi), toml_float(p.delta), toml_float(p.eta), toml_float(p.mu), toml_float(p.epsilon),
      toml_float(p.restitution));
}

inline HarmonicExcitation harmonic(const Model& m, double amplitude_g, double ratio) {
  return {amplitude_g * 9.81, ratio * fundamental_frequency(m.frames.front())};
}

/// Total momentum Σ m u̇ of all floors [N·s].
inline double momentum(const Simulator& sim) {
  double p = 0;
  for (int i = 0; i < sim.layout().size(); ++i) {
    const Frame& f = sim.model().frames[sim.layout().frame_of(i)];
    p += f.mass[sim.layout().floor_of(i)] * sim.state().v(i);
  }
  return p;
}

/// Two runs' statistics the same to the bit: every floor's peaks with their times, shears,
/// neighbours' approaches, gap elements' counts and peaks, events (and there were events).
/// Every peak of the frames — each floor's five with where they peaked, its yield excursions, the
/// base and storey shears, the approach of facing floors — equal in both.
inline void expect_same_frame_peaks(const ResponseStatistics& with, const ResponseStatistics& without) {
  ASSERT_EQ(with.floors.size(), without.floors.size());
  ASSERT_FALSE(with.floors.empty());
  for (std::size_t i = 0; i < with.floors.size(); ++i) {
    const FloorResponse &a = with.floors[i], &b = without.floors[i];
    for (const auto& [p, q] : {std::pair{a.displacement, b.displacement}, std::pair{a.velocity, b.velocity},
                               std::pair{a.acceleration, b.acceleration},
                               std::pair{a.absolute_acceleration, b.absolute_acceleration}, std::pair{a.drift, b.drift}}) {
      // To the bit (a peak is never −0, but say so rather than rely on it).
      EXPECT_EQ(std::bit_cast<std::uint64_t>(p.value), std::bit_cast<std::uint64_t>(q.value)) << "floor DOF " << i;
      EXPECT_EQ(p.time, q.time) << "floor DOF " << i;
    }
    EXPECT_EQ(a.yield_excursions, b.yield_excursions) << "floor DOF " << i;
  }
  ASSERT_EQ(with.base_shear.size(), without.base_shear.size());
  for (std::size_t f = 0; f < with.base_shear.size(); ++f) {
    EXPECT_EQ(with.base_shear[f].value, without.base_shear[f].value);
    EXPECT_EQ(with.base_shear[f].time, without.base_shear[f].time);
    EXPECT_EQ(with.storey_shear[f].value, without.storey_shear[f].value);
    EXPECT_EQ(with.storey_shear[f].time, without.storey_shear[f].time);
  }
  ASSERT_EQ(with.neighbours.size(), without.neighbours.size());
  for (std::size_t k = 0; k < with.neighbours.size(); ++k) {
    EXPECT_EQ(with.neighbours[k].max_approach, without.neighbours[k].max_approach);
    EXPECT_EQ(with.neighbours[k].max_approach_time, without.neighbours[k].max_approach_time);
  }
}

inline void expect_same_peaks(const ResponseStatistics& with, const ResponseStatistics& without) {
  expect_same_frame_peaks(with, without);
  ASSERT_EQ(with.gaps.size(), without.gaps.size());
  for (std::size_t p = 0; p < with.gaps.size(); ++p) {
    const GapResponse &a = with.gaps[p], &b = without.gaps[p];
    EXPECT_EQ(a.impacts, b.impacts);
    EXPECT_EQ(a.contacts, b.contacts);
    EXPECT_EQ(a.contact_time, b.contact_time);
    EXPECT_EQ(a.force.value, b.force.value);
    EXPECT_EQ(a.shortening.value, b.shortening.value);
    EXPECT_EQ(a.impact_velocity.value, b.impact_velocity.value);
    EXPECT_EQ(a.impulse.value, b.impulse.value);
  }
  EXPECT_GT(with.events, 0);
  EXPECT_EQ(with.events, without.events);
}

/// Two points of a frequency response to the bit (−0 told from +0): what frf.csv reports of them.
inline void expect_same_frf_point(const FrfPoint& a, const FrfPoint& b) {
  const auto bits = [](double x) { return std::bit_cast<std::uint64_t>(x); };
  EXPECT_EQ(bits(a.ratio), bits(b.ratio));
  EXPECT_EQ(bits(a.omega), bits(b.omega));
  EXPECT_EQ(a.branch, b.branch);
  EXPECT_EQ(a.periodicity, b.periodicity);
  EXPECT_EQ(a.transient_periods, b.transient_periods);
  EXPECT_EQ(a.events, b.events);
  EXPECT_EQ(a.impacts, b.impacts);
  for (const auto& [x, y] : {std::pair{&a.interacting, &b.interacting}, std::pair{&a.free, &b.free}}) {
    for (const auto& [p, q] : {std::pair{&x->base_shear, &y->base_shear}, std::pair{&x->storey_shear, &y->storey_shear},
                               std::pair{&x->top_displacement, &y->top_displacement}}) {
      ASSERT_EQ(p->size(), q->size());
      for (std::size_t f = 0; f < p->size(); ++f) EXPECT_EQ(bits((*p)[f]), bits((*q)[f])) << "frame " << f + 1;
    }
  }
}

}  // namespace poundsim::testing
