#pragma once
/// @file
/// The mode of every gap element: which linear phase its law is in (each law names its own modes:
/// the paper's element's GapMode, model/laws/paper_gap.hpp), and how an element in contact
/// separates. What a law keeps besides its mode is its own State (model/laws/).

#include <array>
#include <cstdint>
#include <string_view>
#include <utility>
#include <vector>

#include "poundsim/fields.hpp"
#include "poundsim/model/laws/law_traits.hpp"

namespace poundsim {

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
