// Newmark on linear phases (no contact): closed-form free vibration and steady state.

#include "poundsim/integrate/newmark.hpp"

#include <bit>
#include <cmath>
#include <complex>
#include <cstdint>
#include <limits>
#include <numbers>
#include <random>

#include <Eigen/Dense>
#include <gtest/gtest.h>

#include "poundsim/dynamics/linear_phase.hpp"
#include "poundsim/integrate/simulator.hpp"
#include "test_models.hpp"

namespace poundsim {
namespace {

constexpr double kFar = 1e6;  // a gap no motion closes

TEST(NewmarkFreeVibration, PeriodAndDecayMatchTheDampedOscillator) {
  // u'' + 2ζω u' + ω² u = 0, u(0) = u0, u'(0) = 0.
  const double m = 1.0, k = 400.0, zeta = 0.02, u0 = 0.01;
  const double w = std::sqrt(k / m), wd = w * std::sqrt(1 - zeta * zeta);
  const double c = 2 * zeta * m * w;
  const Model model = make_model({make_uniform_frame(1, m, k, c)}, GapProperties{});
  InitialConditions ic;
  ic.displacement = {{u0}};
  const double dt = 1e-4;
  Simulator sim(model, NoExcitation{}, TimeHistoryOptions{.dt = dt}, ic);

  const auto exact = [&](double t) {
    return std::exp(-zeta * w * t) * (u0 * std::cos(wd * t) + zeta * w * u0 / wd * std::sin(wd * t));
  };
  // Upward zero crossings give the damped period.
  std::vector<double> crossings;
  double previous = sim.state().u(0), max_error = 0;
  for (int n = 1; n <= 30000; ++n) {
    sim.step();
    const double u = sim.state().u(0);
    max_error = std::max(max_error, std::abs(u - exact(sim.time())));
    if (previous < 0 && u >= 0) {
      crossings.push_back(sim.time() - dt * u / (u - previous));
    }
    previous = u;
  }
  ASSERT_GE(crossings.size(), 8u);
  const double period = (crossings.back() - crossings.front()) / double(crossings.size() - 1);
  const double td = 2 * std::numbers::pi / wd;
  // Newmark's period elongation is (ωh)²/12 = 3.3e-7 here.
  EXPECT_NEAR(period, td, 1e-6 * td);
  EXPECT_LT(max_error, 2e-5 * u0);

  // Decay over whole periods: u(t + n T_d) = exp(−ζ ω n T_d) u(t), exactly for the oscillator and
  // without numerical damping for the average-acceleration method. Taken at peaks (ω_d t = kπ),
  // where the small period error does not change u to first order.
  Simulator decay(model, NoExcitation{}, TimeHistoryOptions{.dt = dt}, ic);
  decay.advance_to(td);
  const double first = decay.state().u(0);
  decay.advance_to(6 * td);
  const double ratio = decay.state().u(0) / first;
  EXPECT_NEAR(std::log(ratio), -zeta * w * 5 * td, 1e-5 * zeta * w * 5 * td);
}

TEST(NewmarkSteadyState, MatchesTheClosedFormFrequencyResponse) {
  // A 3-storey frame and a 2-storey neighbour far away under a_g = A sin(ω̄t): after the
  // transient, u(t) = Im(U e^{iω̄t}) with (K − ω̄²M + iω̄C) U = −M 1 A.
  const Frame f1 = make_uniform_frame(3, 1.0, 400.0, 1.0);
  const Frame f2 = make_uniform_frame(2, 2.0, 300.0, 2.0);
  const Model model = make_model({f1, f2}, GapProperties{.gap = kFar});
  const double A = 0.2 * 9.81, omega = 0.9 * fundamental_frequency(f1);
  Simulator sim(model, HarmonicExcitation{A, omega}, TimeHistoryOptions{.dt = 2e-4});

  using Complex = std::complex<double>;
  const auto amplitude = [&](const Frame& f) {
    const Eigen::MatrixXd k = stiffness_matrix(f), c = damping_matrix(f);
    const Eigen::VectorXd mass = Eigen::Map<const Eigen::VectorXd>(f.mass.data(), f.storeys());
    Eigen::MatrixXcd dyn = k.cast<Complex>() - omega * omega * Eigen::MatrixXcd(mass.asDiagonal()) +
                           Complex(0, omega) * c.cast<Complex>();
    return Eigen::VectorXcd(dyn.partialPivLu().solve((-A * mass).cast<Complex>()));
  };
  const Eigen::VectorXcd u1 = amplitude(f1), u2 = amplitude(f2);

  const double period = 2 * std::numbers::pi / omega;
  sim.advance_to(200 * period);  // transient decays as exp(−ζω₁t) with ζω₁ ≈ 0.25 s⁻¹
  double max_error = 0, scale = u1.cwiseAbs().maxCoeff();
  for (int k = 0; k < 200; ++k) {
    sim.advance_to((200 + k / 200.0) * period);
    const Complex phase = std::exp(Complex(0, omega * sim.time()));
    for (int i = 0; i < 3; ++i) {
      max_error = std::max(max_error, std::abs(sim.state().u(sim.layout().dof(0, i)) - (u1(i) * phase).imag()));
    }
    for (int i = 0; i < 2; ++i) {
      max_error = std::max(max_error, std::abs(sim.state().u(sim.layout().dof(1, i)) - (u2(i) * phase).imag()));
    }
  }
  // Newmark's phase error after 200 periods, (ω̄h)²/12 · ω̄t ≈ 1e-5 rad, bounds the difference.
  EXPECT_LT(max_error, 3e-5 * scale);
  EXPECT_EQ(sim.statistics().events, 0);
}

TEST(NewmarkConvergence, LinearResponseIsSecondOrderInTheStep) {
  const Model model = make_model({make_uniform_frame(2, 1.0, 300.0, 0.5)}, GapProperties{});
  const auto run = [&](double dt) {
    Simulator sim(model, HarmonicExcitation{2.0, 9.0}, TimeHistoryOptions{.dt = dt});
    sim.advance_to(2.0);
    return Eigen::VectorXd(sim.state().u);
  };
  const Eigen::VectorXd reference = run(1e-5);
  const double e1 = (run(4e-3) - reference).norm(), e2 = (run(2e-3) - reference).norm();
  EXPECT_NEAR(std::log2(e1 / e2), 2.0, 0.1);
}

/// The same double to the bit (== takes −0 for +0).
::testing::AssertionResult same_bits(double a, double b) {
  if (std::bit_cast<std::uint64_t>(a) == std::bit_cast<std::uint64_t>(b)) return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure() << std::hexfloat << a << " against " << b;
}

/// Checks NewmarkIntegrator::step on `phase` against the general step's expressions written with
/// Eigen (sparse products, SimplicialLDLT's solve), DOF by DOF to the bit, at the phase's step
/// (the banded path when the phase has bands) and at a sub-step (the sparse loops). With locked
/// links the expressions are the reduced system's, from q = the groups' representative floors,
/// and u = T q + o as NewmarkIntegrator::finish writes it. `seed` 0 is a smooth state with nonzero
/// u, u̇ and ü everywhere; others draw each entry at random over six decades of both signs, a
/// tenth of them exactly 0 (Eigen's forward solve skips the zero columns) — many
/// rounding-sensitive sums, where an order of terms changed shows.
void expect_step_is_eigens(const LinearPhase& phase, double dt, double ground, unsigned seed,
                           NewmarkIntegrator* integrator = nullptr) {
  const Eigen::Index n = phase.full_mass().size(), nr = phase.reduced_size();
  KinematicState from;
  from.resize(static_cast<int>(n));
  std::mt19937_64 random(seed);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  const auto draw = [&](double scale) {
    if (unit(random) < 0.1) return 0.0;
    return (unit(random) < 0.5 ? -scale : scale) * std::pow(10.0, -6.0 * unit(random));
  };
  for (Eigen::Index i = 0; i < n; ++i) {
    const auto x = static_cast<double>(i + 1);
    from.u(i) = seed == 0 ? 1e-3 * std::sin(1.3 * x) : draw(1e-2);
    from.v(i) = seed == 0 ? 2e-2 * std::cos(0.7 * x) : draw(1e-1);
    from.a(i) = seed == 0 ? -0.4 * std::sin(2.1 * x + 0.3) : draw(10.0);
  }
  from.t = 0.37;
  Eigen::VectorXd q(nr), qd(nr), qdd(nr);
  phase.gather(from.u, q);
  phase.gather(from.v, qd);
  phase.gather(from.a, qdd);
  // Floor i's group (T = I without locked links).
  const auto group = [&](Eigen::Index i) {
    return phase.is_unreduced() ? i : static_cast<Eigen::Index>(phase.group_of()[static_cast<std::size_t>(i)]);
  };
  for (const double tau : {dt, 0.37 * dt}) {
    const LinearPhase::Solver& solver = tau == dt ? phase.step_solver() : phase.substep_solver(tau);
    KinematicState to;
    to.resize(static_cast<int>(n));
    if (integrator != nullptr) {
      integrator->step(phase, solver, from, tau, ground, to);
    } else {
      NewmarkIntegrator(n).step(phase, solver, from, tau, ground, to);
    }

    const double half = 0.5 * tau, quarter_sq = 0.25 * tau * tau;
    const Eigen::VectorXd w1 = qd + half * qdd;
    const Eigen::VectorXd w2 = q + tau * qd + quarter_sq * qdd;
    Eigen::VectorXd rhs = phase.constant_load() - ground * phase.mass();
    rhs.noalias() -= phase.damping() * w1;
    rhs.noalias() -= phase.stiffness() * w2;
    const Eigen::VectorXd a_new = solver.solve(rhs);
    EXPECT_EQ(to.t, from.t + tau);
    EXPECT_EQ(to.ground, ground);
    for (Eigen::Index i = 0; i < n; ++i) {
      const Eigen::Index r = group(i);
      // Without locked links there is no offset to add (+0 would turn a −0 into +0).
      const double u_new = phase.is_unreduced() ? w2(r) + quarter_sq * a_new(r)
                                                : w2(r) + quarter_sq * a_new(r) + phase.offset()(i);
      const double v_new = qd(r) + half * (qdd(r) + a_new(r));
      EXPECT_TRUE(same_bits(to.a(i), a_new(r))) << "seed " << seed << ", tau " << tau << ", DOF " << i;
      EXPECT_TRUE(same_bits(to.u(i), u_new)) << "seed " << seed << ", tau " << tau << ", DOF " << i;
      EXPECT_TRUE(same_bits(to.v(i), v_new)) << "seed " << seed << ", tau " << tau << ", DOF " << i;
    }
    // And it is the step: the equation of motion holds at the end, to round-off.
    Eigen::VectorXd q_end(nr), qd_end(nr), qdd_end(nr);
    phase.gather(to.u, q_end);
    phase.gather(to.v, qd_end);
    phase.gather(to.a, qdd_end);
    Eigen::VectorXd residual = phase.constant_load() - ground * phase.mass() - phase.mass().cwiseProduct(qdd_end);
    residual.noalias() -= phase.damping() * qd_end;
    residual.noalias() -= phase.stiffness() * q_end;
    EXPECT_LT(residual.cwiseQuotient(phase.mass()).cwiseAbs().maxCoeff(), 1e-12 * from.a.cwiseAbs().maxCoeff() + 1e-9)
        << "seed " << seed;
  }
}

/// F 5-storey frames, every gap element in `mode`.
struct LeanStepCase {
  std::vector<Frame> frames;
  GapMode mode;
  int width;  ///< the phase's band half-width, −1 for none (the sparse loops)
};

TEST(NewmarkLeanStep, IsEigensExpressionsAndSolveBitForBit) {
  // The step of a phase without locked links runs in plain loops (NewmarkIntegrator::step_unreduced
  // over the sparse arrays; step_banded row by row over dense bands at the phase's own step): it
  // must perform Eigen's operations in Eigen's order. The DOFs interleave floor by floor, so F
  // frames have a half-bandwidth F (a storey joins DOFs F apart). Frames in contact couple K and C
  // across frames and give L entries below its diagonal; frames apart leave stored zeros inside
  // the band (two one-storey frames apart: width 0, the diagonal alone); five frames interleave
  // wider than the bands go.
  const Frame a = make_uniform_frame(5, 2e5, 3e8, 4e5, "a"), b = make_uniform_frame(5, 1.5e5, 1.2e8, 1e5, "b"),
              c = make_uniform_frame(5, 1.8e5, 2e8, 2e5, "c"), a1 = make_uniform_frame(1, 2e5, 3e8, 4e5, "a1"),
              b1 = make_uniform_frame(1, 1.5e5, 1.2e8, 1e5, "b1");
  const GapProperties gap{.stiffness = 7e7, .damping = 3e5, .gap = 0.0, .shortening = 0.05, .restitution = 0.75};
  const std::vector<LeanStepCase> cases{
      {{a1, b1}, GapMode::open, 0},     {{a1, b1}, GapMode::contact, 1},     {{a}, GapMode::open, 1},
      {{a, b}, GapMode::contact, 2},    {{a, b}, GapMode::open, 2},          {{a, b, c}, GapMode::contact, 3},
      {{a, b, c, a}, GapMode::contact, 4}, {{a, b, c, a, b}, GapMode::contact, -1},
  };
  const double dt = 2e-3, ground = -1.7;
  for (const LeanStepCase& test : cases) {
    SCOPED_TRACE(::testing::Message() << test.frames.size() << " frames, width " << test.width);
    const Model model = make_model(test.frames, gap);
    const DofLayout layout(model);
    const ContactConfiguration contact(static_cast<std::size_t>(model.gap_count()), static_cast<LinkMode>(test.mode));
    const LinearPhase phase(model, layout, contact, dt);
    ASSERT_TRUE(phase.is_unreduced());
    const LinearPhase::Bands* bands = phase.bands_for(phase.step_solver());
    ASSERT_EQ(bands == nullptr ? -1 : bands->width, test.width);
    if (test.mode == GapMode::contact) {
      ASSERT_GT(phase.step_solver().unit_lower_factor().nonZeros(), 0);
    }
    // The conditions of the sparse loops (else the general step would be compared with itself).
    ASSERT_EQ(phase.step_solver().info(), Eigen::Success);
    ASSERT_EQ(phase.step_solver().permutationP().size(), 0);
    EXPECT_EQ(phase.bands_for(phase.substep_solver(0.5 * dt)), nullptr);
    for (unsigned seed = 0; seed <= 20; ++seed) expect_step_is_eigens(phase, dt, seed == 1 ? 0.0 : ground, seed);
  }
}

TEST(NewmarkLeanStep, LockedLinksStepInTheGroupsBandsBitForBit) {
  // A locked link merges its two floors into a group; the groups are contiguous, so the reduced
  // matrices keep a band and the step runs step_banded's rows over the groups, then u = T q + o.
  // It must be the general step's Eigen expressions on the reduced system, bit for bit. The
  // modes repeat over the elements (floor by floor between each pair of neighbouring frames);
  // the links' lengths differ, so that every offset o is its own. Five frames locked at every
  // floor have a band (one group a floor) where the same frames in contact have none.
  const Frame a = make_uniform_frame(5, 2e5, 3e8, 4e5, "a"), b = make_uniform_frame(5, 1.5e5, 1.2e8, 1e5, "b"),
              c = make_uniform_frame(5, 1.8e5, 2e8, 2e5, "c"), a1 = make_uniform_frame(1, 2e5, 3e8, 4e5, "a1"),
              b1 = make_uniform_frame(1, 1.5e5, 1.2e8, 1e5, "b1");
  const GapProperties gap{.stiffness = 7e7, .damping = 3e5, .gap = 0.0, .shortening = 0.05, .restitution = 0.75};
  struct LockedCase {
    std::vector<Frame> frames;
    std::vector<GapMode> modes;  ///< repeated over the elements
    int groups;
    int width;
  };
  using enum GapMode;
  const std::vector<LockedCase> cases{
      {{a1, b1}, {locked}, 1, 0},
      {{a, b}, {locked}, 5, 1},
      {{a, b}, {locked, contact, open}, 8, 2},
      {{a, b}, {open, locked}, 8, 2},
      {{a, b, c}, {locked, contact}, 10, 3},
      {{a, b, c, a, b}, {locked}, 5, 1},
  };
  const double dt = 2e-3, ground = -1.7;
  for (const LockedCase& test : cases) {
    SCOPED_TRACE(::testing::Message() << test.frames.size() << " frames, " << test.groups << " groups");
    const Model model = make_model(test.frames, gap);
    const DofLayout layout(model);
    ContactConfiguration contact;
    std::vector<double> lengths;
    for (int e = 0; e < model.gap_count(); ++e) {
      contact.push_back(static_cast<LinkMode>(test.modes[static_cast<std::size_t>(e) % test.modes.size()]));
      lengths.push_back(0.05 + 1e-3 * e);
    }
    LinearPhase phase(model, layout, contact, dt);
    phase.set_link_lengths(lengths);
    ASSERT_FALSE(phase.is_unreduced());
    ASSERT_EQ(phase.reduced_size(), test.groups);
    ASSERT_GT(phase.offset().cwiseAbs().maxCoeff(), 0.0);
    const LinearPhase::Bands* bands = phase.bands_for(phase.step_solver());
    ASSERT_NE(bands, nullptr);
    ASSERT_EQ(bands->width, test.width);
    ASSERT_EQ(phase.step_solver().permutationP().size(), 0);
    EXPECT_EQ(phase.bands_for(phase.substep_solver(0.5 * dt)), nullptr);
    for (unsigned seed = 0; seed <= 20; ++seed) expect_step_is_eigens(phase, dt, seed == 1 ? 0.0 : ground, seed);
    // An integrator that stepped the frames apart first (all their rows) from a state that
    // overflows: the rows past the groups' hold ±∞ and NaN, which a reduced step must not read.
    const Eigen::Index n = layout.size();
    NewmarkIntegrator reused(n);
    const LinearPhase apart(model, layout, ContactConfiguration(contact.size(), PaperGap::link_mode(GapMode::open)),
                            dt);
    if (apart.bands_for(apart.step_solver()) == nullptr) continue;  // five frames apart: too wide for bands
    KinematicState huge, overflowed;
    huge.resize(static_cast<int>(n));
    overflowed.resize(static_cast<int>(n));
    huge.u.setConstant(std::numeric_limits<double>::max());
    huge.v = huge.u;
    huge.a = huge.u;
    reused.step(apart, apart.step_solver(), huge, dt, ground, overflowed);
    ASSERT_FALSE(overflowed.a.allFinite());
    for (unsigned seed = 0; seed <= 3; ++seed) expect_step_is_eigens(phase, dt, ground, seed, &reused);
  }
}

}  // namespace
}  // namespace poundsim
