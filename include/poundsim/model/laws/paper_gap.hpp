#pragma once
/// @file
/// The paper's unilateral visco-elastic gap element (Pasquino, Santini & Caliò, eqs. 2–4) as a
/// law of the link from the left floor to the right one (d = u_L − u_R, F > 0 compression).
///
/// Parameters: GapProperties (k, c, δ, ε, e; gap_element.hpp). Modes (contact_state.hpp):
///
///     open     F = 0                                  (s = d − δ ≤ 0, or relaxing after a
///                                                      force separation: s_e(t), GapMemory)
///     contact  F = k s + c ṡ = k d + c ḋ − k δ          (0 < s < ε)
///     locked   the link is rigid at s = ε: d is held; the stop adds its reaction λ ≥ 0
///
/// Events (the simulator applies them; docs/model.md): contact when s reaches 0 (or the free end
/// s_e), impact with restitution e when s reaches ε (at once when ε = 0: a rigid stop),
/// separation when s or F returns to 0, locking of a pair pressed together, unlocking when λ
/// returns to 0. Stored energy ½ k s² (½ k s_e² while relaxing), dissipated power c ṡ² in
/// contact and locked, and the relaxation's release; impact losses are booked at the impact.

#include <optional>

#include "poundsim/model/contact_state.hpp"
#include "poundsim/model/gap_element.hpp"
#include "poundsim/model/laws/law_traits.hpp"

namespace poundsim {

struct PaperGap {
  GapProperties parameters;

  static constexpr LawTraits traits{
      .piecewise_linear = true, .has_stop = true, .energy = EnergyGroup::gap_element};

  [[nodiscard]] static GapMode gap_mode(LinkMode mode) { return static_cast<GapMode>(mode); }
  [[nodiscard]] static LinkMode link_mode(GapMode mode) { return static_cast<LinkMode>(mode); }

  /// Nothing while open: the element transmits no force.
  [[nodiscard]] std::optional<LinearForm> linear_form(LinkMode mode) const {
    if (gap_mode(mode) == GapMode::open) return std::nullopt;
    // Locked keeps the spring and dashpot: they act inside the rigid group and their constant
    // force enters through the link's length (linear_phase.hpp).
    return LinearForm{.stiffness = parameters.stiffness,
            .damping = parameters.damping,
            .force_at_zero = -(parameters.stiffness * parameters.gap),
            .rigid = gap_mode(mode) == GapMode::locked};
  }
  /// Stored energy ½ k s² (contact, locked) or ½ k s_e(t)² (open, relaxing) [J].
  [[nodiscard]] double stored_energy(double d, LinkMode mode, const GapMemory& memory,
                                     double t) const {
    const double s = gap_mode(mode) == GapMode::open
                         ? memory.free_end_shortening(t, parameters.stiffness, parameters.damping)
                         : shortening(parameters, d, 0.0);
    return 0.5 * (parameters.stiffness * s * s);
  }
  /// c ṡ² in contact and locked, 0 open [W] (the relaxation is booked apart).
  [[nodiscard]] double dashpot(LinkMode mode) const {
    return gap_mode(mode) == GapMode::open ? 0.0 : parameters.damping;
  }
};

}  // namespace poundsim
