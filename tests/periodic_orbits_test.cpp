// Periodic orbits by shooting and continuation: the monodromy matrix against finite
// differences of the map, linear frames against their closed form, the forced impact oscillator
// against its analytic period-1 orbit and period-doubling frequency, stable orbits against long
// exact simulations, the paper's frequency responses from rest against their continuation.

#include <cmath>
#include <complex>
#include <algorithm>
#include <array>
#include <map>
#include <numbers>
#include <set>
#include <string>
#include <vector>

#include <Eigen/Dense>
#include <unsupported/Eigen/MatrixFunctions>
#include <gtest/gtest.h>

#include "poundsim/analysis/periodic_orbits.hpp"
#include "poundsim/io/frequency_response_run.hpp"
#include "poundsim/io/input.hpp"
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

/// Fig. 2c's frames (gap elements: contact, impact on the stop, separation) and Fig. 2b's (bare
/// pounding, e = 0.75), Fig. 3's three-storey frames, Fig. 4's frames touching at rest (locks).
std::vector<MapCase> map_cases() {
  DimensionlessParameters hard = testing::fig2('c');
  hard.epsilon = 0.1;  // a short stroke: the spring bottoms out on the stop
  DimensionlessParameters fig3b = testing::fig2('c');
  fig3b.lambda2 = 400; fig3b.delta = 0.5; fig3b.mu = 2; fig3b.epsilon = 1;
  DimensionlessParameters fig3a = testing::fig2('b');
  fig3a.lambda2 = 400; fig3a.delta = 0.5;
  DimensionlessParameters plastic = testing::fig2('b');
  plastic.restitution = 0.0;
  return {{"2b", make_model(testing::fig2('b'), {1, 1}), 0.8},  {"2c", make_model(testing::fig2('c'), {1, 1}), 0.8},
          {"2c-short", make_model(hard, {1, 1}), 0.9},          {"2c-short", make_model(hard, {1, 1}), 0.6},
          {"3a", make_model(fig3a, {3, 3}), 0.9},               {"3b", make_model(fig3b, {3, 3}), 0.9},
          {"4b", make_model(testing::fig4('b'), {1, 3}), 0.8}, {"4a", make_model(testing::fig4('a'), {1, 3}), 0.8},
          {"4a", make_model(testing::fig4('a'), {1, 3}), 1.5}, {"2-plastic", make_model(plastic, {1, 1}), 0.9},
          {"2-plastic", make_model(plastic, {1, 1}), 0.6}};
}

TEST(StroboscopicMap, TheMonodromyOfImpactsAndContactsIsTheMapsDerivative) {
  // The exact monodromy against central differences of the map.
  const std::vector<MapCase> cases = map_cases();
  std::array<int, 5> kinds{};
  for (const MapCase& c : cases) {
    const double omega1 = reference_frequency(c.model);
    StroboscopicMap map(c.model, 0.2 * kG, c.ratio * omega1, exact_options(), 64);
    const Eigen::VectorXd start = settled_state(map, Eigen::VectorXd::Zero(2 * map.dofs()), 40);
    const ShootingResult r = shoot(map, start, 1, ShootingOptions{});
    ASSERT_TRUE(r.converged) << c.name << ": " << r.failure;
    ASSERT_GT(r.orbit.events, 0) << c.name;
    const Eigen::VectorXd x = state_of(r.orbit);
    // Recording the peaks changes nothing of the run: the same state, the same monodromy, the same
    // events, bit for bit (the map meters no energy; that metering leaves a run's bits alone is
    // SimulatorEnergy.PeaksWithoutTheBalanceAreTheSameBits).
    Eigen::MatrixXd recorded_monodromy;
    const Eigen::VectorXd recorded = map.evaluate(x, 1, &recorded_monodromy, StroboscopicMap::Responses::record);
    const long recorded_events = map.simulator().statistics().events;
    // The orbit's peaks are those of its recorded period.
    const FrameAmplitudes peaks = run_amplitudes(map.simulator());
    for (std::size_t f = 0; f < 2; ++f) {
      EXPECT_GT(peaks.base_shear[f], 0.0) << c.name;
      EXPECT_EQ(r.orbit.amplitudes.base_shear[f], peaks.base_shear[f]) << c.name;
      EXPECT_EQ(r.orbit.amplitudes.top_displacement[f], peaks.top_displacement[f]) << c.name;
    }
    Eigen::MatrixXd exact;
    const Eigen::VectorXd skipped = map.evaluate(x, 1, &exact);
    EXPECT_TRUE(skipped == recorded) << c.name;
    EXPECT_TRUE(exact == recorded_monodromy) << c.name;
    EXPECT_EQ(map.simulator().statistics().events, recorded_events) << c.name;
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

TEST(StroboscopicMap, SensitivitiesStartedMidRunFollowTheSegmentUnderWay) {
  // Two oscillators in free vibration with impacts; J started at t₁ inside a segment (not at an
  // event or a restart) is ∂x(t₂)/∂x(t₁): against central differences of runs started at x(t₁)
  // (autonomous, so their clock does not matter). Before the stepper handed its segment to a
  // tangent flow started mid-run, J stayed I until the first event.
  const Model model = testing::two_oscillators(1, 25, 1, 1, 400, 4, GapProperties{.gap = 0.02, .restitution = 0.5});
  TimeHistoryOptions options = exact_options();
  options.dt = 0.01;
  InitialConditions ic;
  ic.velocity = {{0.4}, {0.0}};
  Simulator run(model, NoExcitation{}, options, ic);
  const double t1 = 0.0537, t2 = 1.3;
  run.advance_to(t1);
  const Eigen::Index n = 2;
  Eigen::VectorXd x1(2 * n);
  x1 << run.state().u, run.state().v;
  run.track_sensitivity();
  const long events_before = run.statistics().events;
  run.advance_to(t2);
  ASSERT_GE(run.statistics().events, events_before + 2);
  const Eigen::MatrixXd j = run.sensitivity();
  Eigen::MatrixXd differences(2 * n, 2 * n);
  for (Eigen::Index c = 0; c < 2 * n; ++c) {
    const double h = 1e-7;
    Eigen::VectorXd plus = x1, minus = x1;
    plus(c) += h;
    minus(c) -= h;
    Eigen::VectorXd images[2];
    for (int side = 0; side < 2; ++side) {
      const Eigen::VectorXd& start = side == 0 ? plus : minus;
      Simulator from(model, NoExcitation{}, options);
      from.reset_state(start.head(n), start.tail(n));
      from.advance_to(t2 - t1);
      images[side].resize(2 * n);
      images[side] << from.state().u, from.state().v;
    }
    differences.col(c) = (images[0] - images[1]) / (2 * h);
  }
  EXPECT_LT(relative_difference(j, differences), 1e-5) << "J\n" << j << "\ndifferences\n" << differences;
}

TEST(StroboscopicMap, ItsFrequencyDerivativeIsTheMapsDerivativeInTheFrequency) {
  // ∂P/∂ω̄ carried through the run (the sensitivity to ω̄ within each phase, the events'
  // saltation, the period's shortening) against central differences of the map in ω̄ at the same
  // state, on the orbits of every kind of event above; and for linear frames against the closed
  // form: P(x*(ω̄); ω̄) = x*(ω̄) for their steady state x*, so ∂P/∂ω̄ = (I − M) dx*/dω̄.
  for (const MapCase& c : map_cases()) {
    const double omega = c.ratio * reference_frequency(c.model);
    StroboscopicMap map(c.model, 0.2 * kG, omega, exact_options(), 64);
    const Eigen::VectorXd start = settled_state(map, Eigen::VectorXd::Zero(2 * map.dofs()), 40);
    const ShootingResult r = shoot(map, start, 1, ShootingOptions{});
    ASSERT_TRUE(r.converged) << c.name << ": " << r.failure;
    const Eigen::VectorXd x = state_of(r.orbit);
    Eigen::MatrixXd monodromy, without;
    Eigen::VectorXd rate;
    const Eigen::VectorXd image = map.evaluate(x, 1, &monodromy, StroboscopicMap::Responses::skip, &rate);
    // Carrying ∂x/∂ω̄ leaves the run and its monodromy as they were, bit for bit.
    EXPECT_TRUE(map.evaluate(x, 1, &without) == image) << c.name;
    EXPECT_TRUE(without == monodromy) << c.name;
    const double h = 1e-6 * omega;
    map.set_omega(omega + h);
    const Eigen::VectorXd plus = map.evaluate(x, 1);
    map.set_omega(omega - h);
    const Eigen::VectorXd minus = map.evaluate(x, 1);
    map.set_omega(omega);
    const Eigen::VectorXd difference = (plus - minus) / (2 * h);
    const Eigen::Index n = map.dofs();
    // Displacements and velocities apart: they differ by ω̄.
    for (const Eigen::Index first : {Eigen::Index{0}, n}) {
      const Eigen::VectorXd a = rate.segment(first, n), d = difference.segment(first, n);
      EXPECT_LT((a - d).cwiseAbs().maxCoeff(), 1e-6 * d.cwiseAbs().maxCoeff())
          << c.name << " at " << c.ratio << "\nexact " << rate.transpose() << "\ndifferences " << difference.transpose();
    }
  }

  // Frames far apart: no contact, the map is the linear frames'.
  DimensionlessParameters far = testing::fig2('c');
  far.delta = 100.0;
  const Model apart = make_model(far, {2, 3});
  for (const double ratio : {0.5, 0.9, 1.4}) {
    const double omega = ratio * reference_frequency(apart);
    StroboscopicMap map(apart, 0.2 * kG, omega, exact_options(), 64);
    const Eigen::VectorXd steady = linear_steady_state(apart, 0.2 * kG, omega);
    Eigen::MatrixXd monodromy;
    Eigen::VectorXd rate;
    map.evaluate(steady, 1, &monodromy, StroboscopicMap::Responses::skip, &rate);
    ASSERT_EQ(map.simulator().statistics().events, 0);
    const double h = 1e-5 * omega;
    const Eigen::VectorXd steady_rate =
        (linear_steady_state(apart, 0.2 * kG, omega + h) - linear_steady_state(apart, 0.2 * kG, omega - h)) / (2 * h);
    const Eigen::VectorXd closed = (Eigen::MatrixXd::Identity(rate.size(), rate.size()) - monodromy) * steady_rate;
    EXPECT_LT((rate - closed).cwiseAbs().maxCoeff(), 1e-7 * closed.cwiseAbs().maxCoeff()) << ratio;
  }
}


// ---- the forced impact oscillator ---------------------------------------------------------
//
// ẍ + 2ζω₀ẋ + ω₀²x = −A sin ω̄t with a rigid stop at x = δ (impact: ẋ → −e ẋ). Its period-1 orbit
// with one impact per period, in closed form (docs/periodic-orbits.md): with the impact at phase
// θ = ω̄τ at speed V, the flight of one period from (δ, −eV) returns to (δ, V):
//     Φ(T)(δ, −eV) − (δ, V) = (Φ(T) − I) x_p(τ),   x_p(τ) = P (sin θ, cos θ),
// so (sin θ, cos θ) = a + V b and |a + V b| = 1 is a quadratic in V. The monodromy from just
// after an impact is M = Φ(T) S, S = [[−e, 0], [(a⁺ + e a⁻)/V, −e]]; it doubles its period where
// 1 + tr M + det M = 0.

struct ImpactOscillator {
  double omega0 = 2 * std::numbers::pi, zeta = 0.05, amplitude = 1.0, e = 0.8;
  double gap = 0.1 * 1.0 / (4 * std::numbers::pi * std::numbers::pi);  // σ = δω₀²/A = 0.1

  /// The frame on a stiff, heavy neighbour (10⁸ × the mass, 10⁴ × the frequency, 5 % damping): a
  /// stop that moves by ~10⁻⁸ of the oscillator and whose own multipliers are ~e^{−0.05·10⁴ω₀T}.
  [[nodiscard]] Model model() const {
    const double m = 1e5;
    const double m2 = 1e8 * m, w2 = 1e4 * omega0;
    GapProperties stop;
    stop.gap = gap;
    stop.restitution = e;
    return make_model({make_uniform_frame(1, m, m * omega0 * omega0, 2 * zeta * omega0 * m, "oscillator"),
                       make_uniform_frame(1, m2, m2 * w2 * w2, 2 * 0.05 * w2 * m2, "stop")},
                      stop);
  }
  [[nodiscard]] Eigen::Matrix2d flow(double s) const {
    Eigen::Matrix2d a;
    a << 0, 1, -omega0 * omega0, -2 * zeta * omega0;
    return (a * s).exp();
  }
  [[nodiscard]] std::complex<double> response(double w) const {
    return -amplitude / std::complex<double>(omega0 * omega0 - w * w, 2 * zeta * omega0 * w);
  }
  [[nodiscard]] Eigen::Vector2d particular(double w, double t) const {
    const std::complex<double> u = response(w) * std::exp(std::complex<double>(0, w * t));
    return {u.imag(), (std::complex<double>(0, w) * u).imag()};
  }
  struct Orbit {
    bool exists = false;
    double theta = 0, speed = 0;
    Eigen::Vector2d at_zero;   ///< the state at t = 0 (mod T)
    Eigen::Matrix2d monodromy;  ///< from just after the impact
  };
  /// `high`: the root with the larger impact speed (the resonant, stable one).
  [[nodiscard]] Orbit orbit(double w, bool high = true) const {
    const double period = 2 * std::numbers::pi / w;
    const Eigen::Matrix2d phi = flow(period);
    const Eigen::Matrix2d b_matrix = phi - Eigen::Matrix2d::Identity();
    const std::complex<double> u = response(w);
    Eigen::Matrix2d p;
    p << u.real(), u.imag(), -w * u.imag(), w * u.real();
    const Eigen::Vector2d q = -e * phi.col(1) - Eigen::Vector2d(0, 1);
    const Eigen::Matrix2d bp = b_matrix * p;
    const Eigen::Vector2d a = bp.lu().solve(b_matrix * Eigen::Vector2d(gap, 0));
    const Eigen::Vector2d b = bp.lu().solve(q);
    const double qa = b.squaredNorm(), qb = 2 * a.dot(b), qc = a.squaredNorm() - 1;
    const double disc = qb * qb - 4 * qa * qc;
    Orbit o;
    if (disc < 0) return o;
    o.speed = (-qb + (high ? 1 : -1) * std::sqrt(disc)) / (2 * qa);
    if (!(o.speed > 0)) return o;
    const Eigen::Vector2d sc = a + o.speed * b;
    o.theta = std::atan2(sc(0), sc(1));
    double tau = o.theta / w;
    while (tau < 0) tau += period;
    while (tau >= period) tau -= period;
    const Eigen::Vector2d after(gap, -e * o.speed);
    o.at_zero = particular(w, period) + flow(period - tau) * (after - particular(w, tau));
    // No other contact in flight.
    for (int i = 1; i < 400; ++i) {
      const double s = period * i / 400;
      const Eigen::Vector2d x = particular(w, tau + s) + flow(s) * (after - particular(w, tau));
      if (x(0) > gap) return o;
    }
    const double forcing = -amplitude * std::sin(o.theta);
    const double before_acc = -2 * zeta * omega0 * o.speed - omega0 * omega0 * gap + forcing;
    const double after_acc = 2 * zeta * omega0 * e * o.speed - omega0 * omega0 * gap + forcing;
    Eigen::Matrix2d salt;
    salt << -e, 0, (after_acc + e * before_acc) / o.speed, -e;
    o.monodromy = phi * salt;
    o.exists = true;
    return o;
  }
  /// 1 + tr M + det M of the resonant orbit: 0 at its period doubling.
  [[nodiscard]] double doubling_test(double w) const {
    const Orbit o = orbit(w);
    return 1 + o.monodromy.trace() + o.monodromy.determinant();
  }
};

TEST(ImpactOscillator, ShootingFindsTheAnalyticPeriodOneOrbitAndItsMultipliers) {
  const ImpactOscillator osc;
  const Model model = osc.model();
  for (const double ratio : {1.2, 1.8, 2.0, 2.3}) {
    const double w = ratio * osc.omega0;
    const ImpactOscillator::Orbit analytic = osc.orbit(w);
    ASSERT_TRUE(analytic.exists) << ratio;
    StroboscopicMap map(model, osc.amplitude, w, exact_options(), 32);
    Eigen::VectorXd start = Eigen::VectorXd::Zero(4);
    start(0) = analytic.at_zero(0) * 1.01;
    start(2) = analytic.at_zero(1) * 0.99;
    const ShootingResult r = shoot(map, start, 1, ShootingOptions{});
    ASSERT_TRUE(r.converged) << ratio << ": " << r.failure;
    EXPECT_EQ(r.orbit.impacts, 1) << ratio;
    // The neighbour moves by ~1e-8 of the oscillator where the analytic stop is fixed.
    const double size = analytic.at_zero.cwiseAbs().maxCoeff();
    EXPECT_NEAR(r.orbit.u(0), analytic.at_zero(0), 1e-7 * size) << ratio;
    EXPECT_NEAR(r.orbit.v(0) / w, analytic.at_zero(1) / w, 1e-7 * size) << ratio;
    // The oscillator's two multipliers are those of M = Φ(T) S (the same up to a similarity); the
    // neighbour's two are e^{λT} of its own stiff mode, far smaller.
    const Eigen::Vector2cd expected = Eigen::EigenSolver<Eigen::Matrix2d>(analytic.monodromy).eigenvalues();
    std::vector<std::complex<double>> got(r.orbit.multipliers.data(), r.orbit.multipliers.data() + 2);
    for (const std::complex<double>& mu : expected) {
      const double nearest = std::min(std::abs(got[0] - mu), std::abs(got[1] - mu));
      EXPECT_LT(nearest, 1e-4) << ratio << ": " << mu;
    }
    EXPECT_EQ(r.orbit.stable, std::abs(expected(0)) < 1 && std::abs(expected(1)) < 1) << ratio;
  }
}

TEST(ImpactOscillator, ContinuationFindsTheAnalyticPeriodDoubling) {
  const ImpactOscillator osc;
  // The analytic doubling: 1 + tr M + det M changes sign; bisected to 1e-12.
  double lo = 2.0 * osc.omega0, hi = 2.8 * osc.omega0;
  ASSERT_LT(osc.doubling_test(lo) * osc.doubling_test(hi), 0);
  for (int i = 0; i < 100; ++i) {
    const double mid = 0.5 * (lo + hi);
    (osc.doubling_test(lo) * osc.doubling_test(mid) <= 0 ? hi : lo) = mid;
  }
  const double analytic = 0.5 * (lo + hi) / osc.omega0;
  // As derived independently for σ = 0.1, e = 0.8, ζ = 0.05 (docs/periodic-orbits.md).
  EXPECT_NEAR(analytic, 2.45671536, 1e-8);

  const Model model = osc.model();
  TimeHistoryOptions options = exact_options();
  FrequencyFamily family(model, osc.amplitude, options, 32);
  StroboscopicMap& map = family.at(2.4);
  const ImpactOscillator::Orbit start_orbit = osc.orbit(2.4 * osc.omega0);
  Eigen::VectorXd start = Eigen::VectorXd::Zero(4);
  start(0) = start_orbit.at_zero(0);
  start(2) = start_orbit.at_zero(1);
  ShootingResult r = shoot(map, start, 1, ShootingOptions{});
  ASSERT_TRUE(r.converged) << r.failure;
  r.orbit.parameter = 2.4;
  ContinuationOptions co;
  co.max_parameter_step = 5e-3;
  co.max_points = 30;  // enough to pass the doubling and start the period-2 branch
  const ContinuationResult traced = continue_orbits(family, r.orbit, 2.4, 2.5, +1, ShootingOptions{}, co);
  ASSERT_FALSE(traced.branches.empty());
  const Branch& main = traced.branches.front();
  const auto pd = std::find_if(main.points.begin(), main.points.end(), [](const PeriodicOrbit& p) {
    return p.bifurcation == BifurcationKind::period_doubling;
  });
  ASSERT_NE(pd, main.points.end());
  // The doubling lies between the flagged point and the one before; the refined point is at it.
  EXPECT_NEAR(pd->parameter, analytic, 1e-6) << "between " << (pd - 1)->parameter << " and " << (pd + 1)->parameter;
  EXPECT_NEAR(pd->multipliers(pd->multipliers.size() > 0 ? 0 : 0).real(), -1.0, 1e-6);
  // Beyond it a period-2 branch is followed.
  ASSERT_GE(traced.branches.size(), 2u);
  EXPECT_EQ(traced.branches[1].periodicity, 2);
  EXPECT_GT(traced.branches[1].points.size(), 3u);
}


// A period-1 orbit shot as a fixed point of P² is labelled by its minimal period, 1; the
// period-2 branch born at the doubling keeps 2 away from it, where P(w) is far from w.
TEST(ImpactOscillator, ContinuedOrbitsAreLabelledWithTheirMinimalPeriod) {
  const ImpactOscillator osc;
  const Model model = osc.model();
  StroboscopicMap map(model, osc.amplitude, 1.8 * osc.omega0, exact_options(), 32);
  const ImpactOscillator::Orbit analytic = osc.orbit(1.8 * osc.omega0);
  Eigen::VectorXd start = Eigen::VectorXd::Zero(4);
  start(0) = analytic.at_zero(0);
  start(2) = analytic.at_zero(1);
  const ShootingResult twice = shoot(map, start, 2, ShootingOptions{});
  ASSERT_TRUE(twice.converged) << twice.failure;
  EXPECT_EQ(twice.orbit.periodicity, 2);
  EXPECT_EQ(minimal_period(map, twice.orbit, 1e-7), 1);

  FrequencyFamily family(model, osc.amplitude, exact_options(), 32);
  const ImpactOscillator::Orbit before = osc.orbit(2.4 * osc.omega0);
  start.setZero();
  start(0) = before.at_zero(0);
  start(2) = before.at_zero(1);
  ShootingResult r = shoot(family.at(2.4), start, 1, ShootingOptions{});
  ASSERT_TRUE(r.converged) << r.failure;
  r.orbit.parameter = 2.4;
  ContinuationOptions co;
  co.max_parameter_step = 5e-3;
  co.max_points = 30;
  const ContinuationResult traced = continue_orbits(family, r.orbit, 2.4, 2.5, +1, ShootingOptions{}, co);
  ASSERT_GE(traced.branches.size(), 2u);
  const PeriodicOrbit& doubled = traced.branches[1].points.back();  // the farthest from the doubling
  ASSERT_EQ(doubled.periodicity, 2);
  EXPECT_EQ(minimal_period(family.at(doubled.parameter), doubled, 1e-7), 2) << doubled.parameter;
}

TEST(ImpactOscillator, ContinuationInTheGapFollowsTheAnalyticOrbitsToTheirDoubling) {
  // At ω̄ = 2.4ω₀ the period-1 orbit is stable for σ = δω₀²/A = 0.1 (its doubling in ω̄ is at
  // 2.4567ω₀) and doubles its period as the gap widens: where 1 + tr M + det M = 0 in σ, bisected
  // to 1e-12. Continued in σ from 0.1 down to 0.02 and up to 0.16, each period-1 point's
  // multipliers are the analytic ones, and the doubling is found where the closed form puts it.
  const double w = 2.4 * ImpactOscillator{}.omega0;
  const auto oscillator = [](double sigma) {
    ImpactOscillator osc;
    osc.gap = sigma * osc.amplitude / (osc.omega0 * osc.omega0);
    return osc;
  };
  double lo = 0.1, hi = 0.16;
  ASSERT_LT(oscillator(lo).doubling_test(w) * oscillator(hi).doubling_test(w), 0);
  for (int i = 0; i < 100; ++i) {
    const double mid = 0.5 * (lo + hi);
    (oscillator(lo).doubling_test(w) * oscillator(mid).doubling_test(w) <= 0 ? hi : lo) = mid;
  }
  const double analytic = 0.5 * (lo + hi);

  FrequencyResponseOptions o;
  o.amplitude = ImpactOscillator{}.amplitude;
  o.ratios = {2.4};
  o.steady.steps_per_period = 32;
  o.time_history = exact_options();
  o.continuation.max_parameter_step = 2e-3;
  o.continuation.max_periodicity = 2;
  const auto model_at = [&](double sigma) { return oscillator(sigma).model(); };
  const std::vector<ParameterPoint> points = parameter_response_by_continuation(model_at, 0.02, 0.16, 0.1, o);
  int checked = 0;
  std::vector<double> doublings;
  double lowest = 1, highest = 0;
  for (const ParameterPoint& p : points) {
    EXPECT_EQ(p.response.ratio, 2.4);
    if (p.response.periodicity != 1) continue;
    lowest = std::min(lowest, p.parameter);
    highest = std::max(highest, p.parameter);
    if (p.response.bifurcation == BifurcationKind::period_doubling) doublings.push_back(p.parameter);
    const ImpactOscillator::Orbit orbit = oscillator(p.parameter).orbit(w);
    ASSERT_TRUE(orbit.exists) << p.parameter;
    const Eigen::Vector2cd expected = Eigen::EigenSolver<Eigen::Matrix2d>(orbit.monodromy).eigenvalues();
    for (const std::complex<double>& mu : expected) {
      const double nearest = std::min(std::abs(p.response.multipliers[0] - mu), std::abs(p.response.multipliers[1] - mu));
      EXPECT_LT(nearest, 1e-4) << "sigma = " << p.parameter << ": " << mu;
    }
    if (p.response.bifurcation == BifurcationKind::none) {  // at a bifurcation a multiplier is on the circle
      EXPECT_EQ(p.response.stable, std::abs(expected(0)) < 1 && std::abs(expected(1)) < 1) << p.parameter;
    }
    ++checked;
  }
  EXPECT_GT(checked, 50);
  // Both directions reach the ends of the range (each branch ends on it).
  EXPECT_EQ(lowest, 0.02);
  EXPECT_EQ(highest, 0.16);
  ASSERT_EQ(doublings.size(), 1u);
  EXPECT_NEAR(doublings[0], analytic, 1e-6);
  // Beyond the doubling a period-2 branch is followed.
  EXPECT_TRUE(std::any_of(points.begin(), points.end(), [](const ParameterPoint& p) {
    return p.response.periodicity == 2 && p.response.parent_branch >= 0;
  }));
}

TEST(ImpactOscillator, ContinuationRestartsAcrossTheGrazingWhereTheImpactsEnd) {
  // At ω̄ = 2.4ω₀ the impacting period-1 orbit's impact speed falls to zero as the gap opens to
  // the free amplitude |U| = A/|ω₀² − ω̄² + 2iζω₀ω̄|: a grazing, where the map's derivative is
  // singular and the corrector stalls (continued in the gap in metres, as an input key gives it). The
  // branch is restarted beyond it and goes on as the linear orbit, which never touches the stop.
  const ImpactOscillator base;
  const double w = 2.4 * base.omega0;
  const double sigma_grazing = std::abs(base.response(w)) * base.omega0 * base.omega0 / base.amplitude;
  ASSERT_GT(sigma_grazing, 0.2);
  ASSERT_LT(sigma_grazing, 0.22);
  const double metres = base.amplitude / (base.omega0 * base.omega0);  // per unit of σ
  const auto model_at = [&](double gap) {
    ImpactOscillator osc;
    osc.gap = gap;
    return osc.model();
  };
  ParameterFamily family(model_at, base.amplitude, 2.4, exact_options(), 32);
  const double start = 0.16 * metres, end = 0.3 * metres;
  ImpactOscillator at_start;
  at_start.gap = start;
  const ImpactOscillator::Orbit analytic = at_start.orbit(w);
  ASSERT_TRUE(analytic.exists);
  Eigen::VectorXd x = Eigen::VectorXd::Zero(4);
  x << analytic.at_zero(0), 0, analytic.at_zero(1), 0;
  ShootingResult r = shoot(family.at(start), x, 1, ShootingOptions{});
  ASSERT_TRUE(r.converged) << r.failure;
  r.orbit.parameter = start;
  ContinuationOptions co;
  co.max_parameter_step = 2e-3 * metres;
  co.max_periodicity = 1;
  const ContinuationResult traced = continue_orbits(family, r.orbit, start, end, +1, ShootingOptions{}, co);
  ASSERT_EQ(traced.branches.size(), 1u);
  const Branch& branch = traced.branches.front();
  EXPECT_GE(traced.restarts, 1);
  EXPECT_EQ(branch.ended, "left the parameter range");
  int beyond = 0;
  for (const PeriodicOrbit& orbit : branch.points) {
    if (orbit.parameter > end) continue;
    const double sigma = orbit.parameter / metres;
    if (sigma < sigma_grazing - 1e-3) {
      EXPECT_EQ(orbit.impacts, 1) << orbit.parameter;
    } else if (sigma > sigma_grazing + 1e-9) {
      // The linear steady state, and stable (the free frame's damping).
      ++beyond;
      EXPECT_EQ(orbit.events, 0) << orbit.parameter;
      const Eigen::VectorXd linear = linear_steady_state(model_at(orbit.parameter), base.amplitude, w);
      EXPECT_LT((state_of(orbit) - linear).cwiseAbs().maxCoeff(), 1e-9 * linear.cwiseAbs().maxCoeff()) << orbit.parameter;
      EXPECT_TRUE(orbit.stable);
    }
  }
  EXPECT_GT(beyond, 20);
  EXPECT_EQ(branch.points.back().parameter > end ? branch.points[branch.points.size() - 2].parameter
                                                 : branch.points.back().parameter,
            end);
}

TEST(PeriodicOrbits, LinearFramesShootToTheirClosedFormInOneStep) {
  // A joint too wide to close: the frames are linear, P is affine, and Newton lands on the closed
  // form in one step; the multipliers are e^{λT} of the frames' modes.
  DimensionlessParameters p = testing::fig2('c');
  p.delta = 100;
  const Model model = make_model(p, {1, 1});
  const double w = 0.9 * reference_frequency(model);
  StroboscopicMap map(model, 0.2 * kG, w, exact_options(), 32);
  const ShootingResult r = shoot(map, Eigen::VectorXd::Zero(4), 1, ShootingOptions{});
  ASSERT_TRUE(r.converged) << r.failure;
  EXPECT_EQ(r.orbit.iterations, 1);
  EXPECT_EQ(r.orbit.events, 0);
  const Eigen::VectorXd closed = linear_steady_state(model, 0.2 * kG, w);
  EXPECT_LT((state_of(r.orbit) - closed).cwiseAbs().maxCoeff(), 1e-12 * closed.cwiseAbs().maxCoeff());
  const double period = 2 * std::numbers::pi / w;
  for (const Frame& f : model.frames) {
    // |e^{λT}| = e^{−ξωT} for each frame's (proportionally damped) mode: ξω = c/(2m).
    const double decay = std::exp(-f.damping[0] / (2 * f.mass[0]) * period);
    const double nearest = std::min({std::abs(std::abs(r.orbit.multipliers(0)) - decay), std::abs(std::abs(r.orbit.multipliers(2)) - decay)});
    EXPECT_LT(nearest, 1e-12);
  }
  EXPECT_TRUE(r.orbit.stable);
}

/// A frequency response by continuation of Fig. 2's frames at 0.2 g, ω̄/ω₁ = 0.6, 0.65, …, 1.1.
FrequencyResponseOptions continued_response_options(int samples_per_period) {
  FrequencyResponseOptions o;
  o.amplitude = 0.2 * kG;
  o.method = FrfMethod::continuation;
  o.steady.steps_per_period = samples_per_period;
  for (int i = 0; i <= 10; ++i) o.ratios.push_back(0.6 + 0.05 * i);
  o.time_history = exact_options();
  return o;
}

TEST(PeriodicOrbits, StableContinuedOrbitsAreWhereLongSimulationsSettle) {
  // Fig. 2c's and 2b's frames: each stable continued orbit, perturbed by 1 % and simulated exactly
  // for as many periods as its largest multiplier needs to shrink the perturbation below 1e-12,
  // settles on the same peaks to 1e-8.
  for (const char panel : {'b', 'c'}) {
    const Model model = make_model(testing::fig2(panel), {1, 1});
    const FrequencyResponseOptions o = continued_response_options(64);
    const std::vector<FrfPoint> points = frequency_response(model, o);
    int checked = 0;
    for (std::size_t i = 0; i < points.size(); i += 7) {
      const FrfPoint& p = points[i];
      if (!p.continued || !p.stable || std::abs(p.multipliers.front()) > 0.9) continue;
      StroboscopicMap map(model, o.amplitude, p.omega, o.time_history, 64);
      // The continued orbit's state is not in FrfPoint: recover it by shooting from a settled run.
      Eigen::VectorXd x = settled_state(map, Eigen::VectorXd::Zero(4), 20);
      const ShootingResult shot = shoot(map, x, p.periodicity, ShootingOptions{});
      ASSERT_TRUE(shot.converged);
      if (std::abs(shot.orbit.amplitudes.base_shear[0] - p.interacting.base_shear[0]) > 1e-6 * p.interacting.base_shear[0]) {
        continue;  // a coexisting orbit: the settled run found another one
      }
      const int periods = static_cast<int>(std::ceil(std::log(1e-12 / 1e-2) / std::log(std::abs(p.multipliers.front())))) + 1;
      Eigen::VectorXd start = state_of(shot.orbit) * 1.01;
      start = settled_state(map, start, (periods / p.periodicity + 1) * p.periodicity);
      map.evaluate(start, p.periodicity, nullptr, StroboscopicMap::Responses::record);
      const FrameAmplitudes simulated = run_amplitudes(map.simulator());
      for (std::size_t f = 0; f < 2; ++f) {
        EXPECT_NEAR(simulated.base_shear[f], p.interacting.base_shear[f], 1e-8 * p.interacting.base_shear[f])
            << panel << " at " << p.ratio << " frame " << f + 1;
        EXPECT_NEAR(simulated.top_displacement[f], p.interacting.top_displacement[f], 1e-8 * p.interacting.top_displacement[f])
            << panel << " at " << p.ratio << " frame " << f + 1;
      }
      ++checked;
    }
    EXPECT_GE(checked, 3) << panel;
  }
}

/// A ratio where the response from rest is periodic, and the stable continued orbit found there.
struct CoveredRatio {
  double ratio = 0.0;
  int periodicity = 0;
  bool found = false;
  int branch = -1, parent = -1;  ///< the continued orbit's branch and the branch it doubled from
};

bool same_peaks(const FrameAmplitudes& a, const FrameAmplitudes& b, double tolerance) {
  for (std::size_t f = 0; f < b.base_shear.size(); ++f) {
    if (std::abs(a.base_shear[f] - b.base_shear[f]) > tolerance * b.base_shear[f]) return false;
    if (std::abs(a.top_displacement[f] - b.top_displacement[f]) > tolerance * b.top_displacement[f]) return false;
  }
  return true;
}

/// A paper figure's frequency response simulated from rest and by continuation (the exact
/// integrator, 16 samples a period, the file's 71 ratios): for each ratio where the response from
/// rest is not periodic, a simulated point of the continuation with its peaks; where it is
/// periodic with minimal period k, a stable continued orbit there of minimal period k whose
/// peaks — base shear and top displacement of each frame — agree with it to 1e-3. A continued point
/// at that ratio, or the orbit at that ratio between two consecutive points of a branch, shot from
/// their interpolated section states as the branch's period. An orbit of minimal period j, a
/// multiple of k, counts when it repeats after k periods to ten times the simulation's tolerance
/// on its sections (the simulation labels such an orbit k: near a period doubling, the doubled
/// orbit is that close to the orbit it doubled from).
std::vector<CoveredRatio> periodic_responses_continued(const std::string& figure,
                                                       const std::vector<std::string>& more = {}) {
  const std::string file = std::string(POUNDSIM_SOURCE_DIR) + "/examples/paper/" + figure + ".toml";
  const auto options = [&](const char* method) {
    std::vector<std::string> settings{"analysis.integrator=exact", "frf.steps_per_period=16",
                                      std::string("frf.method=") + method};
    for (const std::string& setting : more) {
      // [frf.continuation] is refused with the simulation method
      if (setting.starts_with("frf.continuation.") && std::string_view(method) != "continuation") continue;
      settings.push_back(setting);
    }
    return io::read_input(file, settings);
  };
  const io::RunInput simulated = options("simulation"), continued = options("continuation");
  const Model& model = simulated.model;
  const FrequencyResponseOptions so = io::frequency_response_options(simulated);
  const FrequencyResponseOptions co = io::frequency_response_options(continued);
  const std::vector<FrfPoint> from_rest = frequency_response(model, so);
  const std::vector<FrfPoint> orbits = frequency_response(model, co);
  TimeHistoryOptions th = co.time_history;
  th.integrator = Integrator::exact;
  std::vector<CoveredRatio> out;
  for (const FrfPoint& b : from_rest) {
    const int k = b.periodicity;
    CoveredRatio covered{b.ratio, k};
    if (k == 0) {
      // Not periodic: the continuation reports the simulated response itself, the same bits.
      covered.found = std::any_of(orbits.begin(), orbits.end(), [&](const FrfPoint& c) {
        return !c.continued && c.ratio == b.ratio && same_peaks(c.interacting, b.interacting, 0.0);
      });
      out.push_back(covered);
      continue;
    }
    StroboscopicMap map(model, co.amplitude, b.omega, th, co.steady.steps_per_period);
    const Eigen::Index n = map.dofs();
    const auto section = [&](const FrfPoint& p) {
      Eigen::VectorXd x(2 * n);
      for (Eigen::Index i = 0; i < n; ++i) {
        x(i) = p.section_u[static_cast<std::size_t>(i)];
        x(n + i) = p.section_v[static_cast<std::size_t>(i)];
      }
      return x;
    };
    // The orbit through x, of minimal period j (a multiple of k), is the response from rest.
    const auto matches = [&](const Eigen::VectorXd& x, int j, const FrameAmplitudes& peaks, bool stable) {
      if (!stable || !same_peaks(peaks, b.interacting, 1e-3)) return false;
      if (j == k) return true;
      Eigen::VectorXd y0 = x, y1 = map.evaluate(x, k);
      y0.tail(n) /= b.omega;
      y1.tail(n) /= b.omega;
      return (y1 - y0).cwiseAbs().maxCoeff() <= 10 * so.steady.tolerance * y0.cwiseAbs().maxCoeff();
    };
    for (std::size_t i = 0; i < orbits.size() && !covered.found; ++i) {
      const FrfPoint& c = orbits[i];
      if (!c.continued) continue;
      if (c.ratio == b.ratio) {
        covered.found = c.periodicity % k == 0 && matches(section(c), c.periodicity, c.interacting, c.stable);
      } else if (i + 1 < orbits.size() && orbits[i + 1].continued && orbits[i + 1].branch_id == c.branch_id &&
                 (c.ratio - b.ratio) * (orbits[i + 1].ratio - b.ratio) < 0) {
        const FrfPoint& d = orbits[i + 1];
        // The branch's period (a point at its doubling is labelled with the period it doubled).
        const int j = std::max(c.periodicity, d.periodicity);
        if (j % std::min(c.periodicity, d.periodicity) != 0 || j % k != 0) continue;
        const double t = (b.ratio - c.ratio) / (d.ratio - c.ratio);
        const ShootingResult shot = shoot(map, section(c) + t * (section(d) - section(c)), j, co.shooting);
        covered.found = shot.converged && matches(state_of(shot.orbit), j, shot.orbit.amplitudes, shot.orbit.stable);
      }
      if (covered.found) {
        covered.branch = c.branch_id;
        covered.parent = c.parent_branch;
      }
    }
    out.push_back(covered);
  }
  return out;
}

TEST(PeriodicOrbits, ThePeriodicResponsesFromRestAreStableContinuedOrbits) {
  // The seven paper figures: every ratio where the response from rest is periodic has a stable
  // continued orbit of that minimal period with the same peaks — coexisting responses born at a
  // fold or a grazing included (seeds_from_rest = every, the default) — and every ratio where it
  // is not has that simulated response. Where the response from rest is the period-2 orbit born
  // at a period doubling of a continued branch, the orbit is on the branch switched to there.
  struct Case {
    const char* figure;
    int periodic;                ///< ratios where the response from rest is periodic
    std::vector<double> doubled; ///< ratios whose response lies on a branch born at a doubling
  };
  const std::vector<Case> cases{
      {"fig2a", 65, {0.58, 0.60, 0.80}}, {"fig2b", 69, {0.78}}, {"fig2c", 71, {}},    {"fig3a", 65, {}},
      {"fig3b", 71, {}},                 {"fig4a", 58, {1.3043}}, {"fig4b", 70, {}},
  };
  for (const Case& c : cases) {
    const std::vector<CoveredRatio> ratios = periodic_responses_continued(c.figure);
    ASSERT_EQ(ratios.size(), 71u) << c.figure;
    EXPECT_EQ(std::count_if(ratios.begin(), ratios.end(), [](const CoveredRatio& r) { return r.periodicity > 0; }),
              c.periodic)
        << c.figure;
    for (const CoveredRatio& r : ratios) {
      EXPECT_TRUE(r.found) << c.figure << " at " << r.ratio << ": period " << r.periodicity;
      const bool doubled = std::any_of(c.doubled.begin(), c.doubled.end(),
                                       [&](double d) { return std::abs(d - r.ratio) < 5e-5; });
      if (doubled) {
        EXPECT_EQ(r.periodicity, 2) << c.figure << " at " << r.ratio;
        EXPECT_GE(r.parent, 0) << c.figure << " at " << r.ratio << ": on branch " << r.branch;
      }
    }
  }
}

TEST(PeriodicOrbits, SeedsFromRestAtEveryRatioFindTheCoexistingOrbitsNoBranchReaches) {
  // Fig. 2b at 1.22 … 1.40: the responses from rest at 1.26 … 1.38 are a stable period-2 branch
  // (1.166–1.400) born at a grazing of a low-amplitude period-1 branch, beside the stable
  // period-1 branch the continuation follows there. Seeded only where every continued orbit is
  // unstable, none of them is reported; seeded at every ratio, all are, on one branch.
  // Ratios 1.22, 1.24, …, 1.40.
  const std::vector<std::string> range{"frf.ratio_min=1.22", "frf.ratio_max=1.40", "frf.points=10"};
  const auto found = [](const std::vector<CoveredRatio>& ratios, bool inside) {
    return std::count_if(ratios.begin(), ratios.end(), [&](const CoveredRatio& r) {
      return r.found && (r.ratio > 1.25 && r.ratio < 1.39) == inside;
    });
  };
  std::vector<std::string> unstable = range;
  unstable.emplace_back("frf.continuation.seeds_from_rest=unstable");
  const std::vector<CoveredRatio> some = periodic_responses_continued("fig2b", unstable);
  const std::vector<CoveredRatio> every = periodic_responses_continued("fig2b", range);
  ASSERT_EQ(every.size(), 10u);
  // From rest: period 1 at 1.22 and 1.40, not periodic at 1.24 (reported as simulated only when
  // seeded at every ratio), period 2 between.
  for (const CoveredRatio& r : every) {
    EXPECT_EQ(r.periodicity, r.ratio > 1.25 && r.ratio < 1.39 ? 2 : (r.ratio < 1.23 || r.ratio > 1.39 ? 1 : 0)) << r.ratio;
  }
  EXPECT_EQ(found(some, true), 0);
  EXPECT_EQ(found(every, true), 7);
  EXPECT_EQ(found(some, false), 2);
  EXPECT_EQ(found(every, false), 3);
  std::set<int> branches;
  for (const CoveredRatio& r : every) {
    if (r.periodicity == 2) branches.insert(r.branch);
  }
  EXPECT_EQ(branches.size(), 1u);
}

TEST(PeriodicOrbits, AFrequencyResponseInPiecesIsTheSameOnAnyThreadsAndCoversTheRange) {
  // Fig. 2c's frames at 0.6 … 1.1 in pieces of four ratios: the points on one thread and on two
  // are the same bit for bit, each piece's branch ids follow the last piece's, and every ratio
  // lies on a continued branch (Fig. 2c has one stable period-1 orbit there: nothing simulated).
  const Model model = make_model(testing::fig2('c'), {1, 1});
  FrequencyResponseOptions o = continued_response_options(32);
  o.continuation.ratios_per_segment = 4;
  o.threads = 1;
  const std::vector<FrfPoint> one = frequency_response(model, o);
  o.threads = 2;
  const std::vector<FrfPoint> two = frequency_response(model, o);
  ASSERT_EQ(one.size(), two.size());
  for (std::size_t i = 0; i < one.size(); ++i) {
    EXPECT_EQ(one[i].ratio, two[i].ratio) << i;
    EXPECT_EQ(one[i].branch_id, two[i].branch_id) << i;
    EXPECT_EQ(one[i].interacting.base_shear, two[i].interacting.base_shear) << i;
    EXPECT_EQ(one[i].interacting.top_displacement, two[i].interacting.top_displacement) << i;
  }
  // Three pieces: [0.6, 0.8], [0.8, 1.0], [1.0, 1.1]; a branch of each, in order, ids 0, 1, 2.
  int last_branch = -1;
  double lowest = 10, highest = 0;
  for (const FrfPoint& p : one) {
    ASSERT_TRUE(p.continued) << p.ratio;
    EXPECT_GE(p.branch_id, last_branch);
    last_branch = p.branch_id;
    lowest = std::min(lowest, p.ratio);
    highest = std::max(highest, p.ratio);
  }
  EXPECT_EQ(last_branch, 2);
  EXPECT_NEAR(lowest, 0.6, 1e-12);
  EXPECT_NEAR(highest, 1.1, 1e-12);
  // Where two pieces meet, both continue the same orbit: its peaks agree to Newton's tolerance.
  for (const double seam : {0.8, 1.0}) {
    std::vector<double> shears;
    for (const FrfPoint& p : one) {
      if (std::abs(p.ratio - seam) < 1e-12) shears.push_back(p.interacting.base_shear[0]);
    }
    ASSERT_EQ(shears.size(), 2u) << seam;
    EXPECT_NEAR(shears[0], shears[1], 1e-8 * shears[0]) << seam;
  }
}

}  // namespace
}  // namespace poundsim
