#pragma once
/// @file
/// The Bouc–Wen hysteretic storey (Wen 1976, "Method for random vibration of hysteretic systems",
/// J. Eng. Mech. Div. ASCE 102(2), 249–263), in the normalised form whose hysteretic force
/// saturates at (1 − α) F_y when A / (β + γ) = 1:
///
///     F = α K d + (1 − α) F_y z + C ḋ                                              [N]
///     u_y ż = ḋ [A − |z|ⁿ (β sgn(ḋ z) + γ)],   u_y = F_y / K
///
/// z is the dimensionless hysteretic variable, the law's State with the drift it was committed
/// at. The force is smooth, so Newmark solves it by Newton (traits.newton); the exact integrator
/// refuses it. As n grows the loop tends to the bilinear storey's (bilinear_storey.hpp) with the
/// same K, F_y and α (β + γ = A = 1).
///
/// Trial and commit (OpenSees' material state): a trial drift d₁ gives the trial z₁ by the
/// trapezoidal rule in the drift, z₁ = z₀ + (Δd/2u_y)(Φ(z₀) + Φ(z₁)), Φ(z) = A − |z|ⁿ(β sgn(Δd z)
/// + γ), Δd = d₁ − d₀ from the committed (d₀, z₀) — a pure function of the committed state,
/// solved by a safeguarded Newton iteration — and its consistent tangent dz₁/dd₁ =
/// (Φ(z₀) + Φ(z₁))/(2u_y − Δd Φ′(z₁)). The loop commits (d₁, z₁) at every accepted state
/// (commit). The trapezoidal rule is second order in Δd, as Newmark's average acceleration is in
/// dt, so the whole run converges at second order where the storey yields; it is A-stable, so
/// z stays bounded near its saturation |z| → (A/(β+γ))^{1/n} for large n (a stiff ODE), where
/// backward Euler (first order) would only damp the approach faster.
///
/// The admissible parameters: z is bounded for every drift history if and only if β ≥ 0 and
/// β + γ > 0 (with A > 0): Ikhouane, Mañosa & Rodellar (2007), "Dynamic properties of the
/// hysteretic Bouc–Wen model", Systems & Control Letters 56(3), 197–205, classes I and II.
///
/// Energy: ½ α K d² + ½ (1 − α) F_y u_y z²/A is stored; the hysteretic part's work beyond it,
/// ½((1 − α)F_y)(z₀ + z₁)Δd − Δ(½(1 − α)F_y u_y z²/A) per step (the trapezoidal work Newmark's
/// discrete energy identity holds to), is its hysteretic energy (plastic_work).

#include <cmath>
#include <optional>
#include <string_view>
#include <tuple>

#include "poundsim/fields.hpp"
#include "poundsim/model/laws/contact_law.hpp"
#include "poundsim/model/laws/law_traits.hpp"
#include "poundsim/model/laws/yielding_storey.hpp"
#include "poundsim/model/laws/smooth_contact.hpp"

namespace poundsim {

struct BoucWenStorey {
  struct Parameters {
    double yield_force = 0.0;       ///< F_y [N]; 0 when the yield drift is given instead.
    double yield_drift = 0.0;       ///< u_y [m]; 0 when the yield force is given instead.
    double post_yield_ratio = 0.0;  ///< α ∈ [0, 1).
    double a = 1.0;                 ///< A > 0: the initial slope of z against d/u_y.
    double beta = 0.5;              ///< β ≥ 0: with γ, the shape of the loop.
    double gamma = 0.5;             ///< γ; β + γ > 0.
    double n = 2.0;                 ///< n ≥ 1: the sharpness of yielding (large: bilinear).

    static constexpr auto fields() {
      using P = Parameters;
      return std::tuple{
          NumberField{"yield_force", &P::yield_force, "N", non_negative, "F_y, the hysteretic force's scale"},
          NumberField{"yield_drift", &P::yield_drift, "m", non_negative, "u_y = F_y / K (instead of yield_force)"},
          NumberField{"post_yield_ratio", &P::post_yield_ratio, "", below_one, "α: the post-yield stiffness α K"},
          NumberField{"a", &P::a, "", positive, "A: z's initial slope against d/u_y"},
          NumberField{"beta", &P::beta, "", any_finite, "β ≥ 0: the loop's shape, with γ"},
          NumberField{"gamma", &P::gamma, "", any_finite, "γ: the loop's shape, with β; β + γ > 0"},
          NumberField{"n", &P::n, "", Interval{.lo = 1.0, .hi = 1000.0}, "n: the sharpness of yielding"},
      };
    }
    [[nodiscard]] std::optional<FieldRule> rule_violation() const {
      if (auto rule = yielding_storey::yield_rule(yield_force, yield_drift)) return rule;
      // z stays bounded for every drift history if and only if β ≥ 0 and β + γ > 0 (with A > 0;
      // Ikhouane, Mañosa & Rodellar 2007, classes I and II): with β < 0 unloading from the
      // saturation z₀ = (A/(β+γ))^(1/n) makes |z| grow without bound, as γ − β > β + γ.
      if (!(beta >= 0)) {
        return FieldRule{{"beta", "gamma"},
                         fmt::format("β must be ≥ 0 (got {}): with β < 0, z grows without bound on unloading from its "
                                     "saturation (γ − β > β + γ); z is bounded for every drift history only when "
                                     "β ≥ 0 and β + γ > 0 (Ikhouane, Mañosa & Rodellar 2007)",
                                     beta)};
      }
      if (!(beta + gamma > 0)) {
        return FieldRule{{"gamma", "beta"},
                         "β + γ must be > 0 for z to stay bounded (z saturates at (A/(β+γ))^(1/n); Ikhouane, "
                         "Mañosa & Rodellar 2007)"};
      }
      return std::nullopt;
    }
    [[nodiscard]] bool operator==(const Parameters&) const = default;
  };
  /// Its name in a model file: `storey_law = "bouc_wen"`.
  static constexpr std::string_view key = "bouc_wen";
  [[nodiscard]] static BoucWenStorey make(double stiffness, double damping, const Parameters& p) {
    return {.stiffness = stiffness,
            .damping = damping,
            .yield_force = yielding_storey::yield_force(stiffness, p.yield_force, p.yield_drift),
            .post_yield_ratio = p.post_yield_ratio,
            .a = p.a,
            .beta = p.beta,
            .gamma = p.gamma,
            .n = p.n};
  }

  /// The committed drift and hysteretic variable.
  struct State {
    double drift = 0.0;  ///< d₀ [m]
    double z = 0.0;      ///< z₀
    void shift_clock(double /*origin*/) {}
    [[nodiscard]] bool operator==(const State&) const = default;
  };

  double stiffness = 0.0;         ///< K [N/m]
  double damping = 0.0;           ///< C [N·s/m]
  double yield_force = 0.0;       ///< F_y [N]
  double post_yield_ratio = 0.0;  ///< α
  double a = 1.0, beta = 0.5, gamma = 0.5, n = 2.0;

  static constexpr LawTraits traits{.piecewise_linear = false,
                                    .newton = true,
                                    .has_stop = false,
                                    .energy = EnergyGroup::storey,
                                    .name = "Bouc–Wen storey"};

  [[nodiscard]] bool operator==(const BoucWenStorey&) const = default;

  [[nodiscard]] double yield_drift() const { return yield_force / stiffness; }
  /// (1 − α) F_y [N]: the hysteretic force per unit z.
  [[nodiscard]] double hysteretic_scale() const { return (1.0 - post_yield_ratio) * yield_force; }

  /// z₁ and dz₁/dd₁ at the trial drift d₁ from the committed state.
  struct Trial {
    double z = 0.0;
    double slope = 0.0;  ///< dz₁/dd₁ [1/m]
  };
  [[nodiscard]] Trial trial(double d, const State& state) const;

  /// No linear form: its force is smooth (SmoothLaw).
  [[nodiscard]] static std::optional<LinearForm> linear_form(LinkMode /*mode*/) { return std::nullopt; }
  [[nodiscard]] static bool carries_force(LinkMode /*mode*/) { return true; }
  /// F, ∂F/∂d and ∂F/∂ḋ at the trial state k.
  [[nodiscard]] ForceTangent force_tangent(const LinkKinematics& k, LinkMode /*mode*/, const State& state) const {
    const double d = k.ua - k.ub;
    const Trial t = trial(d, state);
    return {.force = post_yield_ratio * stiffness * d + hysteretic_scale() * t.z + damping * (k.va - k.vb),
            .stiffness = post_yield_ratio * stiffness + hysteretic_scale() * t.slope,
            .damping = damping};
  }
  [[nodiscard]] double restoring_force(double d, LinkMode /*mode*/, const State& state) const {
    return post_yield_ratio * stiffness * d + hysteretic_scale() * trial(d, state).z;
  }
  /// Commits the trial state at k (the loop calls it at every accepted state).
  void commit(const LinkKinematics& k, LinkMode /*mode*/, State& state) const {
    const double d = k.ua - k.ub;
    state.z = trial(d, state).z;
    state.drift = d;
  }

  // Energy (dynamics/energy.hpp).
  [[nodiscard]] double stored_energy(const LinkKinematics& k, LinkMode /*mode*/, const State& state) const {
    const double d = k.ua - k.ub;
    const double z = trial(d, state).z;
    return 0.5 * post_yield_ratio * stiffness * d * d + 0.5 * hysteretic_scale() * yield_drift() * z * z / a;
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
  [[nodiscard]] double plastic_work(const LinkKinematics& k0, const LinkKinematics& k1, LinkMode /*mode*/,
                                    const State& state) const {
    const double d0 = k0.ua - k0.ub, d1 = k1.ua - k1.ub;
    const double z0 = trial(d0, state).z, z1 = trial(d1, state).z;
    const double work = 0.5 * hysteretic_scale() * (z0 + z1) * (d1 - d0);
    return work - 0.5 * hysteretic_scale() * yield_drift() * (z1 * z1 - z0 * z0) / a;
  }
};

}  // namespace poundsim
