// The exact integrator against closed-form solutions.

#include "poundsim/integrate/exact_phase.hpp"

#include <cmath>
#include <complex>
#include <cstring>
#include <random>

#include <Eigen/Dense>
#include <gtest/gtest.h>
#include <unsupported/Eigen/MatrixFunctions>

#include "poundsim/error.hpp"
#include "poundsim/integrate/simulator.hpp"
#include "test_models.hpp"

namespace poundsim {
namespace {

constexpr double kFar = 1e6;

TimeHistoryOptions exact_options(double dt) {
  return TimeHistoryOptions{.dt = dt, .integrator = Integrator::exact};
}

TEST(ExactPhase, DampedFreeVibrationToRoundOff) {
  const double m = 2.0, k = 800.0, zeta = 0.03, u0 = 0.01, v0 = -0.2;
  const double w = std::sqrt(k / m), wd = w * std::sqrt(1 - zeta * zeta);
  const Model model = make_model({make_uniform_frame(1, m, k, 2 * zeta * m * w)}, GapProperties{});
  InitialConditions ic;
  ic.displacement = {{u0}};
  ic.velocity = {{v0}};
  Simulator sim(model, NoExcitation{}, exact_options(0.05), ic);
  double worst = 0;
  for (int n = 1; n <= 100; ++n) {
    sim.step();
    const double t = sim.time();
    const double exact = std::exp(-zeta * w * t) *
                         (u0 * std::cos(wd * t) + (v0 + zeta * w * u0) / wd * std::sin(wd * t));
    worst = std::max(worst, std::abs(sim.state().u(0) - exact));
  }
  EXPECT_LT(worst, 1e-14);  // m: |u| ≤ 1e-2, so relative 1e-12
  EXPECT_LT(sim.energy_meter().max_relative_residual(), 1e-13);
}

TEST(ExactPhase, CriticallyDampedModeUsesTheMatrixExponential) {
  // ζ = 1: a double eigenvalue −ω with one eigenvector; u = (u0 + (v0 + ω u0) t) e^{−ωt}.
  const double m = 1.0, k = 100.0, w = 10.0, u0 = 0.02, v0 = 0.5;
  const Model model = make_model({make_uniform_frame(1, m, k, 2 * m * w)}, GapProperties{});
  const DofLayout layout(model);
  const LinearPhase phase(model, layout, {}, 1e-3);
  const ExactPhase exact(phase);
  EXPECT_FALSE(exact.modal());
  // The norms that bound e^{As} on this path are computed for it.
  EXPECT_GE(exact.norm(), w);
  EXPECT_LE(exact.log_norm(), exact.norm());
  EXPECT_EQ(exact.spectral_radius(), exact.norm());
  InitialConditions ic;
  ic.displacement = {{u0}};
  ic.velocity = {{v0}};
  Simulator sim(model, NoExcitation{}, exact_options(0.01), ic);
  double worst = 0;
  for (int n = 1; n <= 50; ++n) {
    sim.step();
    const double t = sim.time();
    worst = std::max(worst, std::abs(sim.state().u(0) - (u0 + (v0 + w * u0) * t) * std::exp(-w * t)));
  }
  EXPECT_LT(worst, 1e-14);
}

// The guard search and the trajectory take e^{λs} from complex_exp and reuse it for the conjugate
// eigenvalue: both must give std::exp's bits, or every exact result (and the golden outputs)
// would move in its last bits.
TEST(ExactPhase, ItsExponentialsAreStdExpBitForBit) {
  std::mt19937_64 generator(7);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  const auto same = [](std::complex<double> a, std::complex<double> b) {
    return std::memcmp(&a, &b, sizeof a) == 0;
  };
  long differing = 0;
  for (int i = 0; i < 200000; ++i) {
    const double x = unit(generator) * std::pow(10.0, 3 * unit(generator));
    const double y = i % 7 == 0 ? 0.0 : unit(generator) * std::pow(10.0, 8 * unit(generator));
    const std::complex<double> z(x, y);
    if (!same(complex_exp(z), std::exp(z))) ++differing;
    if (!same(std::conj(std::exp(z)), std::exp(std::conj(z)))) ++differing;
  }
  EXPECT_EQ(differing, 0);
  EXPECT_TRUE(std::isinf(complex_exp({800.0, 0.5}).real()));  // past 709: std::exp's own overflow

  const Model model = make_model(testing::fig2('c'), {3, 3});
  const DofLayout layout(model);
  const LinearPhase phase(model, layout, ContactConfiguration(model.gap_count(), PaperGap::link_mode(GapMode::open)), 1e-3);
  const ExactPhase exact(phase);
  ASSERT_TRUE(exact.modal());
  Eigen::VectorXcd e;
  for (const double s : {0.0, 1e-9, 0.37, 12.5}) {
    exact.exponentials(s, e);
    ASSERT_EQ(e.size(), exact.eigenvalues().size());
    for (Eigen::Index k = 0; k < e.size(); ++k) EXPECT_TRUE(same(e(k), std::exp(exact.eigenvalues()(k) * s))) << k;
  }
}

// The monitor's extremum searches take the state without its rate (half the work): the same bits
// as the state taken with it, on the modal path and on the matrix exponential's.
TEST(ExactPhase, TheStateAloneIsTheStateWithItsRateBitForBit) {
  const Model modal_model = make_model(testing::fig2('c'), {3, 3});
  const Model critical_model = make_model({make_uniform_frame(1, 1.0, 100.0, 20.0)}, GapProperties{});
  for (const Model* model : {&modal_model, &critical_model}) {
    const DofLayout layout(*model);
    const LinearPhase phase(*model, layout, ContactConfiguration(model->gap_count(), PaperGap::link_mode(GapMode::open)), 1e-3);
    const ExactPhase exact(phase);
    EXPECT_EQ(exact.modal(), model == &modal_model);
    const auto n = 2 * exact.groups();
    const Eigen::VectorXd mass = Eigen::VectorXd::Ones(n / 2), load = Eigen::VectorXd::Zero(n / 2);
    const ForcingPiece piece{.kind = ForcingPiece::Kind::harmonic, .amplitude = 2.0, .omega = 9.0};
    ExactTrajectory trajectory;
    trajectory.start(exact, mass, load, 0.3, Eigen::VectorXd::LinSpaced(n, -0.01, 0.02), piece);
    Eigen::VectorXd with_rate, rate, alone;
    for (const double s : {0.0, 0.013, 0.37, 2.5}) {
      trajectory.evaluate(s, with_rate, rate);
      trajectory.evaluate(s, alone);
      ASSERT_EQ(alone.size(), n);
      EXPECT_EQ(std::memcmp(alone.data(), with_rate.data(), sizeof(double) * static_cast<std::size_t>(n)), 0) << s;
    }
  }
}

// The tangent flow's propagation (one of each conjugate pair, doubled; real modes once) is e^{As} r
// to round-off, on phases with complex modes only and with real (overdamped) ones.
TEST(ExactPhase, ItsModalPropagationIsThePropagatorTimesTheColumns) {
  DimensionlessParameters damped = testing::fig2('c');
  damped.xi = 2.0;  // storeys damped past critical: real modes
  int real_modes = 0, pairs = 0;
  for (const auto& [parameters, mode] : {std::pair{testing::fig2('c'), GapMode::open}, std::pair{damped, GapMode::open}}) {
    const Model model = make_model(parameters, {3, 3});
    const DofLayout layout(model);
    const LinearPhase phase(model, layout, ContactConfiguration(model.gap_count(), PaperGap::link_mode(mode)), 1e-3);
    const ExactPhase exact(phase);
    ASSERT_TRUE(exact.modal());
    for (const auto& l : exact.eigenvalues()) (l.imag() == 0.0 ? real_modes : pairs) += 1;
    const Eigen::Index n = exact.matrix().rows();
    const Eigen::MatrixXd r = Eigen::MatrixXd::Random(n, n + 1);
    ExactPhase::Projection projected;
    exact.project_modes(r, projected);
    Eigen::MatrixXd out;
    for (const double s : {0.0, 0.05, 0.37, 1.9}) {
      const Eigen::MatrixXd reference = (exact.matrix() * s).exp() * r;
      exact.propagate_projected(s, projected, out);
      EXPECT_LT((out - reference).norm(), 1e-12 * reference.norm()) << s;
    }
  }
  EXPECT_GT(real_modes, 0);
  EXPECT_GT(pairs, 0);
}

// The propagator is the state's sensitivity to its start: e^{As} on both paths, a semigroup, and
// (the system being linear) the difference of two trajectories from nearby starts, under forcing.
TEST(ExactPhase, ThePropagatorIsTheSensitivityOfTheStateToItsStart) {
  const Model model = make_model(testing::fig2('c'), {3, 3});
  const DofLayout layout(model);
  const LinearPhase phase(model, layout, ContactConfiguration(model.gap_count(), PaperGap::link_mode(GapMode::open)), 1e-3);
  const ExactPhase exact(phase);
  ASSERT_TRUE(exact.modal());
  const double s = 0.37;
  const Eigen::MatrixXd phi = exact.propagator(s);
  const Eigen::MatrixXd reference = (exact.matrix() * s).exp();
  EXPECT_LT((phi - reference).norm(), 1e-12 * reference.norm());
  EXPECT_LT((exact.propagator(0.1) * exact.propagator(0.27) - phi).norm(), 1e-12 * phi.norm());
  EXPECT_LT((exact.propagator(0.0) - Eigen::MatrixXd::Identity(phi.rows(), phi.cols())).norm(), 1e-13);
  // Under harmonic forcing: x(s; x0 + δ) − x(s; x0) = Φ(s) δ.
  const auto n = phi.rows();
  const Eigen::VectorXd mass = Eigen::VectorXd::Ones(n / 2), load = Eigen::VectorXd::Zero(n / 2);
  const ForcingPiece piece{.kind = ForcingPiece::Kind::harmonic, .amplitude = 2.0, .omega = 9.0};
  Eigen::VectorXd x0 = Eigen::VectorXd::LinSpaced(n, -0.01, 0.02), delta = Eigen::VectorXd::LinSpaced(n, 1e-4, -2e-4);
  ExactTrajectory a, b;
  a.start(exact, mass, load, 0.3, x0, piece);
  b.start(exact, mass, load, 0.3, x0 + delta, piece);
  Eigen::VectorXd xa, xb, rate;
  a.evaluate(s, xa, rate);
  b.evaluate(s, xb, rate);
  EXPECT_LT(((xb - xa) - phi * delta).norm(), 1e-10 * (phi * delta).norm());
}

TEST(ExactPhase, PiecewiseLinearRecordRestartsAtEverySample) {
  // Undamped oscillator from rest under a_g with slope changes a₁ₖ at t_k: by superposition
  // u(t) = −Σ Δa₁ₖ/ω² ((t − t_k) − sin(ω(t − t_k))/ω) for t > t_k.
  const double k = 400.0, w = 20.0;
  const Model model = make_model({make_uniform_frame(1, 1.0, k, 0.0)}, GapProperties{});
  const std::vector<double> t{0.0, 0.13, 0.31, 0.5, 0.77};
  const std::vector<double> a{0.0, 1.3, -0.4, 0.9, 0.9};
  const RecordExcitation record{t, a, "test"};
  Simulator sim(model, record, exact_options(0.01));
  const auto exact = [&](double time) {
    double u = 0, previous_slope = 0;
    for (std::size_t i = 0; i + 1 < t.size(); ++i) {
      const double slope = (a[i + 1] - a[i]) / (t[i + 1] - t[i]);
      const double change = slope - previous_slope;
      previous_slope = slope;
      if (time > t[i]) {
        const double s = time - t[i];
        u -= change / (w * w) * (s - std::sin(w * s) / w);
      }
    }
    // After the last sample a_g drops to zero: a step of −a_last and the ramp's end.
    if (time > t.back()) {
      const double s = time - t.back();
      u -= -previous_slope / (w * w) * (s - std::sin(w * s) / w);
      u -= -a.back() / (w * w) * (1 - std::cos(w * s));
    }
    return u;
  };
  double worst = 0, scale = 0;
  for (int n = 1; n <= 150; ++n) {
    sim.step();
    worst = std::max(worst, std::abs(sim.state().u(0) - exact(sim.time())));
    scale = std::max(scale, std::abs(exact(sim.time())));
  }
  EXPECT_LT(worst, 1e-12 * scale);
}

// A floor held by nothing (no storey spring; no dashpot, or one) beside a damped 2-storey frame,
// the gap between them open. Undamped, the floor is a defective zero eigenvalue of A (a Jordan
// pair, [0; N] ↦ [N; 0]), which no sum of exponentials represents and which the eigen-solver's
// modes cannot span; the modal path splits it off into the particular polynomial. Damped, it is a
// simple zero eigenvalue. Either way the phase stays modal: the floor follows its closed form, the
// frame moves as it does alone, and the propagator (with its s A(I − P) term) is e^{As}.
TEST(ExactPhase, AFloorHeldByNothingStaysOnTheModalPath) {
  Frame frame = make_uniform_frame(2, 1.5, 900.0, 2.0, "frame");
  frame.damping[1] = 0.3;
  const Model alone = make_model({frame}, GapProperties{});
  const DofLayout alone_layout(alone);
  const LinearPhase alone_phase(alone, alone_layout, {}, 1e-3);
  const ExactPhase frame_only(alone_phase);
  ASSERT_TRUE(frame_only.modal());
  ASSERT_FALSE(frame_only.singular());
  for (const double damping : {0.0, 0.8}) {
    const double mass = 2.0, rate = damping / mass;  // γ = c/m of the floor
    const Model model = make_model({frame, make_uniform_frame(1, mass, 0.0, damping, "free")},
                                   GapProperties{.gap = 1.0, .restitution = 0.5});
    const DofLayout layout(model);
    const LinearPhase phase(model, layout, ContactConfiguration(1, PaperGap::link_mode(GapMode::open)), 1e-3);
    ASSERT_TRUE(phase.is_unreduced());
    const ExactPhase exact(phase);
    EXPECT_TRUE(exact.singular());
    ASSERT_TRUE(exact.modal()) << damping;
    EXPECT_EQ(exact.rigid_modes().cols(), damping == 0.0 ? 1 : 0);
    EXPECT_EQ(exact.jordan_columns().size(), damping == 0.0 ? 2u : 0u);
    for (const double s : {0.05, 0.37, 1.9}) {
      // (e^{As} itself, by scaling and squaring, is good to a few 1e-12 here.)
      const Eigen::MatrixXd reference = (exact.matrix() * s).exp();
      EXPECT_LT((exact.propagator(s) - reference).norm(), 1e-11 * reference.norm()) << damping << ' ' << s;
      const Eigen::MatrixXd r = Eigen::MatrixXd::Random(6, 3);
      ExactPhase::Projection projected;
      exact.project_modes(r, projected);
      Eigen::MatrixXd out;
      exact.propagate_projected(s, projected, out);
      EXPECT_LT((out - reference * r).norm(), 1e-11 * (reference * r).norm()) << damping << ' ' << s;
    }
    // Floors level by level (DofLayout): frame's first, free, frame's second; then velocities.
    Eigen::VectorXd x0(6), frame_x0(4);
    x0 << 0.004, -0.02, 0.012, 0.2, 0.7, -0.3;
    frame_x0 << x0(0), x0(2), x0(3), x0(5);
    const double t0 = 0.7, q0 = x0(1), v0 = x0(4);
    const ForcingPiece linear{.kind = ForcingPiece::Kind::linear, .start = 0.2, .end = 5.0, .value = 1.1, .slope = -3.0};
    const ForcingPiece harmonic{.kind = ForcingPiece::Kind::harmonic, .start = 0.0, .end = 1e9, .amplitude = 2.0, .omega = 17.0};
    // The floor under a_g: q̈ = −γq̇ − a_g, in closed form.
    const auto floor = [&](const ForcingPiece& piece, double s) -> std::pair<double, double> {
      if (piece.kind == ForcingPiece::Kind::linear) {
        const double a0 = piece.at(t0), a1 = piece.slope;
        if (rate == 0.0) return {q0 + v0 * s - a0 * s * s / 2 - a1 * s * s * s / 6, v0 - a0 * s - a1 * s * s / 2};
        const double b = -a1 / rate, c = (-a0 - b) / rate, decay = std::exp(-rate * s);
        return {q0 + c * s + b * s * s / 2 + (v0 - c) * (1 - decay) / rate, c + b * s + (v0 - c) * decay};
      }
      if (rate != 0.0) return {std::nan(""), std::nan("")};  // (the damped floor: linear piece only)
      const double w = piece.omega, a = piece.amplitude, start = w * t0, now = w * (t0 + s);
      return {q0 + v0 * s + a / w * ((std::sin(now) - std::sin(start)) / w - std::cos(start) * s),
              v0 + a / w * (std::cos(now) - std::cos(start))};
    };
    for (const ForcingPiece* piece : {&linear, &harmonic}) {
      if (rate != 0.0 && piece == &harmonic) continue;
      ExactTrajectory trajectory, reference;
      trajectory.start(exact, phase.mass(), phase.constant_load(), t0, x0, *piece);
      reference.start(frame_only, alone_phase.mass(), alone_phase.constant_load(), t0, frame_x0, *piece);
      Eigen::VectorXd x, x_rate, y, y_rate;
      for (const double s : {0.0, 0.013, 0.37, 2.5}) {
        trajectory.evaluate(s, x, x_rate);
        reference.evaluate(s, y, y_rate);
        const auto [q, v] = floor(*piece, s);
        EXPECT_NEAR(x(1), q, 1e-13 * (1 + std::abs(q))) << damping << ' ' << s;
        EXPECT_NEAR(x(4), v, 1e-13 * (1 + std::abs(v))) << damping << ' ' << s;
        const Eigen::Vector4d frame_x(x(0), x(2), x(3), x(5));
        EXPECT_LT((frame_x - y).norm(), 1e-12 * (1 + y.norm())) << damping << ' ' << s;
      }
    }
  }
}

// The steady state under harmonic forcing with complex modes is checked against the closed form
// by Verification.ExactSteadyStateMatchesTheClosedForm (the same check `poundsim verify` prints).

TEST(ExactPhase, HarmonicResponseSolvesItsSystemForEachFrequency) {
  // (iωI − A) h = e, with the last h remembered: asking again after another ω gives it back.
  const Model model = make_model({make_uniform_frame(2, 1.0, 100.0, 0.5)}, GapProperties{});
  const DofLayout layout(model);
  const ExactPhase exact{LinearPhase(model, layout, {}, 1e-3)};
  const Eigen::Index n = exact.groups();
  Eigen::VectorXcd e = Eigen::VectorXcd::Zero(2 * n);
  e.tail(n).setConstant(-1.0);
  const auto residual = [&](double omega, const Eigen::VectorXcd& h) {
    Eigen::MatrixXcd m = -exact.matrix().cast<std::complex<double>>();
    m.diagonal().array() += std::complex<double>(0.0, omega);
    return (m * h - e).norm();
  };
  const Eigen::VectorXcd first = exact.harmonic_response(3.0);
  const Eigen::VectorXcd second = exact.harmonic_response(7.0);
  EXPECT_LT(residual(3.0, first), 1e-12);
  EXPECT_LT(residual(7.0, second), 1e-12);
  EXPECT_GT((first - second).norm(), 1e-3);
  EXPECT_EQ(exact.harmonic_response(3.0), first);
}

TEST(ExactPhase, UndampedForcingAtResonanceIsRejected) {
  const Model model = make_model({make_uniform_frame(1, 1.0, 100.0, 0.0)}, GapProperties{});
  EXPECT_THROW(
      {
        Simulator sim(model, HarmonicExcitation{1.0, 10.0}, exact_options(1e-2));
        sim.step();
      },
      SimulationError);
}


// A neighbour 8e4 times stiffer in frequency than its frame (a wall, in effect): unbalanced, its
// modes (1, ±iω)/‖·‖ were nearly parallel, the phase fell back to the matrix exponential, and 10 ms
// of free vibration did not finish in 15 s. Balanced, the phase stays modal and the frame's free
// vibration is exact while the wall stays at rest.
TEST(ExactPhase, AStiffNeighbourKeepsTheModalSolution) {
  const double m = 1.0, k = 200.0, zeta = 0.05, v0 = 0.1, ratio = 8e4;
  const double w = std::sqrt(k / m), wd = w * std::sqrt(1 - zeta * zeta);
  const Model model = testing::two_oscillators(m, k, 2 * zeta * m * w, m, k * ratio * ratio, 0.0,
                                               GapProperties{.gap = 0.1, .restitution = 0.75});
  const DofLayout layout(model);
  const LinearPhase phase(model, layout, ContactConfiguration(1, PaperGap::link_mode(GapMode::open)), 1e-3);
  const ExactPhase exact(phase);
  EXPECT_TRUE(exact.modal());
  EXPECT_NEAR(exact.spectral_radius(), w * ratio, 1e-9 * w * ratio);

  InitialConditions ic;
  ic.velocity = {{v0}, {0.0}};
  Simulator sim(model, NoExcitation{}, exact_options(1e-3), ic);
  double worst = 0;
  for (int n = 1; n <= 10; ++n) {
    sim.step();
    const double t = sim.time();
    const double u = std::exp(-zeta * w * t) * v0 / wd * std::sin(wd * t);
    worst = std::max({worst, std::abs(sim.state().u(0) - u), std::abs(sim.state().u(1))});
  }
  EXPECT_LT(worst, 1e-15);  // m: |u| ≤ 1e-3
  EXPECT_LT(sim.energy_meter().max_relative_residual(), 1e-12);
}

TEST(ExactPhase, AWallBesideAFrameLeavesItsForcedResponseAndEnergyUnchanged) {
  // Without contact frame 1 does not feel its neighbour: beside a wall (frame 2 up to 10⁶ times
  // its frequency) its forced response must be the one beside a twin. Before the balanced
  // harmonic solve, ratio 10⁶ was refused as a resonance (rcond ~ ω̄/‖A‖); before the closed-form
  // energy integrals, the quadrature cost grew with the ratio.
  const double m = 1.0, k = 200.0, c = 1.4;
  const HarmonicExcitation forcing{.amplitude = 2.0, .omega = 0.8 * std::sqrt(k / m)};
  const auto run = [&](double ratio) {
    const Model model = testing::two_oscillators(m, k, c, m, k * ratio * ratio, 0.0,
                                                 GapProperties{.gap = 1.0, .restitution = 0.5});
    Simulator sim(model, forcing, exact_options(1e-3));
    sim.advance_to(2.0);
    EXPECT_LT(sim.energy_meter().max_relative_residual(), 1e-12) << ratio;
    return std::pair{sim.state().u(0), sim.energy_meter().balance()};
  };
  const auto [twin_u, twin_energy] = run(1.0);
  for (const double ratio : {1e2, 1e4, 8e4, 1e6}) {
    const auto [u, energy] = run(ratio);
    EXPECT_NEAR(u, twin_u, 1e-13) << ratio;  // m: |u| ~ 1e-2
    EXPECT_NEAR(energy.storey_damping, twin_energy.storey_damping, 1e-12 * twin_energy.storey_damping) << ratio;
  }
}

}  // namespace
}  // namespace poundsim
