#include "poundsim/model/impact.hpp"

#include <gtest/gtest.h>

namespace poundsim {
namespace {

TEST(Impact, MatchesThePapersFormulas) {
  // Pasquino et al., impact law after Conoscente et al. (1992).
  const double mi = 2.0, mj = 3.0, e = 0.6, vi = 1.5, vj = -0.5;
  const ImpactOutcome o = restitution_impact(mi, mj, vi, vj, e);
  EXPECT_NEAR(o.v_left, (mi - e * mj) / (mi + mj) * vi + (1 + e) * mj / (mi + mj) * vj, 1e-15);
  EXPECT_NEAR(o.v_right, (1 + e) * mi / (mi + mj) * vi + (mj - e * mi) / (mi + mj) * vj, 1e-15);
}

TEST(Impact, ConservesMomentumAndReversesRelativeVelocity) {
  const double mi = 2.0, mj = 3.0, vi = 1.5, vj = -0.5;
  for (const double e : {0.0, 0.3, 0.75, 1.0}) {
    const ImpactOutcome o = restitution_impact(mi, mj, vi, vj, e);
    EXPECT_NEAR(mi * o.v_left + mj * o.v_right, mi * vi + mj * vj, 1e-14);
    EXPECT_NEAR(o.v_left - o.v_right, -e * (vi - vj), 1e-14);
    const double lost = 0.5 * (mi * vi * vi + mj * vj * vj) -
                        0.5 * (mi * o.v_left * o.v_left + mj * o.v_right * o.v_right);
    EXPECT_NEAR(o.energy_loss, lost, 1e-14);
    EXPECT_NEAR(o.impulse, mj * (o.v_right - vj), 1e-14);
  }
}

TEST(Impact, SeparatingBodiesAreLeftAlone) {
  const ImpactOutcome o = restitution_impact(1.0, 1.0, -1.0, 1.0, 0.5);
  EXPECT_EQ(o.v_left, -1.0);
  EXPECT_EQ(o.v_right, 1.0);
  EXPECT_EQ(o.impulse, 0.0);
}

}  // namespace
}  // namespace poundsim
