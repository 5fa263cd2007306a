// Floors at different heights (docs/input.md, gap_elements.pairing): a 6-storey frame of 3.0 m
// storeys beside a 5-storey frame of 3.6 m storeys, whose roofs stand at 18 m. The default
// pairing by floor number refuses them with a message that says how to pair them; pairing by
// height joins the two roofs; listed pairs join any floors, and the element then acts between
// exactly those floors (impacts, energy, both integrators); the echo writes the pairs back.
#include <cmath>
#include <string>

#include <gtest/gtest.h>

#include "poundsim/integrate/simulator.hpp"
#include "poundsim/io/input.hpp"
#include "poundsim/model/model.hpp"

namespace poundsim {
namespace {

std::string model_text(const std::string& gap_keys) {
  return "[[frames]]\nstoreys = 6\nmass = 2e5\nstiffness = 3e8\ndamping = 0\nstorey_height = 3.0\n"
         "[[frames]]\nstoreys = 5\nmass = 2e5\nstiffness = 2e8\ndamping = 0\nstorey_height = 3.6\n"
         "[gap_elements]\nlaw = \"kelvin_voigt\"\nstiffness = 2e9\ngap = 0.01\nrestitution = 0.7\n" +
         gap_keys +
         "\n[initial]\nvelocity = [[0.3, 0.3, 0.3, 0.3, 0.3, 0.3], [-0.3, -0.3, -0.3, -0.3, -0.3]]\n"
         "[analysis]\nkind = \"time_history\"\nduration = 1.0\ndt = 0.0005\n[excitation]\nkind = \"none\"\n";
}

io::RunInput read(const std::string& gap_keys) {
  return io::read_input_string(model_text(gap_keys), "pairing.toml", ".");
}

std::string error_of(const std::string& gap_keys) {
  try {
    (void)read(gap_keys);
  } catch (const InputError& e) {
    return e.what();
  }
  return "no error";
}

TEST(FloorPairing, FloorNumbersAtDifferentHeightsAreRefusedWithHowToPairThem) {
  const std::string e = error_of("");
  EXPECT_NE(e.find("frames[2].storey_height"), std::string::npos) << e;
  EXPECT_NE(e.find("floor 1 stands 3.6 m above the ground, floor 1 of frame 1 3 m"), std::string::npos) << e;
  EXPECT_NE(e.find("pairing = \"height\""), std::string::npos) << e;
  EXPECT_NE(e.find("[[gap_elements.pair]]"), std::string::npos) << e;
  EXPECT_NE(e.find("frames = [1, 2], floors = [left floor, right floor]"), std::string::npos) << e;
}

TEST(FloorPairing, ByHeightJoinsTheFloorsThatStandAtTheSameHeight) {
  // 6 × 3.0 m and 5 × 3.6 m: only the roofs meet (18 m; 5 × 3.6 is 18.000000000000004).
  const io::RunInput in = read("pairing = \"height\"");
  ASSERT_EQ(in.model.gap_count(), 1);
  const GapElement& g = in.model.gaps[0];
  EXPECT_EQ(g.floor, 5);
  EXPECT_EQ(g.floor_right(), 4);
  const DofLayout layout(in.model);
  EXPECT_EQ(layout.gap_left(0), layout.dof(0, 5));
  EXPECT_EQ(layout.gap_right(0), layout.dof(1, 4));
  EXPECT_EQ(describe(make_links(in.model, layout).back(), layout),
            "the Kelvin–Voigt contact between floor 6 of frame 1 and floor 5 of frame 2");
  // Without heights there is nothing to pair by.
  std::string text = model_text("pairing = \"height\"");
  text.erase(text.find("storey_height = 3.6\n"), 20);
  try {
    (void)io::read_input_string(text, "pairing.toml", ".");
    ADD_FAILURE() << "accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("frames[2]: missing key: storey_height"), std::string::npos) << e.what();
  }
}

TEST(FloorPairing, ListedPairsAreCheckedAndNamedByTheirKeys) {
  EXPECT_NE(error_of("pairing = \"listed\"").find("gap_elements.pairing: \"listed\" needs a [[gap_elements.pair]]"),
            std::string::npos);
  const std::string twice = error_of(
      "pairing = \"listed\"\n[[gap_elements.pair]]\nframes = [1, 2]\nfloors = [6, 5]\n"
      "[[gap_elements.pair]]\nframes = [1, 2]\nfloors = [5, 5]");
  EXPECT_NE(twice.find("gap_elements.pair[2].floors"), std::string::npos) << twice;
  EXPECT_NE(twice.find("already has a gap element"), std::string::npos) << twice;
  const std::string high = error_of("pairing = \"listed\"\n[[gap_elements.pair]]\nframes = [1, 2]\nfloors = [6, 6]");
  EXPECT_NE(high.find("floors"), std::string::npos) << high;
  EXPECT_NE(high.find("frame 2 has 5 floors"), std::string::npos) << high;
  const std::string stray = error_of("[[gap_elements.pair]]\nframes = [1, 2]\nfloors = [6, 5]");
  EXPECT_NE(stray.find("pairing = \"listed\""), std::string::npos) << stray;
}

// Two listed pairs, the roofs and floor 4 of the left frame against floor 3 of the right
// (12 m and 10.8 m: a slab that strikes the neighbour's slab 1.2 m lower, as two rigid floors).
// The frames are released towards each other: each element's contacts are between its own two
// floors, momentum is exchanged between exactly those floors, the balance closes, and Newmark
// agrees with the exact integrator.
TEST(FloorPairing, ListedPairsPoundBetweenExactlyTheirFloors) {
  const std::string pairs =
      "pairing = \"listed\"\n[[gap_elements.pair]]\nframes = [1, 2]\nfloors = [4, 3]\n"
      "[[gap_elements.pair]]\nframes = [1, 2]\nfloors = [6, 5]";
  const io::RunInput in = read(pairs);
  ASSERT_EQ(in.model.gap_count(), 2);
  EXPECT_EQ(in.model.gaps[0].floor, 3);
  EXPECT_EQ(in.model.gaps[0].floor_right(), 2);
  std::vector<double> peaks[2];
  for (const Integrator integrator : {Integrator::newmark, Integrator::exact}) {
    TimeHistoryOptions options = in.analysis.options;
    options.integrator = integrator;
    Simulator sim(in.model, in.excitation, options, in.initial);
    sim.advance_to(1.0);
    const ResponseStatistics& st = sim.statistics();
    EXPECT_GT(st.gaps[0].contacts, 0);
    EXPECT_GT(st.gaps[1].contacts, 0);
    EXPECT_LT(sim.energy_meter().max_relative_residual(), 1e-9);
    // The peak approach of each facing pair is that element's peak shortening plus its gap (the
    // shortening sampled at accepted states, the approach refined between them: 1e-5 m).
    ASSERT_EQ(st.neighbours.size(), 2U);
    EXPECT_EQ(st.neighbours[0].right_floor, 2);
    EXPECT_NEAR(st.neighbours[0].max_approach, st.gaps[0].shortening.value + 0.01, 1e-5);
    EXPECT_NEAR(st.neighbours[1].max_approach, st.gaps[1].shortening.value + 0.01, 1e-5);
    auto& p = peaks[integrator == Integrator::exact ? 1 : 0];
    for (const FloorResponse& f : st.floors) p.push_back(f.displacement.value);
    for (const GapResponse& g : st.gaps) p.push_back(g.force.value);
  }
  for (std::size_t i = 0; i < peaks[0].size(); ++i) {
    EXPECT_NEAR(peaks[0][i], peaks[1][i], 1e-3 * std::abs(peaks[1][i])) << i;
  }
  // The echo writes the pairs, and reads back to the same model.
  const io::RunInput again = io::read_input_string(io::to_toml(in), "input.toml", ".");
  ASSERT_EQ(again.model.gap_count(), 2);
  EXPECT_EQ(again.model.gaps[0].floor_right(), 2);
  EXPECT_EQ(again.model.gaps[1].floor_right(), 4);
  EXPECT_EQ(io::to_toml(again), io::to_toml(in));
}

}  // namespace
}  // namespace poundsim
