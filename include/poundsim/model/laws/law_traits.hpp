#pragma once
/// @file
/// What every law declares besides its force: its modes, its linear form in each, and traits.
/// See model/law.hpp for the sign convention.

#include <concepts>
#include <cstdint>

namespace poundsim {

/// A law's mode (its linear phase), law-defined; a law with one mode uses 0.
using LinkMode = std::uint8_t;

/// F = stiffness·d + damping·ḋ + force_at_zero in one mode of a piecewise-linear law.
struct LinearForm {
  double stiffness = 0.0;      ///< ∂F/∂d [N/m]
  double damping = 0.0;        ///< ∂F/∂ḋ [N·s/m]
  double force_at_zero = 0.0;  ///< f₀ [N]: F at d = ḋ = 0
  bool rigid = false;          ///< The link holds d fixed (its floors move as one group).
  /// F = k d + c ḋ + f₀ [N], summed in this order: the monitor's shears, their refinement between
  /// samples and the lockstep kernel's finiteness check all take it, for the same bits.
  [[nodiscard]] double force(double d, double rate) const { return stiffness * d + damping * rate + force_at_zero; }
};

/// Which term of the energy balance a law's stored and dissipated energy belongs to.
enum class EnergyGroup : std::uint8_t { storey, gap_element };

/// The state a law keeps between events, committed at each event that changes it (a relaxing
/// free end, a closing velocity at contact, a plastic drift): each law declares its own as
/// `State`, and the loop keeps one per link (LinkStates, model/law.hpp). Times in it are on the
/// simulation's clock, which restarts at 0 when a simulation restarts on a new excitation:
/// shift_clock(origin) makes them relative to the new origin.
template <class S>
concept LawState = std::default_initializable<S> && std::copyable<S> && requires(S& s) {
  s.shift_clock(0.0);
};

/// The state of a law that keeps nothing between events.
struct NoState {
  void shift_clock(double /*origin*/) {}
  [[nodiscard]] bool operator==(const NoState&) const = default;
};

struct LawTraits {
  bool piecewise_linear = true;  ///< Linear in each mode: Newmark and the exact integrator apply.
  /// Not piecewise linear but gives its force's consistent tangent: Newmark solves it by Newton.
  bool newton = false;
  bool has_stop = false;         ///< Has a rigid stop: impacts with restitution, locking.
  EnergyGroup energy = EnergyGroup::storey;
  const char* name = "";  ///< For messages, e.g. "the paper's gap element".
};

}  // namespace poundsim
