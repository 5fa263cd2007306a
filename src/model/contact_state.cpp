#include "poundsim/model/contact_state.hpp"

#include <cmath>

namespace poundsim {

std::string_view to_string(GapMode mode) {
  switch (mode) {
    case GapMode::open: return "open";
    case GapMode::contact: return "contact";
    case GapMode::locked: return "locked";
  }
  return "?";
}

double GapMemory::free_end_shortening(double t, double stiffness, double damping) const {
  if (released_shortening == 0.0) return 0.0;
  if (damping <= 0.0) return 0.0;  // a spring without dashpot recovers at once
  return released_shortening * std::exp(-stiffness / damping * (t - release_time));
}

}  // namespace poundsim
