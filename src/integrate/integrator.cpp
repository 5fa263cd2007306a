#include "poundsim/integrate/integrator.hpp"

#include <vector>

#include <fmt/format.h>

namespace poundsim {

std::string_view to_string(Integrator integrator) {
  return integrator == Integrator::exact ? "exact" : "newmark";
}

namespace {

/// The refusal of the exact integrator for a law that is not piecewise linear, on `link`.
IntegratorSupport refuse_exact(const std::string& link) {
  return {false, fmt::format("the exact integrator solves phases of piecewise-linear laws in closed form; "
                             "{} is not piecewise linear: use analysis.integrator = \"newmark\"",
                             link)};
}

}  // namespace

IntegratorSupport supports(Integrator integrator, std::span<const LawTraits> laws) {
  if (integrator == Integrator::newmark) return {};
  for (std::size_t i = 0; i < laws.size(); ++i) {
    if (!laws[i].piecewise_linear) return refuse_exact(fmt::format("link {} ({})", i + 1, laws[i].name));
  }
  return {};
}

IntegratorSupport supports(Integrator integrator, std::span<const Link> links, const DofLayout& layout) {
  if (integrator == Integrator::newmark) return {};
  for (const Link& link : links) {
    if (!link.traits().piecewise_linear) return refuse_exact(describe(link, layout));
  }
  return {};
}

}  // namespace poundsim
