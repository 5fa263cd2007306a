#pragma once
/// @file
/// A spring k and a dashpot c in parallel between two floors, in contact while the shortening
/// s = d − δ is positive, F = c ṡ + k s (compression positive). It touches when s reaches 0 — or
/// the free end of an element that separated compressed — and separates when s returns to 0
/// (the displacement criterion) or when F would become tensile (the force criterion); after a
/// force separation its massless free end relaxes on its own, c ṡ_e + k s_e = 0, until the floors
/// touch it again. What the contact laws built on it share: the paper's element adds a stop at
/// s = ε (paper_gap.hpp); the Kelvin–Voigt contact is this alone (kelvin_voigt.hpp).

#include <cmath>
#include <limits>

#include "poundsim/model/contact_state.hpp"
#include "poundsim/model/laws/contact_law.hpp"

namespace poundsim {

struct SpringDashpot {
  double stiffness = 0.0;  ///< k [N/m]
  double damping = 0.0;    ///< c [N·s/m]

  /// A guard within a few ulps of zero is zero, and zero does not fire: without this floor, a
  /// guard that stays at zero for a while (a pair released with ṡ = 0 at the stop) would flicker
  /// in the last bit and stall event location.
  static constexpr double kNoise = 8 * std::numeric_limits<double>::epsilon();

  /// The round-off level of s = u_a − u_b − δ [m] for a contact with gap δ (the contact laws
  /// without a stop share it; the paper's element adds its stroke ε to the lengths).
  [[nodiscard]] static double position_noise(const LinkKinematics& k, double gap) {
    return kNoise * (std::abs(k.ua) + std::abs(k.ub) + gap);
  }

  /// What the element keeps between events (its law's State): after a separation with its spring
  /// compressed (the force criterion), its free end relaxes, s_e(t) = released_shortening ·
  /// exp(−k (t − release_time) / c), until the floors touch it again.
  struct FreeEnd {
    double released_shortening = 0.0;  ///< s_e at release [m]; 0 when the element is relaxed.
    double release_time = 0.0;         ///< [s] on the simulation's clock
    /// Shortening of the element's free end at time t [m] (0 for a plain open element). Inline:
    /// every guard evaluation of an open element asks it.
    [[nodiscard]] double free_end_shortening(double t, double spring, double dashpot) const {
      if (released_shortening == 0.0) return 0.0;
      if (dashpot <= 0.0) return 0.0;  // a spring without dashpot recovers at once
      return released_shortening * std::exp(-spring / dashpot * (t - release_time));
    }
    void shift_clock(double origin) { release_time -= origin; }
    [[nodiscard]] bool operator==(const FreeEnd&) const = default;
  };

  /// F = c ṡ + k s [N].
  [[nodiscard]] double force(double s, double rate) const { return damping * rate + stiffness * s; }

  /// s_e of `end` at t [m].
  [[nodiscard]] double free_end(const FreeEnd& end, double t) const {
    return end.free_end_shortening(t, stiffness, damping);
  }

  /// The approach guard of an open element: s − s_e, rising through 0 at contact.
  [[nodiscard]] GuardValue approach_guard(const LinkKinematics& k, double s, double s_noise,
                                          const FreeEnd& end) const {
    const double se = free_end(end, k.t);
    const double se_rate = damping > 0 ? -stiffness / damping * se : 0.0;
    return {.active = true, .value = s - se, .rate = (k.va - k.vb) - se_rate, .noise = s_noise,
            .hysteresis = true};
  }

  /// The separation guard in contact: −s, or −F under the force criterion.
  [[nodiscard]] GuardValue separation_guard(const LinkKinematics& k, double s, double s_noise,
                                            SeparationCriterion separation) const {
    const double rate = k.va - k.vb;
    if (separation == SeparationCriterion::force) {
      const double accel = k.aa - k.ab;
      const double f_noise = kNoise * (damping * (std::abs(k.va) + std::abs(k.vb)) + stiffness * s_noise / kNoise);
      return {.active = true, .value = -force(s, rate), .rate = -(damping * accel + stiffness * rate),
              .noise = f_noise};
    }
    return {.active = true, .value = -s, .rate = -rate, .noise = s_noise};
  }

  /// The separation guard's affine form in (d, ḋ), for the exact integrator.
  [[nodiscard]] GuardForm separation_form(SeparationCriterion separation) const {
    if (separation == SeparationCriterion::force) {
      return {.kind = GuardForm::Kind::affine, .d_coefficient = -stiffness, .rate_coefficient = -damping};
    }
    return {.kind = GuardForm::Kind::affine, .d_coefficient = -1.0};
  }

  /// The free end an element leaves when it separates at shortening s and time t: relaxing after a
  /// force separation with the spring compressed, relaxed otherwise.
  [[nodiscard]] static FreeEnd released(double s, double t, SeparationCriterion separation) {
    return separation == SeparationCriterion::force && s > 0 ? FreeEnd{s, t} : FreeEnd{};
  }

  /// The relaxation in the approach guard of an open element (nothing when not relaxing).
  [[nodiscard]] Relaxation relaxation(const FreeEnd& end, double t) const {
    if (end.released_shortening == 0.0 || !(damping > 0)) return {};
    return {.amplitude = free_end(end, t), .rate = stiffness / damping};
  }

  /// What a relaxing free end's spring releases into its dashpot from t0 to t1,
  /// ½ k (s_e0² − s_e1²) [J]; 0 when not relaxing.
  [[nodiscard]] double relaxation_release(const FreeEnd& end, double t0, double t1) const {
    if (end.released_shortening == 0.0) return 0.0;
    const double s0 = free_end(end, t0);
    const double s1 = free_end(end, t1);
    return 0.5 * stiffness * (s0 * s0 - s1 * s1);
  }
};

}  // namespace poundsim
