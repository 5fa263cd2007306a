#include "poundsim/model/dimensionless.hpp"

#include <cmath>

#include <gtest/gtest.h>

#include "test_models.hpp"

namespace poundsim {
namespace {

TEST(Dimensionless, Fig2SystemHasPeriodsTwoToOneAndFivePercentDamping) {
  // The paper: "the ratio between their fundamental periods is equal to two and their damping
  // ratios are both equal to 5%".
  const Model m = make_model(testing::fig2('c'), {1, 1});
  const double w1 = fundamental_frequency(m.frames[0]), w2 = fundamental_frequency(m.frames[1]);
  EXPECT_NEAR(w1 / w2, 2.0, 1e-14);
  EXPECT_NEAR(w1, std::sqrt(200.0), 1e-12);
  const auto zeta = [](const Frame& f) {
    return f.damping[0] / (2 * f.mass[0] * fundamental_frequency(f));
  };
  EXPECT_NEAR(zeta(m.frames[0]), 0.05, 1e-14);
  EXPECT_NEAR(zeta(m.frames[1]), 0.05, 1e-14);
}

TEST(Dimensionless, GapPropertiesFollowTheDefinitions) {
  DimensionlessParameters p = testing::fig2('c');
  p.mass1 = 2.0;
  const PhysicalParameters q = to_physical(p);
  const double lambda = std::sqrt(p.lambda2);
  EXPECT_DOUBLE_EQ(q.k1, 400.0);
  EXPECT_DOUBLE_EQ(q.gap.stiffness, 0.125 * 400.0);
  EXPECT_DOUBLE_EQ(q.gap.damping, 1.0 * 2.0 * lambda);
  EXPECT_DOUBLE_EQ(q.gap.gap, 0.25 * 9.81 / 200);
  EXPECT_DOUBLE_EQ(q.gap.shortening, 0.5 * 9.81 / 200);
  EXPECT_DOUBLE_EQ(q.gap.restitution, 0.75);
  // And back.
  const DimensionlessParameters r = to_dimensionless(q);
  EXPECT_NEAR(r.lambda2, p.lambda2, 1e-12);
  EXPECT_NEAR(r.alpha, p.alpha, 1e-15);
  EXPECT_NEAR(r.gamma, p.gamma, 1e-15);
  EXPECT_NEAR(r.xi, p.xi, 1e-15);
  EXPECT_NEAR(r.delta, p.delta, 1e-15);
  EXPECT_NEAR(r.eta, p.eta, 1e-15);
  EXPECT_NEAR(r.mu, p.mu, 1e-15);
  EXPECT_NEAR(r.epsilon, p.epsilon, 1e-15);
}

TEST(Dimensionless, RejectsOutOfRangeParameters) {
  DimensionlessParameters p = testing::fig2('a');
  p.restitution = 1.2;
  EXPECT_THROW(to_physical(p), std::invalid_argument);
  p = testing::fig2('a');
  p.lambda2 = 0;
  EXPECT_THROW(to_physical(p), std::invalid_argument);
}

}  // namespace
}  // namespace poundsim
