// The channels of a time history (analysis/channels.hpp): every channel a model offers, the
// default selection (history.csv as it always was: the golden outputs check its bits), patterns
// that choose frames, floors and quantities, and each channel's value against the simulator's
// state and the closed relations between them (a_abs = a + a_g, drift ratio = drift ÷ h, a
// linear storey's restoring force k·drift).
#include "poundsim/analysis/channels.hpp"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "poundsim/io/input.hpp"
#include "poundsim/io/time_history_run.hpp"
#include "poundsim/model/model.hpp"
#include "test_files.hpp"

namespace poundsim {
namespace {

/// A 3-storey frame (3.0 m storeys) beside a 2-storey one without heights, pounding through
/// Kelvin–Voigt contacts under a harmonic ground motion.
Model two_frames(bool heights = true) {
  Frame left = make_uniform_frame(3, 1e5, 1e8, 2e5, "left");
  if (heights) left.storey_height = {3.0, 3.0, 3.0};
  Frame right = make_uniform_frame(2, 1e5, 4e8, 2e5, "right");
  return make_model({left, right}, GapLaw(KelvinVoigt{.parameters = {.stiffness = 1e9, .gap = 0.005, .restitution = 0.6}}));
}

std::vector<std::string> names_of(const HistoryChannels& c) {
  std::vector<std::string> out;
  for (const Channel& channel : c.channels()) out.push_back(channel.name);
  return out;
}

TEST(Channels, TheDefaultIsTheHistoryPoundsimAlwaysWrote) {
  const HistoryChannels c(two_frames());
  EXPECT_EQ(names_of(c),
            (std::vector<std::string>{"u_1_1", "u_1_2", "u_1_3", "u_2_1", "u_2_2", "v_1_1", "v_1_2", "v_1_3", "v_2_1",
                                      "v_2_2", "a_1_1", "a_1_2", "a_1_3", "a_2_1", "a_2_2", "V_1", "V_2", "F_1_1",
                                      "F_1_2", "E_input", "E_kinetic", "E_storey_strain", "E_gap_strain",
                                      "E_storey_damping", "E_gap_damping", "E_impact", "E_residual"}));
  // A frame with an inelastic storey law adds its drifts and storey forces, and the hysteretic energy.
  Model inelastic = two_frames();
  inelastic.frames[1].storey_law = PerStorey<BilinearStorey>{
      std::vector<BilinearStorey::Parameters>(2, {.yield_drift = 0.01, .post_yield_ratio = 0.1})};
  const std::vector<std::string> names = names_of(HistoryChannels(inelastic));
  const std::vector<std::string> tail(names.end() - 14, names.end());
  EXPECT_EQ(tail, (std::vector<std::string>{"F_1_2", "drift_2_1", "drift_2_2", "Fs_2_1", "Fs_2_2", "E_input",
                                            "E_kinetic", "E_storey_strain", "E_gap_strain", "E_storey_damping",
                                            "E_gap_damping", "E_impact", "E_storey_hysteretic", "E_residual"}));
}

TEST(Channels, PatternsChooseFramesFloorsAndQuantitiesInTheModelsOrder) {
  const Model m = two_frames();
  const std::vector<std::string> patterns{"drift_ratio_*", "u_*_2", "a_abs_1_?", "s_*", "E_in*"};
  const HistoryChannels c(m, patterns);
  EXPECT_EQ(names_of(c), (std::vector<std::string>{"u_1_2", "u_2_2", "a_abs_1_1", "a_abs_1_2", "a_abs_1_3", "s_1_1",
                                                   "s_1_2", "drift_ratio_1_1", "drift_ratio_1_2", "drift_ratio_1_3",
                                                   "E_input"}));
  std::vector<std::string_view> units;
  for (const Channel& channel : c.channels()) units.push_back(channel.unit);
  EXPECT_EQ(units, (std::vector<std::string_view>{"m", "m", "m/s2", "m/s2", "m/s2", "m", "m", "1", "1", "1", "J"}));
  // A pattern that names nothing is refused, naming it; frame 2 has no heights, so no drift ratios.
  try {
    const std::vector<std::string> none{"u_*", "drift_ratio_2_*"};
    (void)HistoryChannels(m, none);
    ADD_FAILURE() << "accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("\"drift_ratio_2_*\" names no channel of this model"), std::string::npos)
        << e.what();
  }
}

TEST(Channels, EachChannelReadsTheState) {
  const Model m = two_frames();
  const std::vector<std::string> all{"*"};
  const HistoryChannels c(m, all);
  Simulator sim(m, HarmonicExcitation{6.0, 9.0}, TimeHistoryOptions{.dt = 1e-3});
  std::vector<double> row(c.size());
  const DofLayout layout(m);
  int contacts = 0;
  for (int k = 1; k <= 300; ++k) {
    sim.advance_to(0.01 * k);
    c.sample(sim, row);
    const KinematicState& x = sim.state();
    for (std::size_t i = 0; i < c.size(); ++i) {
      const Channel& ch = c.channels()[i];
      const int d = ch.index;
      switch (ch.quantity) {
        case Quantity::displacement: EXPECT_EQ(row[i], x.u(d)); break;
        case Quantity::absolute_acceleration: EXPECT_EQ(row[i], x.a(d) + x.ground); break;
        case Quantity::drift: {
          const int below = layout.below(d);
          EXPECT_EQ(row[i], x.u(d) - (below >= 0 ? x.u(below) : 0.0));
          break;
        }
        case Quantity::drift_ratio: EXPECT_EQ(row[i], sim.storey_drift(d) / 3.0); break;
        case Quantity::storey_force: {
          // A linear storey's restoring force is its spring's, k·drift (its dashpot is damping).
          const Frame& frame = m.frames[static_cast<std::size_t>(layout.frame_of(d))];
          EXPECT_DOUBLE_EQ(row[i], frame.stiffness[static_cast<std::size_t>(layout.floor_of(d))] * sim.storey_drift(d))
              << ch.name;
          break;
        }
        case Quantity::gap_shortening: EXPECT_EQ(row[i], sim.shortening(d)); break;
        case Quantity::gap_force:
          EXPECT_EQ(row[i], sim.gap_force(d));
          contacts += row[i] > 0 ? 1 : 0;
          break;
        case Quantity::base_shear: EXPECT_EQ(row[i], sim.base_shear(d)); break;
        default: break;
      }
    }
    EXPECT_EQ(row.back(), sim.energy().residual());
  }
  EXPECT_GT(contacts, 0);  // the frames pounded: the gap channels were not all zeros
}

TEST(Channels, TheOutputTableChoosesHistoryCsvsColumns) {
  const std::string text =
      "[[frames]]\nstoreys = 3\nmass = 1e5\nstiffness = 1e8\ndamping = 2e5\nstorey_height = 3.0\n"
      "[[frames]]\nstoreys = 2\nmass = 1e5\nstiffness = 4e8\ndamping = 2e5\nstorey_height = 3.0\n"
      "[gap_elements]\nlaw = \"kelvin_voigt\"\nstiffness = 1e9\ngap = 0.005\nrestitution = 0.6\n"
      "[output]\nchannels = [\"a_abs_*_2\", \"drift_ratio_1_*\", \"F_*\"]\n"
      "[excitation]\nkind = \"harmonic\"\namplitude_g = 0.6\nomega = 9.0\n"
      "[analysis]\nkind = \"time_history\"\nduration = 0.5\ndt = 0.001\noutput_dt = 0.01\n";
  const io::RunInput in = io::read_input_string(text, "channels.toml", ".");
  EXPECT_EQ(in.channels, (std::vector<std::string>{"a_abs_*_2", "drift_ratio_1_*", "F_*"}));
  const std::filesystem::path dir = std::filesystem::temp_directory_path() / "poundsim_channels";
  std::filesystem::remove_all(dir);
  (void)io::run_time_history(in, dir);
  const std::string history = testing::slurp(dir / "history.csv");
  EXPECT_EQ(history.substr(0, history.find('\n')),
            "t_s,a_abs_1_2_m_s2,a_abs_2_2_m_s2,F_1_1_N,F_1_2_N,drift_ratio_1_1,drift_ratio_1_2,drift_ratio_1_3");
  EXPECT_EQ(std::count(history.begin(), history.end(), '\n'), 52);  // the header and 51 instants
  std::filesystem::remove_all(dir);
  // The echo keeps the selection.
  const io::RunInput again = io::read_input_string(io::to_toml(in), "input.toml", ".");
  EXPECT_EQ(again.channels, in.channels);
  // A pattern that names nothing is refused naming the key; so is [output] for another analysis.
  std::string bad = text;
  bad.replace(bad.find("\"F_*\""), 5, "\"F_2_*\"");
  try {
    (void)io::read_input_string(bad, "channels.toml", ".");
    ADD_FAILURE() << "accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("output.channels: \"F_2_*\" names no channel"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace poundsim
