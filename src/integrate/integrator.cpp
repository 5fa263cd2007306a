#include "poundsim/integrate/integrator.hpp"

#include <optional>
#include <vector>

#include <fmt/format.h>

namespace poundsim {

std::string_view to_string(Integrator integrator) {
  return integrator == Integrator::exact ? "exact" : "newmark";
}

namespace {

/// Why `integrator` cannot integrate a law with these traits on `link`; nothing when it can.
/// Both step the linear phase of each mode (LinearPhase); Newmark also solves a law that gives its
/// tangent by Newton iterations, the exact integrator has no closed form for it.
std::optional<IntegratorSupport> refusal(Integrator integrator, const LawTraits& law, const std::string& link) {
  if (law.piecewise_linear) return std::nullopt;
  if (integrator == Integrator::exact) {
    return IntegratorSupport{false, fmt::format("the exact integrator solves phases of piecewise-linear laws in "
                                                "closed form; {} is not piecewise linear: use integrator = \"newmark\"",
                                                link)};
  }
  if (law.newton) return std::nullopt;
  return IntegratorSupport{false, fmt::format("Newmark solves piecewise-linear laws and laws that give their "
                                              "tangent (Newton); {} is neither",
                                              link)};
}

}  // namespace

IntegratorSupport supports(Integrator integrator, std::span<const LawTraits> laws) {
  for (std::size_t i = 0; i < laws.size(); ++i) {
    if (auto no = refusal(integrator, laws[i], fmt::format("link {} ({})", i + 1, laws[i].name))) return *no;
  }
  return {};
}

IntegratorSupport supports(Integrator integrator, std::span<const Link> links, const DofLayout& layout) {
  for (const Link& link : links) {
    if (!link.traits().piecewise_linear) {
      if (auto no = refusal(integrator, link.traits(), describe(link, layout))) return *no;
    }
  }
  return {};
}

}  // namespace poundsim
