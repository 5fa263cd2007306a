#pragma once
/// @file
/// The impact law (Pasquino, Santini & Caliò, after Conoscente et al. 1992): when the shortening
/// of a gap element reaches ε while closing, the two floors (or the two groups of floors held
/// together by locked elements) of masses m_L, m_R collide. Momentum is conserved and the relative
/// velocity reverses with the coefficient of restitution e:
///
///     v_L⁺ = ((m_L − e m_R) v_L⁻ + (1+e) m_R v_R⁻) / (m_L + m_R)
///     v_R⁺ = ((1+e) m_L v_L⁻ + (m_R − e m_L) v_R⁻) / (m_L + m_R)
///
/// equivalently an impulse J = (1+e) m_L m_R/(m_L+m_R) · w on the pair, w = v_L⁻ − v_R⁻ > 0 the
/// closing velocity, which loses ½ (1−e²) m_L m_R/(m_L+m_R) w² of kinetic energy.
/// e = 0 is the plastic impact: both leave with the common velocity of their centre of mass.

namespace poundsim {

struct ImpactOutcome {
  double v_left = 0.0;       ///< v_L⁺ [m/s]
  double v_right = 0.0;      ///< v_R⁺ [m/s]
  double impulse = 0.0;      ///< J ≥ 0 [N·s], pushing the left body left and the right one right.
  double energy_loss = 0.0;  ///< ΔT ≥ 0 [J]
};

/// Applies the restitution law. Requires m_L, m_R > 0 and 0 ≤ e ≤ 1; for w ≤ 0 (not closing)
/// nothing happens.
[[nodiscard]] ImpactOutcome restitution_impact(double m_left, double m_right, double v_left,
                                               double v_right, double restitution);

}  // namespace poundsim
