#include "poundsim/integrate/integrator.hpp"

#include <vector>

#include <fmt/format.h>

namespace poundsim {

std::string_view to_string(Integrator integrator) {
  return integrator == Integrator::exact ? "exact" : "newmark";
}

IntegratorSupport supports(Integrator integrator, std::span<const LawTraits> laws) {
  if (integrator == Integrator::newmark) return {};
  for (std::size_t i = 0; i < laws.size(); ++i) {
    if (!laws[i].piecewise_linear) {
      return {false, fmt::format("the exact integrator solves phases of piecewise-linear laws in closed form; "
                                 "link {} has {}, which is not piecewise linear: use analysis.integrator = "
                                 "\"newmark\"",
                                 i + 1, laws[i].name)};
    }
  }
  return {};
}

IntegratorSupport supports(Integrator integrator, std::span<const Link> links) {
  std::vector<LawTraits> laws;
  laws.reserve(links.size());
  for (const Link& link : links) laws.push_back(link.traits());
  return supports(integrator, laws);
}

}  // namespace poundsim
