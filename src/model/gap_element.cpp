#include "poundsim/model/gap_element.hpp"

#include <stdexcept>

#include <fmt/format.h>

namespace poundsim {

void validate(const GapProperties& p, const std::string& what) {
  if (const auto violation = first_violation(p)) {
    throw std::invalid_argument(fmt::format("{}: {}", what, *violation));
  }
}

}  // namespace poundsim
