// Periodic orbits by shooting and continuation (issue 12): the monodromy matrix against finite
// differences of the map, linear frames against their closed form, the forced impact oscillator
// against its analytic period-1 orbit and period-doubling frequency, stable orbits against long
// exact simulations.

#include <cmath>
#include <complex>
#include <array>
#include <numbers>
#include <vector>

#include <Eigen/Dense>
#include <gtest/gtest.h>

#include "poundsim/analysis/periodic_orbits.hpp"
#include "poundsim/model/dimensionless.hpp"
#include "test_models.hpp"

namespace poundsim {
namespace {

constexpr double kG = 9.81;

TimeHistoryOptions exact_options() {
  TimeHistoryOptions o;
  o.integrator = Integrator::exact;
  o.dt = 1.0;
  // The rest-velocity rule switches e to 0 below a threshold: a jump of the map that finite
  // differences would straddle. None of these orbits comes near it; off keeps the map smooth.
  o.rest_velocity_ratio = 0.0;
  return o;
}

Eigen::VectorXd state_of(const PeriodicOrbit& orbit) {
  Eigen::VectorXd x(2 * orbit.u.size());
  x << orbit.u, orbit.v;
  return x;
}

/// Central differences of the map, column by column.
Eigen::MatrixXd finite_difference_jacobian(StroboscopicMap& map, const Eigen::VectorXd& x, int k) {
  const Eigen::Index m = x.size();
  Eigen::MatrixXd j(m, m);
  const Eigen::Index n = m / 2;
  const double u_scale = x.head(n).cwiseAbs().maxCoeff(), v_scale = x.tail(n).cwiseAbs().maxCoeff();
  for (Eigen::Index c = 0; c < m; ++c) {
    const double h = 1e-6 * (c < n ? u_scale : v_scale);
    Eigen::VectorXd plus = x, minus = x;
    plus(c) += h;
    minus(c) -= h;
    j.col(c) = (map.evaluate(plus, k) - map.evaluate(minus, k)) / (2 * h);
  }
  return j;
}

/// max |A − B| relative to max |B|, column scaled (displacement and velocity columns differ by ω).
double relative_difference(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b) {
  double worst = 0;
  for (Eigen::Index c = 0; c < a.cols(); ++c) {
    worst = std::max(worst, (a.col(c) - b.col(c)).cwiseAbs().maxCoeff() / b.col(c).cwiseAbs().maxCoeff());
  }
  return worst;
}

struct MapCase {
  const char* name;
  Model model;
  double ratio;
};

TEST(StroboscopicMap, TheMonodromyOfImpactsAndContactsIsTheMapsDerivative) {
  // Fig. 2c's frames (gap elements: contact, impact on the stop, separation) and Fig. 2b's (bare
  // pounding, e = 0.75), Fig. 3's three-storey frames: the exact monodromy against central
  // differences of the map.
  DimensionlessParameters hard = testing::fig2('c');
  hard.epsilon = 0.1;  // a short stroke: the spring bottoms out on the stop
  DimensionlessParameters fig3b = testing::fig2('c');
  fig3b.lambda2 = 400; fig3b.delta = 0.5; fig3b.mu = 2; fig3b.epsilon = 1;
  DimensionlessParameters fig3a = testing::fig2('b');
  fig3a.lambda2 = 400; fig3a.delta = 0.5;
  DimensionlessParameters plastic = testing::fig2('b');
  plastic.restitution = 0.0;
  const std::vector<MapCase> cases{
      {"2b", make_model(testing::fig2('b'), {1, 1}), 0.8},  {"2c", make_model(testing::fig2('c'), {1, 1}), 0.8},
      {"2c-short", make_model(hard, {1, 1}), 0.9},          {"2c-short", make_model(hard, {1, 1}), 0.6},
      {"3a", make_model(fig3a, {3, 3}), 0.9},               {"3b", make_model(fig3b, {3, 3}), 0.9},
      {"4b", make_model(testing::fig4('b'), {1, 3}), 0.8}, {"4a", make_model(testing::fig4('a'), {1, 3}), 0.8},
      {"4a", make_model(testing::fig4('a'), {1, 3}), 1.5}, {"2-plastic", make_model(plastic, {1, 1}), 0.9},
      {"2-plastic", make_model(plastic, {1, 1}), 0.6}};
  std::array<int, 5> kinds{};
  for (const MapCase& c : cases) {
    const double omega1 = reference_frequency(c.model);
    StroboscopicMap map(c.model, 0.2 * kG, c.ratio * omega1, exact_options(), 64);
    const Eigen::VectorXd start = settled_state(map, Eigen::VectorXd::Zero(2 * map.dofs()), 40);
    const ShootingResult r = shoot(map, start, 1, ShootingOptions{});
    ASSERT_TRUE(r.converged) << c.name << ": " << r.failure;
    ASSERT_GT(r.orbit.events, 0) << c.name;
    const Eigen::VectorXd x = state_of(r.orbit);
    Eigen::MatrixXd exact;
    map.evaluate(x, 1, &exact);
    const Eigen::MatrixXd differences = finite_difference_jacobian(map, x, 1);
    for (const auto& g : map.simulator().statistics().gaps) {
      kinds[0] += g.contacts;
      kinds[1] += g.separations;
      kinds[2] += g.impacts;
      kinds[3] += g.locks;
      kinds[4] += g.unlocks;
    }
    EXPECT_LT(relative_difference(exact, differences), 1e-6) << c.name << " at " << c.ratio << "\nexact\n"
                                                             << exact << "\ndifferences\n" << differences;
  }
  // Every kind of event was crossed: contact, separation, impact, lock, unlock.
  for (const int count : kinds) EXPECT_GT(count, 0);
}

}  // namespace
}  // namespace poundsim
