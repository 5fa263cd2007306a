#include "poundsim/integrate/integrator.hpp"

#include <vector>

#include <fmt/format.h>

namespace poundsim {

std::string_view to_string(Integrator integrator) {
  return integrator == Integrator::exact ? "exact" : "newmark";
}

namespace {

/// The refusal of a law that is not piecewise linear, on `link`: both integrators step the linear
/// phase of each mode (LinearPhase), and Newmark's Newton iteration on a law's tangent, which a
/// smooth law needs, is not built yet.
IntegratorSupport refuse(Integrator integrator, const std::string& link) {
  if (integrator == Integrator::exact) {
    return {false, fmt::format("the exact integrator solves phases of piecewise-linear laws in closed form; "
                               "{} is not piecewise linear",
                               link)};
  }
  return {false, fmt::format("Newmark steps the linear phase of each mode and has no Newton iteration yet; "
                             "{} is not piecewise linear",
                             link)};
}

}  // namespace

IntegratorSupport supports(Integrator integrator, std::span<const LawTraits> laws) {
  for (std::size_t i = 0; i < laws.size(); ++i) {
    if (!laws[i].piecewise_linear) return refuse(integrator, fmt::format("link {} ({})", i + 1, laws[i].name));
  }
  return {};
}

IntegratorSupport supports(Integrator integrator, std::span<const Link> links, const DofLayout& layout) {
  for (const Link& link : links) {
    if (!link.traits().piecewise_linear) return refuse(integrator, describe(link, layout));
  }
  return {};
}

}  // namespace poundsim
