#include "poundsim/model/laws/paper_gap.hpp"

#include <cmath>
#include <limits>
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

std::string_view to_string(GapMode mode) {
  switch (mode) {
    case GapMode::open: return "open";
    case GapMode::contact: return "contact";
    case GapMode::locked: return "locked";
  }
  return "?";
}

LinkMode PaperGap::initial_mode(double d) const {
  const double s = d - parameters.gap;
  if (s <= 0) return link_mode(GapMode::open);
  if (s >= parameters.shortening) {
    throw std::invalid_argument(fmt::format("by {} m, beyond the allowable shortening {} m", s,
                                            parameters.shortening));
  }
  return link_mode(GapMode::contact);
}

GuardForm PaperGap::guard_form(int guard, LinkMode mode, SeparationCriterion separation) const {
  using Kind = GuardForm::Kind;
  switch (gap_mode(mode)) {
    case GapMode::open:
      if (guard == 0) return {.kind = Kind::affine, .d_coefficient = 1.0};
      return {};
    case GapMode::contact:
      if (guard == 0) return {.kind = Kind::affine, .d_coefficient = 1.0};
      return spring_dashpot().separation_form(separation);
    case GapMode::locked:
      if (guard == 0) return {.kind = Kind::reaction};
      return {};
  }
  return {};
}

Relaxation PaperGap::relaxation(LinkMode mode, const State& state, double t) const {
  if (gap_mode(mode) != GapMode::open) return {};
  return spring_dashpot().relaxation(state, t);
}

Transition PaperGap::on_guard(int guard, const LinkKinematics& k, LinkMode& mode,
                              State& state, SeparationCriterion separation) const {
  if (guard == 1) {  // separation from contact
    mode = link_mode(GapMode::open);
    const double s = shortening(k);
    state = SpringDashpot::released(s, k.t, separation);
    return Transition::separation;
  }
  switch (gap_mode(mode)) {
    case GapMode::open:
      if (parameters.is_rigid_stop()) return Transition::impact;
      mode = link_mode(GapMode::contact);
      state = State{};
      return Transition::contact;
    case GapMode::contact: return Transition::impact;
    case GapMode::locked:
      mode = link_mode(parameters.is_rigid_stop() ? GapMode::open : GapMode::contact);
      state = State{};
      return Transition::unlock;
  }
  return Transition::impact;
}

double PaperGap::stop_distance(const LinkKinematics& k, LinkMode mode,
                               const State& state) const {
  const double s = shortening(k);
  if (gap_mode(mode) == GapMode::contact) return s - parameters.shortening;
  return s - spring_dashpot().free_end(state, k.t);
}

}  // namespace poundsim
