#include "poundsim/model/impact.hpp"

namespace poundsim {

ImpactOutcome restitution_impact(double m_left, double m_right, double v_left, double v_right,
                                 double restitution) {
  const double w = v_left - v_right;
  if (!(w > 0.0)) return {v_left, v_right, 0.0, 0.0};
  const double total = m_left + m_right;
  const double reduced_mass = m_left * m_right / total;
  const double impulse = (1.0 + restitution) * reduced_mass * w;
  // From the centre of mass rather than v ∓ J/m: a plastic impact (e = 0) then leaves both bodies
  // with bit-identical velocities, not a closing speed of a few ulps that fires a second impact.
  const double centre = (m_left * v_left + m_right * v_right) / total;
  return {centre - restitution * m_right * w / total, centre + restitution * m_left * w / total,
          impulse, 0.5 * (1.0 - restitution * restitution) * reduced_mass * w * w};
}

}  // namespace poundsim
