#include "poundsim/model/laws/kelvin_voigt.hpp"

#include <cmath>
#include <numbers>

namespace poundsim {

double KelvinVoigt::damping_ratio(double e) {
  if (e <= 0.0) return 1.0;  // the limit of −ln e / √(π² + ln² e) as e → 0
  const double log_e = std::log(e);
  return -log_e / std::sqrt(std::numbers::pi * std::numbers::pi + log_e * log_e);
}

void KelvinVoigt::bind_masses(double mass_a, double mass_b) {
  damping = 2.0 * damping_ratio(parameters.restitution) * std::sqrt(parameters.stiffness * reduced_mass(mass_a, mass_b));
}

GuardForm KelvinVoigt::guard_form(int guard, LinkMode mode, SeparationCriterion separation) const {
  if (in_contact(mode)) {
    return guard == 1 ? spring_dashpot().separation_form(separation) : GuardForm{};
  }
  return guard == 0 ? GuardForm{.kind = GuardForm::Kind::affine, .d_coefficient = 1.0} : GuardForm{};
}

Transition KelvinVoigt::on_guard(int guard, const LinkKinematics& k, LinkMode& mode, State& state,
                                 SeparationCriterion separation) const {
  if (guard == 1) {
    mode = static_cast<LinkMode>(Mode::open);
    state = SpringDashpot::released(shortening(k), k.t, separation);
    return Transition::separation;
  }
  mode = static_cast<LinkMode>(Mode::contact);
  state = State{};
  return Transition::contact;
}

}  // namespace poundsim
