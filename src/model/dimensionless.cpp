#include "poundsim/model/dimensionless.hpp"

#include <cmath>
#include <stdexcept>

#include "poundsim/units.hpp"

namespace poundsim {

PhysicalParameters to_physical(const DimensionlessParameters& p) {
  if (const auto violation = first_violation(p)) throw std::invalid_argument(*violation);

  const double lambda = std::sqrt(p.lambda2);
  PhysicalParameters out{};
  out.m1 = p.mass1;
  out.k1 = p.lambda2 * p.mass1;
  out.c1 = 2.0 * p.xi * p.mass1 * lambda;
  out.m2 = p.beta * out.m1;
  out.k2 = p.alpha * out.k1;
  out.c2 = p.gamma * out.c1;
  out.gap.stiffness = p.eta * out.k1;
  out.gap.damping = p.mu * p.mass1 * lambda;
  out.gap.gap = p.delta * standard_gravity / p.lambda2;
  out.gap.shortening = p.epsilon * standard_gravity / p.lambda2;
  out.gap.restitution = p.restitution;
  return out;
}

DimensionlessParameters to_dimensionless(const PhysicalParameters& p) {
  DimensionlessParameters d;
  d.mass1 = p.m1;
  d.lambda2 = p.k1 / p.m1;
  const double lambda = std::sqrt(d.lambda2);
  d.alpha = p.k2 / p.k1;
  d.beta = p.m2 / p.m1;
  d.gamma = p.c1 > 0 ? p.c2 / p.c1 : 0.0;
  d.xi = p.c1 / (2.0 * p.m1 * lambda);
  d.delta = p.gap.gap * d.lambda2 / standard_gravity;
  d.eta = p.gap.stiffness / p.k1;
  d.mu = p.gap.damping / (p.m1 * lambda);
  d.epsilon = p.gap.shortening * d.lambda2 / standard_gravity;
  d.restitution = p.gap.restitution;
  return d;
}

Model make_model(const DimensionlessParameters& p, std::array<int, 2> storeys) {
  const PhysicalParameters phys = to_physical(p);
  return make_model({make_uniform_frame(storeys[0], phys.m1, phys.k1, phys.c1, "1"),
                     make_uniform_frame(storeys[1], phys.m2, phys.k2, phys.c2, "2")},
                    phys.gap);
}

}  // namespace poundsim
