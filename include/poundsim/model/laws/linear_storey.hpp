#pragma once
/// @file
/// The linear storey of a shear frame (Pasquino, Santini & Caliò, Fig. 1): a spring K and a
/// dashpot C in parallel between a floor and the floor below (or the ground),
///
///     F = K d + C ḋ,   d = u_i − u_{i−1} (the drift)           [N]
///
/// with stored energy ½ K d² and dissipated power C ḋ². One mode, no events. Its parameters are
/// validated with the frame's (validate(const Frame&)).

#include <optional>
#include <string_view>
#include <tuple>

#include "poundsim/fields.hpp"
#include "poundsim/model/laws/contact_law.hpp"
#include "poundsim/model/laws/law_traits.hpp"

namespace poundsim {

struct LinearStorey {
  /// Nothing besides the frame's K_i and C_i (its `stiffness` and `damping`).
  struct Parameters {
    static constexpr auto fields() { return std::tuple{}; }
    [[nodiscard]] std::optional<FieldRule> rule_violation() const { return std::nullopt; }
    [[nodiscard]] bool operator==(const Parameters&) const = default;
  };
  /// Its name in a model file: `storey_law = "linear"` (the default of [[frames]]).
  static constexpr std::string_view key = "linear";
  /// The law of a storey with the frame's K and C and its own parameters.
  [[nodiscard]] static LinearStorey make(double stiffness, double damping, const Parameters& /*none*/) {
    return {.stiffness = stiffness, .damping = damping};
  }

  /// Nothing is kept between events.
  using State = NoState;

  double stiffness = 0.0;  ///< K [N/m], > 0.
  double damping = 0.0;    ///< C [N·s/m], ≥ 0.

  static constexpr LawTraits traits{
      .piecewise_linear = true, .has_stop = false, .energy = EnergyGroup::storey, .name = "linear storey"};

  [[nodiscard]] LinearForm linear_form(LinkMode /*mode*/) const {
    return {.stiffness = stiffness, .damping = damping};
  }
  /// F [N].
  [[nodiscard]] double force(double d, double rate) const { return stiffness * d + damping * rate; }
  /// K d: the storey's restoring force without its dashpot [N] (mode and state unused).
  [[nodiscard]] double restoring_force(double d, LinkMode /*mode*/, const State& /*state*/) const {
    return stiffness * d;
  }
  /// ½ K d² [J].
  [[nodiscard]] double stored_energy(double d) const { return 0.5 * (stiffness * d * d); }
  /// C ḋ² [W].
  [[nodiscard]] double dissipated_power(double rate) const { return damping * rate * rate; }

  // The energy interface every law has (dynamics/energy.hpp asks it).
  [[nodiscard]] double stored_energy(const LinkKinematics& k, LinkMode /*mode*/,
                                     const State& /*state*/) const {
    return stored_energy(k.ua - k.ub);
  }
  [[nodiscard]] double dissipated_power(const LinkKinematics& k, LinkMode /*mode*/, const State& /*state*/) const {
    return dissipated_power(k.va - k.vb);
  }
  /// C ḋ̄² with ḋ̄ the mean of the rates at both ends of a step: the trapezoidal rule, which
  /// Newmark's average-acceleration scheme satisfies exactly.
  [[nodiscard]] double trapezoidal_power(const LinkKinematics& k0, const LinkKinematics& k1, LinkMode /*mode*/,
                                         const State& /*state*/) const {
    const double rate = 0.5 * (k0.va + k1.va - (k0.vb + k1.vb));
    return dissipated_power(rate);
  }
  /// No relaxing part: 0 [J].
  [[nodiscard]] double relaxation_release(LinkMode /*mode*/, const State& /*state*/,
                                          double /*t0*/, double /*t1*/) const {
    return 0.0;
  }
};

}  // namespace poundsim
