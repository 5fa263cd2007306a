#include "poundsim/analysis/channels.hpp"

#include <fnmatch.h>

#include <algorithm>
#include <array>
#include <stdexcept>

#include <fmt/format.h>

namespace poundsim {

namespace {

constexpr std::array<std::string_view, 9> kEnergyNames{"E_input",          "E_kinetic",      "E_storey_strain",
                                                       "E_gap_strain",     "E_storey_damping", "E_gap_damping",
                                                       "E_impact",         "E_storey_hysteretic", "E_residual"};

bool inelastic(const Frame& frame) { return !is_default(frame.storey_law); }

/// The channels of the default selection: every one but absolute accelerations, shortenings,
/// drift ratios, and the drifts and storey forces of linear frames.
bool in_default(const Channel& c, const Model& model, const DofLayout& layout) {
  switch (c.quantity) {
    case Quantity::absolute_acceleration:
    case Quantity::gap_shortening:
    case Quantity::drift_ratio: return false;
    case Quantity::drift:
    case Quantity::storey_force: return inelastic(model.frames[static_cast<std::size_t>(layout.frame_of(c.index))]);
    default: return true;
  }
}

}  // namespace

std::vector<Channel> HistoryChannels::available(const Model& model) {
  const DofLayout layout(model);
  std::vector<int> dofs;  // frame by frame, floor by floor
  for (int f = 0; f < model.frame_count(); ++f) {
    for (int i = 0; i < model.frames[static_cast<std::size_t>(f)].storeys(); ++i) dofs.push_back(layout.dof(f, i));
  }
  const auto label = [&](int dof) { return fmt::format("{}_{}", layout.frame_of(dof) + 1, layout.floor_of(dof) + 1); };
  std::vector<Channel> out;
  const auto per_floor = [&](Quantity q, std::string_view prefix, std::string_view unit) {
    for (const int d : dofs) out.push_back({.name = fmt::format("{}_{}", prefix, label(d)), .unit = unit, .quantity = q, .index = d});
  };
  per_floor(Quantity::displacement, "u", "m");
  per_floor(Quantity::velocity, "v", "m/s");
  per_floor(Quantity::acceleration, "a", "m/s2");
  per_floor(Quantity::absolute_acceleration, "a_abs", "m/s2");
  for (int f = 0; f < model.frame_count(); ++f) {
    out.push_back({.name = fmt::format("V_{}", f + 1), .unit = "N", .quantity = Quantity::base_shear, .index = f});
  }
  for (const Quantity q : {Quantity::gap_force, Quantity::gap_shortening}) {
    for (int p = 0; p < model.gap_count(); ++p) {
      const GapElement& g = model.gaps[static_cast<std::size_t>(p)];
      out.push_back({.name = fmt::format("{}_{}", q == Quantity::gap_force ? "F" : "s",
                                         joint_label(g.left_frame, g.floor, g.floor_right(), g.column)),
                     .unit = q == Quantity::gap_force ? "N" : "m",
                     .quantity = q,
                     .index = p});
    }
  }
  per_floor(Quantity::drift, "drift", "m");
  for (const int d : dofs) {
    const Frame& frame = model.frames[static_cast<std::size_t>(layout.frame_of(d))];
    if (frame.storey_height.empty()) continue;
    out.push_back({.name = "drift_ratio_" + label(d),
                   .unit = "1",
                   .quantity = Quantity::drift_ratio,
                   .index = d,
                   .height = frame.storey_height[static_cast<std::size_t>(layout.floor_of(d))]});
  }
  per_floor(Quantity::storey_force, "Fs", "N");
  const bool any_inelastic = std::any_of(model.frames.begin(), model.frames.end(), inelastic);
  for (std::size_t t = 0; t < kEnergyNames.size(); ++t) {
    if (static_cast<EnergyTerm>(t) == EnergyTerm::storey_hysteretic && !any_inelastic) continue;
    out.push_back({.name = std::string(kEnergyNames[t]), .unit = "J", .quantity = Quantity::energy, .index = static_cast<int>(t)});
  }
  return out;
}

HistoryChannels::HistoryChannels(const Model& model, std::span<const std::string> patterns) {
  std::vector<Channel> all = available(model);
  if (patterns.empty()) {
    const DofLayout layout(model);
    for (Channel& c : all) {
      if (in_default(c, model, layout)) channels_.push_back(std::move(c));
    }
    return;
  }
  std::vector<char> chosen(all.size(), 0);
  for (const std::string& pattern : patterns) {
    bool any = false;
    for (std::size_t k = 0; k < all.size(); ++k) {
      if (fnmatch(pattern.c_str(), all[k].name.c_str(), 0) == 0) chosen[k] = any = true;
    }
    if (!any) {
      throw std::invalid_argument(fmt::format(
          "\"{}\" names no channel of this model (channels: u_, v_, a_, a_abs_<frame>_<floor>, V_<frame>, "
          "F_, s_<frame>_<floor> of the gap elements, drift_, drift_ratio_ (frames with storey_height), "
          "Fs_<frame>_<floor>, E_input … E_residual; frames and floors from 1)",
          pattern));
    }
  }
  for (std::size_t k = 0; k < all.size(); ++k) {
    if (chosen[k] != 0) channels_.push_back(std::move(all[k]));
  }
}

void HistoryChannels::sample(const Simulator& sim, std::span<double> row) const {
  const KinematicState& x = sim.state();
  const EnergyBalance& e = sim.energy();
  for (std::size_t k = 0; k < channels_.size(); ++k) {
    const Channel& c = channels_[k];
    double& value = row[k];
    switch (c.quantity) {
      case Quantity::displacement: value = x.u(c.index); break;
      case Quantity::velocity: value = x.v(c.index); break;
      case Quantity::acceleration: value = x.a(c.index); break;
      case Quantity::absolute_acceleration: value = x.a(c.index) + x.ground; break;
      case Quantity::base_shear: value = sim.base_shear(c.index); break;
      case Quantity::gap_force: value = sim.gap_force(c.index); break;
      case Quantity::gap_shortening: value = sim.shortening(c.index); break;
      case Quantity::drift: value = sim.storey_drift(c.index); break;
      case Quantity::drift_ratio: value = sim.storey_drift(c.index) / c.height; break;
      case Quantity::storey_force: value = sim.storey_force(c.index); break;
      case Quantity::energy:
        switch (static_cast<EnergyTerm>(c.index)) {
          case EnergyTerm::input: value = e.input; break;
          case EnergyTerm::kinetic: value = e.kinetic; break;
          case EnergyTerm::storey_strain: value = e.storey_strain; break;
          case EnergyTerm::gap_strain: value = e.gap_strain; break;
          case EnergyTerm::storey_damping: value = e.storey_damping; break;
          case EnergyTerm::gap_damping: value = e.gap_damping; break;
          case EnergyTerm::impact: value = e.impact_loss; break;
          case EnergyTerm::storey_hysteretic: value = e.storey_hysteretic; break;
          case EnergyTerm::residual: value = e.residual(); break;
        }
        break;
    }
  }
}

}  // namespace poundsim
