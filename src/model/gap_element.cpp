#include "poundsim/model/gap_element.hpp"

#include <stdexcept>

#include <fmt/format.h>

namespace poundsim {

std::optional<FieldRule> GapProperties::rule_violation() const {
  if (shortening == 0 && (stiffness > 0 || damping > 0)) {
    return FieldRule{{"shortening", "stiffness", "damping"},
                     "an element with shortening = 0 is a rigid stop whose spring and dashpot never "
                     "act; give shortening > 0 or stiffness = damping = 0"};
  }
  return std::nullopt;
}

void validate(const GapProperties& p, const std::string& what) {
  if (const auto violation = first_violation(p)) {
    throw std::invalid_argument(fmt::format("{}: {}", what, *violation));
  }
  if (const auto rule = p.rule_violation()) {
    throw std::invalid_argument(fmt::format("{}: {}", what, rule->message));
  }
}

}  // namespace poundsim
