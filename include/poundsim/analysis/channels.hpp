#pragma once
/// @file
/// The channels of a time history: what is recorded at each output instant, by name and unit,
/// for history.csv (io/time_history_run.hpp) and the Python module's arrays alike
/// (docs/output.md#history.csv, docs/input.md#output).
///
/// Every channel a model offers has a name (`u_2_5`: the displacement of floor 5 of frame 2;
/// `F_1_3`: the force in the gap element at floor 3 of frames 1 and 2; `E_input`) and a unit.
/// A selection is a list of shell patterns (POSIX fnmatch: `*` any run of characters, `?` one,
/// `[…]` one of a set): `["u_*_8", "drift_ratio_2_*", "F_*"]`. The channels keep the model's order,
/// whatever the order of the patterns: quantity by quantity, then frame by frame and floor by
/// floor (or element by element); each pattern must name at least one channel. The default
/// selection (no patterns) is the history.csv poundsim has always written: displacements,
/// velocities and relative accelerations of every floor, base shears, gap-element forces, the
/// drift and force of every storey of a frame with an inelastic storey law, and the energy terms.
///
/// Example:
/// @code
///   const HistoryChannels channels(model, std::vector<std::string>{"a_abs_*", "drift_ratio_*"});
///   std::vector<double> row(channels.size());
///   channels.sample(simulator, row);  // at every output instant; allocation-free
/// @endcode

#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "poundsim/integrate/simulator.hpp"
#include "poundsim/model/model.hpp"

namespace poundsim {

/// What a channel measures.
enum class Quantity : std::uint8_t {
  displacement,           ///< u_<f>_<i>: floor displacement relative to the ground [m]
  velocity,               ///< v_<f>_<i> [m/s]
  acceleration,           ///< a_<f>_<i>: relative to the ground [m/s²]
  absolute_acceleration,  ///< a_abs_<f>_<i>: ü + a_g, what the floor's contents feel [m/s²]
  base_shear,             ///< V_<f>: the first storey's spring force [N]
  gap_force,              ///< F_<joint>: compression positive [N]
  gap_shortening,         ///< s_<joint>: shortening past the gap, positive in contact [m]
  drift,                  ///< drift_<f>_<i>: u_i − u_{i−1} of the storey below floor i [m]
  drift_ratio,            ///< drift_ratio_<f>_<i>: drift ÷ storey height [1] (frames with storey_height)
  storey_force,           ///< Fs_<f>_<i>: the storey's restoring force, its law's [N]
  energy,                 ///< E_<term>: a term of the energy balance [J]
};

/// One channel: its name, unit and what it reads.
struct Channel {
  std::string name;
  std::string_view unit;  ///< "m", "m/s", "m/s2", "N", "J" or "1"
  Quantity quantity = Quantity::displacement;
  /// The floor's DOF (floor and storey quantities), the frame (base shear), the gap element
  /// (gap quantities) or the energy term (EnergyTerm) it reads.
  int index = 0;
  double height = 0.0;  ///< The storey's height for a drift ratio [m].

  /// Its column in history.csv: the name and its unit as a suffix, as the other tables name
  /// theirs (u_1_1_m, v_1_1_m_s, a_abs_1_1_m_s2, F_1_1_N, E_input_J; a ratio bare: drift_ratio_1_1).
  [[nodiscard]] std::string column() const { return name + unit_suffix(unit); }
  /// "_m", "_m_s", "_m_s2", "_N", "_J" for those units ("/" as "_"), "" for a ratio ("1").
  [[nodiscard]] static std::string unit_suffix(std::string_view unit) {
    if (unit == "1" || unit.empty()) return "";
    std::string suffix = "_";
    for (const char c : unit) suffix += c == '/' ? '_' : c;
    return suffix;
  }
};

/// The terms of the energy balance a history records, in the order of its columns.
enum class EnergyTerm : std::uint8_t {
  input, kinetic, storey_strain, gap_strain, storey_damping, gap_damping, impact, storey_hysteretic, residual
};

class HistoryChannels {
 public:
  /// Every channel `model` offers, in the model's order (E_storey_hysteretic only with an
  /// inelastic storey law, drift ratios only for frames with storey heights).
  [[nodiscard]] static std::vector<Channel> available(const Model& model);

  /// The channels `patterns` name (the default selection when there are none). Throws
  /// std::invalid_argument naming the first pattern that names no channel of the model.
  explicit HistoryChannels(const Model& model, std::span<const std::string> patterns = {});

  [[nodiscard]] std::span<const Channel> channels() const { return channels_; }
  [[nodiscard]] std::size_t size() const { return channels_.size(); }

  /// The value of every channel at the simulator's state, into `row` (size() values).
  /// Allocation-free.
  void sample(const Simulator& sim, std::span<double> row) const;

 private:
  std::vector<Channel> channels_;
};

}  // namespace poundsim
