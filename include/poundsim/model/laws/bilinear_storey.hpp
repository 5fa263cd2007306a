#pragma once
/// @file
/// The bilinear hysteretic storey with kinematic hardening (the "Steel01"-type law without
/// isotropic hardening; e.g. Chopra, Dynamics of Structures, §5.7 and §7.1, and OpenSees'
/// Steel01 with a2 = a4 = 0): an elastic spring α K in parallel with an elastic–perfectly-plastic
/// spring (1 − α) K that yields at the storey's yield drift u_y = F_y / K, plus the storey's
/// dashpot C,
///
///     F = α K d + F_h + C ḋ,   F_h = (1 − α) K (d − d_p),  |F_h| ≤ (1 − α) F_y        [N]
///
/// with d_p the plastic drift of the elastic–plastic spring, its State. The force is linear in
/// each of three modes, so Newmark and the exact integrator both take it, with yielding and
/// unloading located as events like contacts:
///
///     elastic        F = K d − (1 − α) K d_p + C ḋ     guards: d − d_p − u_y   (yield, up)
///                                                             −(d − d_p) − u_y (yield, down)
///     yielding up    F = α K d + (1 − α) F_y + C ḋ     guard:  −ḋ  (unload; d_p = d − u_y)
///     yielding down  F = α K d − (1 − α) F_y + C ḋ     guard:  +ḋ  (unload; d_p = d + u_y)
///
/// Energy: ½ α K d² + ½ (1 − α) K (d − d_p)² is stored (the plastic spring at u_y while it
/// yields); the plastic spring dissipates (1 − α) F_y |Δd| while yielding (hysteretic energy,
/// plastic_work), its dashpot C ḋ². α = 1 is the linear storey; α = 0 elastic–perfectly plastic.
///
/// The storey's parameters besides K and C: the yield force F_y or the yield drift u_y (one of
/// them), and the post-yield stiffness ratio α.

#include <cmath>
#include <limits>
#include <optional>
#include <span>
#include <string_view>
#include <tuple>

#include "poundsim/fields.hpp"
#include "poundsim/model/contact_state.hpp"
#include "poundsim/model/laws/contact_law.hpp"
#include "poundsim/model/laws/law_traits.hpp"
#include "poundsim/model/laws/yielding_storey.hpp"

namespace poundsim {

struct BilinearStorey {
  struct Parameters {
    double yield_force = 0.0;       ///< F_y [N]; 0 when the yield drift is given instead.
    double yield_drift = 0.0;       ///< u_y [m]; 0 when the yield force is given instead.
    double post_yield_ratio = 0.0;  ///< α ∈ [0, 1): the post-yield stiffness over K.

    static constexpr auto fields() {
      using P = Parameters;
      return std::tuple{
          NumberField{"yield_force", &P::yield_force, "N", non_negative, "F_y, the storey shear at first yield"},
          NumberField{"yield_drift", &P::yield_drift, "m", non_negative,
                      "u_y = F_y / K, the drift at first yield (instead of yield_force)"},
          NumberField{"post_yield_ratio", &P::post_yield_ratio, "", below_one,
                      "α: the post-yield stiffness α K (0: elastic–perfectly plastic)"},
      };
    }
    /// Exactly one of the yield force and the yield drift is given (> 0).
    [[nodiscard]] std::optional<FieldRule> rule_violation() const {
      return yielding_storey::yield_rule(yield_force, yield_drift);
    }
    [[nodiscard]] bool operator==(const Parameters&) const = default;
  };
  /// Its name in a model file: `storey_law = "bilinear"`.
  static constexpr std::string_view key = "bilinear";
  [[nodiscard]] static BilinearStorey make(double stiffness, double damping, const Parameters& p) {
    return {.stiffness = stiffness,
            .damping = damping,
            .yield_force = yielding_storey::yield_force(stiffness, p.yield_force, p.yield_drift),
            .post_yield_ratio = p.post_yield_ratio};
  }

  enum class Mode : LinkMode { elastic, yielding_up, yielding_down };
  /// The plastic drift d_p of the elastic–plastic spring, set when a yielding storey unloads.
  struct State {
    double plastic_drift = 0.0;  ///< d_p [m]
    void shift_clock(double /*origin*/) {}
    [[nodiscard]] bool operator==(const State&) const = default;
  };

  double stiffness = 0.0;         ///< K [N/m], > 0.
  double damping = 0.0;           ///< C [N·s/m], ≥ 0.
  double yield_force = 0.0;       ///< F_y [N], > 0.
  double post_yield_ratio = 0.0;  ///< α ∈ [0, 1).

  static constexpr LawTraits traits{
      .piecewise_linear = true, .has_stop = false, .energy = EnergyGroup::storey, .name = "bilinear storey"};

  [[nodiscard]] bool operator==(const BilinearStorey&) const = default;

  /// u_y = F_y / K [m].
  [[nodiscard]] double yield_drift() const { return yield_force / stiffness; }
  /// (1 − α) K [N/m]: the elastic–plastic spring.
  [[nodiscard]] double plastic_spring() const { return (1.0 - post_yield_ratio) * stiffness; }
  /// (1 − α) F_y [N]: the force at which it yields.
  [[nodiscard]] double plastic_spring_yield() const { return (1.0 - post_yield_ratio) * yield_force; }

  [[nodiscard]] static Mode mode(LinkMode m) { return static_cast<Mode>(m); }

  /// The linear form in `mode` with d_p = 0; state_force adds the part d_p sets.
  [[nodiscard]] std::optional<LinearForm> linear_form(LinkMode m) const {
    switch (mode(m)) {
      case Mode::elastic: return LinearForm{.stiffness = stiffness, .damping = damping};
      case Mode::yielding_up:
        return LinearForm{.stiffness = post_yield_ratio * stiffness, .damping = damping,
                          .force_at_zero = plastic_spring_yield()};
      case Mode::yielding_down:
        return LinearForm{.stiffness = post_yield_ratio * stiffness, .damping = damping,
                          .force_at_zero = -plastic_spring_yield()};
    }
    return std::nullopt;
  }
  /// The part of f₀ its State sets: −(1 − α) K d_p while elastic [N].
  [[nodiscard]] double state_force(LinkMode m, const State& state) const {
    return mode(m) == Mode::elastic ? -plastic_spring() * state.plastic_drift : 0.0;
  }

  /// F_h = the elastic–plastic spring's force at drift d [N].
  [[nodiscard]] double hysteretic_force(double d, LinkMode m, const State& state) const {
    switch (mode(m)) {
      case Mode::elastic: return plastic_spring() * (d - state.plastic_drift);
      case Mode::yielding_up: return plastic_spring_yield();
      case Mode::yielding_down: return -plastic_spring_yield();
    }
    return 0.0;
  }
  /// F = α K d + F_h + C ḋ [N].
  [[nodiscard]] double force(const LinkKinematics& k, LinkMode m, const State& state) const {
    const double d = k.ua - k.ub;
    return post_yield_ratio * stiffness * d + hysteretic_force(d, m, state) + damping * (k.va - k.vb);
  }
  /// The restoring force F − C ḋ [N] (the storey shear without its dashpot).
  [[nodiscard]] double restoring_force(double d, LinkMode m, const State& state) const {
    return post_yield_ratio * stiffness * d + hysteretic_force(d, m, state);
  }

  // Modes and events (EventLaw, contact_law.hpp).
  /// Elastic: a frame starts with no plastic drift, its storeys within their yield drift.
  [[nodiscard]] LinkMode initial_mode(double /*d*/) const { return static_cast<LinkMode>(Mode::elastic); }
  void guards(const LinkKinematics& k, LinkMode m, const State& state, const GuardContext& /*context*/,
              std::span<GuardValue, 2> out) const {
    const double d = k.ua - k.ub, rate = k.va - k.vb;
    constexpr double kNoise = 8 * std::numeric_limits<double>::epsilon();
    switch (mode(m)) {
      case Mode::elastic: {
        const double elastic = d - state.plastic_drift, uy = yield_drift();
        const double noise = kNoise * (std::abs(k.ua) + std::abs(k.ub) + std::abs(state.plastic_drift) + uy);
        out[0] = {.active = true, .value = elastic - uy, .rate = rate, .noise = noise};
        out[1] = {.active = true, .value = -elastic - uy, .rate = -rate, .noise = noise};
        return;
      }
      case Mode::yielding_up:
      case Mode::yielding_down: {
        const double sign = mode(m) == Mode::yielding_up ? -1.0 : 1.0;
        const double noise = kNoise * (std::abs(k.va) + std::abs(k.vb));
        out[0] = {.active = true, .value = sign * rate, .rate = sign * (k.aa - k.ab), .noise = noise};
        out[1] = {};
        return;
      }
    }
  }
  [[nodiscard]] GuardForm guard_form(int guard, LinkMode m, SeparationCriterion /*separation*/) const {
    if (mode(m) == Mode::elastic) {
      return {.kind = GuardForm::Kind::affine, .d_coefficient = guard == 0 ? 1.0 : -1.0};
    }
    if (guard != 0) return {};
    return {.kind = GuardForm::Kind::affine, .rate_coefficient = mode(m) == Mode::yielding_up ? -1.0 : 1.0};
  }
  [[nodiscard]] static Relaxation relaxation(LinkMode /*mode*/, const State& /*state*/, double /*t*/) { return {}; }
  [[nodiscard]] Transition on_guard(int guard, const LinkKinematics& k, LinkMode& m, State& state,
                                    SeparationCriterion /*separation*/) const {
    const double d = k.ua - k.ub;
    switch (mode(m)) {
      case Mode::elastic:
        m = static_cast<LinkMode>(guard == 0 ? Mode::yielding_up : Mode::yielding_down);
        return Transition::yield;
      case Mode::yielding_up:
        state.plastic_drift = d - yield_drift();
        break;
      case Mode::yielding_down:
        state.plastic_drift = d + yield_drift();
        break;
    }
    m = static_cast<LinkMode>(Mode::elastic);
    return Transition::unload;
  }

  // Energy (dynamics/energy.hpp).
  /// ½ α K d² + ½ (1 − α) K (d − d_p)², the plastic spring held at u_y while it yields [J].
  [[nodiscard]] double stored_energy(const LinkKinematics& k, LinkMode m, const State& state) const {
    const double d = k.ua - k.ub;
    const double fh = hysteretic_force(d, m, state);
    return 0.5 * post_yield_ratio * stiffness * d * d + 0.5 * fh * fh / plastic_spring();
  }
  [[nodiscard]] double dissipated_power(const LinkKinematics& k, LinkMode /*mode*/, const State& /*state*/) const {
    return yielding_storey::dashpot_power(damping, k);
  }
  [[nodiscard]] double trapezoidal_power(const LinkKinematics& k0, const LinkKinematics& k1, LinkMode /*mode*/,
                                         const State& /*state*/) const {
    return yielding_storey::trapezoidal_dashpot_power(damping, k0, k1);
  }
  [[nodiscard]] static double relaxation_release(LinkMode /*mode*/, const State& /*state*/, double /*t0*/,
                                                 double /*t1*/) {
    return 0.0;
  }
  /// What the plastic spring dissipates between two states in one mode: (1 − α) F_y |Δd| while
  /// it yields, 0 while elastic [J].
  [[nodiscard]] double plastic_work(const LinkKinematics& k0, const LinkKinematics& k1, LinkMode m,
                                    const State& /*state*/) const {
    if (mode(m) == Mode::elastic) return 0.0;
    const double step = (k1.ua - k1.ub) - (k0.ua - k0.ub);
    return (mode(m) == Mode::yielding_up ? step : -step) * plastic_spring_yield();
  }
};

static_assert(EventLaw<BilinearStorey>);

}  // namespace poundsim
