#include "poundsim/model/dimensionless.hpp"

#include <cmath>
#include <stdexcept>
#include <string_view>
#include <vector>

#include <fmt/format.h>

#include "poundsim/units.hpp"

namespace poundsim {

std::optional<FieldRule> DimensionlessParameters::rule_violation() const {
  const double lambda = std::sqrt(lambda2), k1 = lambda2 * mass1, c1 = 2.0 * xi * mass1 * lambda;
  struct Product {
    double value;
    std::vector<std::string_view> keys;
    const char* what;
  };
  for (const Product& q : {Product{k1, {"lambda2", "mass1"}, "K₁ = λ² M₁"},
                           Product{alpha * k1, {"alpha", "lambda2", "mass1"}, "K₂ = α K₁"},
                           Product{beta * mass1, {"beta", "mass1"}, "M₂ = β M₁"},
                           Product{c1, {"xi", "lambda2", "mass1"}, "C₁ = 2 ξ̄ M₁ λ"},
                           Product{gamma * c1, {"gamma", "xi", "lambda2", "mass1"}, "C₂ = γ C₁"},
                           Product{eta * k1, {"eta", "lambda2", "mass1"}, "k = η K₁"},
                           Product{mu * mass1 * lambda, {"mu", "lambda2", "mass1"}, "c = μ M₁ λ"}}) {
    if (!std::isfinite(q.value)) {
      return FieldRule{q.keys, fmt::format("{} overflows the range of double precision (λ² = {}, M₁ = {} kg): give "
                                           "smaller values",
                                           q.what, lambda2, mass1)};
    }
  }
  return std::nullopt;
}

PhysicalParameters to_physical(const DimensionlessParameters& p) {
  if (const auto violation = first_violation(p)) throw std::invalid_argument(*violation);
  if (const auto rule = p.rule_violation()) throw std::invalid_argument(rule->message);

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
