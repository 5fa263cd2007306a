#include "poundsim/impact.hpp"

namespace poundsim {

ImpactOutcome restitution_impact(double m_left, double m_right, double v_left, double v_right,
                                 double restitution) {
  const double w = v_left - v_right;
  if (!(w > 0.0)) return {v_left, v_right, 0.0, 0.0};
  const double reduced_mass = m_left * m_right / (m_left + m_right);
  const double impulse = (1.0 + restitution) * reduced_mass * w;
  return {v_left - impulse / m_left, v_right + impulse / m_right, impulse,
          0.5 * (1.0 - restitution * restitution) * reduced_mass * w * w};
}

}  // namespace poundsim
