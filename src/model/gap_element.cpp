#include "poundsim/model/gap_element.hpp"

#include <cmath>
#include <stdexcept>

#include <fmt/format.h>

namespace poundsim {

void validate(const GapProperties& p, const std::string& what) {
  const auto non_negative = [&](const char* field, double value) {
    if (!std::isfinite(value) || value < 0.0) {
      throw std::invalid_argument(fmt::format("{}: {} = {} must be ≥ 0", what, field, value));
    }
  };
  non_negative("stiffness", p.stiffness);
  non_negative("damping", p.damping);
  non_negative("gap", p.gap);
  non_negative("shortening", p.shortening);
  if (!std::isfinite(p.restitution) || p.restitution < 0.0 || p.restitution > 1.0) {
    throw std::invalid_argument(
        fmt::format("{}: restitution = {} must be in [0, 1]", what, p.restitution));
  }
}

}  // namespace poundsim
