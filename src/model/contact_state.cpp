#include "poundsim/model/contact_state.hpp"

namespace poundsim {

std::string_view to_string(GapMode mode) {
  switch (mode) {
    case GapMode::open: return "open";
    case GapMode::contact: return "contact";
    case GapMode::locked: return "locked";
  }
  return "?";
}


}  // namespace poundsim
