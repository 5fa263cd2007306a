#pragma once
/// @file
/// The mode of every gap element: which linear phase it is in. (What a law keeps besides its mode
/// — the paper's element: the relaxation of its spring after a force separation — is the law's
/// own State, model/laws/.)
///
/// Modes and the events that change them (see docs/model.md for the reasoning):
///
///     open ──contact (s ↑ 0)──▶ contact ──impact (s ↑ ε)──▶ contact (velocities jump)
///       ▲                         │   │                      or locked (chatter suppressed)
///       └──separation (s ↓ 0 or F ↓ 0)┘   └◀──unlock (stop reaction λ ↓ 0)── locked
///
/// For a rigid stop (ε = 0) there is no contact phase: open ──impact──▶ open or locked, and
/// unlock returns to open.

#include <array>
#include <cstdint>
#include <string_view>
#include <utility>
#include <vector>

#include "poundsim/fields.hpp"
#include "poundsim/model/laws/law_traits.hpp"

namespace poundsim {

enum class GapMode : std::uint8_t {
  open,     ///< s ≤ 0 (or the element separated and has not touched again): no force.
  contact,  ///< 0 < s < ε: spring and dashpot act, F = c ṡ + k s.
  locked,   ///< s = ε held by the stop: the floors move together; the stop reaction λ ≥ 0.
};

[[nodiscard]] std::string_view to_string(GapMode mode);

/// The mode of every gap element's link (its law's LinkMode; for the paper's element a GapMode,
/// PaperGap::link_mode), in Model::gaps order. It selects the linear system of the phase.
using ContactConfiguration = std::vector<LinkMode>;

/// How a gap element in contact separates (input key analysis.separation).
enum class SeparationCriterion : std::uint8_t {
  /// The paper's criterion: contact ends when s returns to 0. The dashpot may pull (F < 0) just
  /// before separation.
  displacement,
  /// Contact ends when F = c ṡ + k s would become tensile. The massless element then relaxes on
  /// its own, c ṡ_e + k s_e = 0, and touches again when the floors close on its free end.
  force,
};

/// The names of the criteria in a model file (analysis.separation) and in the summaries.
inline constexpr std::array<std::pair<std::string_view, SeparationCriterion>, 2> separation_criterion_names{{
    {"displacement", SeparationCriterion::displacement},
    {"force", SeparationCriterion::force},
}};
[[nodiscard]] constexpr std::string_view to_string(SeparationCriterion criterion) {
  return name_in(separation_criterion_names, criterion);
}

}  // namespace poundsim
