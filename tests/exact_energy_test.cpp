// The exact integrator's closed-form energy integrals against closed forms and quadrature.

#include "poundsim/integrate/exact_energy.hpp"

#include <cmath>
#include <complex>
#include <vector>

#include <Eigen/Eigenvalues>
#include <gtest/gtest.h>

#include "poundsim/dynamics/energy.hpp"
#include "poundsim/dynamics/linear_phase.hpp"
#include "poundsim/integrate/simulator.hpp"
#include "test_models.hpp"

namespace poundsim {
namespace {

using Complex = std::complex<double>;

TEST(ExactEnergy, ExponentialMomentsMatchTheirAntiderivatives) {
  // ∫ s^d e^{μs} ds = e^{μs} Σ_l (−1)^l d!/(d−l)! s^{d−l} / μ^{l+1}, fine where |μh| is not small.
  const auto antiderivative = [](int d, Complex mu, double s) {
    Complex sum = 0.0, term = 1.0 / mu;
    for (int l = 0; l <= d; ++l) {
      sum += term * std::pow(s, d - l);
      term *= -static_cast<double>(d - l) / mu;
    }
    return std::exp(mu * s) * sum;
  };
  for (const Complex mu : {Complex(-3.0, 40.0), Complex(0.0, -7.0), Complex(-250.0, 0.0), Complex(-0.5, 2.0)}) {
    for (int d = 0; d <= 3; ++d) {
      const double a = 0.37, h = 0.9;
      const Complex exact = antiderivative(d, mu, a + h) - antiderivative(d, mu, a);
      EXPECT_LT(std::abs(exponential_moment(d, mu, a, h) - exact), 1e-14 * std::max(1.0, std::abs(exact)))
          << "d = " << d << ", mu = " << mu;
    }
  }
  // μ → 0, where e^{μh} − 1 cancels: the polynomial limit ((a+h)^{d+1} − a^{d+1})/(d+1) plus its
  // first-order term μ ((a+h)^{d+2} − a^{d+2})/(d+2).
  for (const double size : {1e-3, 1e-8, 1e-14, 0.0}) {
    const Complex mu(0.3 * size, size);
    for (int d = 0; d <= 3; ++d) {
      const double a = 2.0, h = 0.5, b = a + h;
      const Complex series = (std::pow(b, d + 1) - std::pow(a, d + 1)) / (d + 1.0) +
                             mu * (std::pow(b, d + 2) - std::pow(a, d + 2)) / (d + 2.0) +
                             mu * mu * (std::pow(b, d + 3) - std::pow(a, d + 3)) / (2.0 * (d + 3));
      EXPECT_LT(std::abs(exponential_moment(d, mu, a, h) - series), 1e-15 * std::abs(series) + std::pow(size, 3) * std::pow(b, d + 4))
          << "d = " << d << ", |mu| = " << size;
    }
  }
}

/// ∫ of the powers over [a, b] of a trajectory by composite 10-point Gauss–Legendre quadrature,
/// fine enough to resolve every mode: the reference.
EnergyMeter::Powers quadrature(const ExactTrajectory& trajectory, const LinearPhase& phase,
                               const EnergyMeter& meter, const ContactConfiguration& config, const LinkStates& states,
                               double a, double b, int pieces) {
  Eigen::Matrix<double, 10, 1> nodes, weights;
  {
    Eigen::MatrixXd jacobi = Eigen::MatrixXd::Zero(10, 10);
    for (int i = 1; i < 10; ++i) jacobi(i, i - 1) = jacobi(i - 1, i) = i / std::sqrt(4.0 * i * i - 1);
    const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(jacobi);
    nodes = eig.eigenvalues();
    weights = 2 * eig.eigenvectors().row(0).cwiseAbs2().transpose();
  }
  const Eigen::Index n = phase.reduced_size();
  EnergyMeter::Powers sum;
  Eigen::VectorXd x, rate;
  KinematicState state;
  state.u.setZero(n);
  state.v.resize(n);
  const double width = (b - a) / pieces;
  for (int p = 0; p < pieces; ++p) {
    for (int k = 0; k < 10; ++k) {
      const double s = a + (p + 0.5 + 0.5 * nodes(k)) * width;
      trajectory.evaluate(s, x, rate);
      state.v = x.tail(n);
      state.t = trajectory.start_time() + s;
      state.ground = trajectory.piece().at(state.t);
      const EnergyMeter::Powers power = meter.powers(state, config, states);
      const double w = 0.5 * width * weights(k);
      sum.input += w * power.input;
      sum.storey_damping += w * power.storey_damping;
      sum.gap_damping += w * power.gap_damping;
    }
  }
  return sum;
}

/// The closed-form integrals of `config`'s phase against quadrature from x0, on a linear and a
/// harmonic piece: a short step, a step far into the segment, a long one over many periods, then
/// three grid steps of one length (the second and third use the weights kept for that length).
/// Each dashpot's integral is at least `share` of the three (storeys' 10 times that).
void expect_closed_form_matches_quadrature(const Model& model, const ContactConfiguration& config,
                                           const Eigen::VectorXd& x0, double share = 1e-4) {
  const DofLayout layout(model);
  const LinearPhase phase(model, layout, config, 1e-3);
  ASSERT_TRUE(phase.is_unreduced());
  const ExactPhase exact(phase);
  ASSERT_TRUE(exact.modal());
  const EnergyMeter meter(model, layout);
  const LinkStates states(make_links(model, layout));  // every law in its initial state
  ExactPowerIntegrals closed(exact, meter.power_forms(config, phase.group_of(), exact.groups()));
  ASSERT_EQ(x0.size(), 2 * exact.groups());
  const ForcingPiece pieces[] = {
      ForcingPiece{.kind = ForcingPiece::Kind::linear, .start = 0.2, .end = 5.0, .value = 1.1, .slope = -3.0},
      ForcingPiece{.kind = ForcingPiece::Kind::harmonic, .start = 0.0, .end = 1e9, .amplitude = 2.0, .omega = 17.0}};
  for (const ForcingPiece& piece : pieces) {
    ExactTrajectory trajectory;
    trajectory.start(exact, phase.mass(), phase.constant_load(), 0.7, x0, piece);
    closed.start(trajectory);
    for (const auto& [a, b] : {std::pair{0.0, 1e-3}, std::pair{2.5, 2.5 + 2e-3}, std::pair{0.1, 3.1},
                               std::pair{1.0, 1.004}, std::pair{1.004, 1.008}, std::pair{1.008, 1.012}}) {
      const EnergyMeter::Powers got = closed.integrate(a, b);
      const EnergyMeter::Powers want = quadrature(trajectory, phase, meter, config, states, a, b, 400);
      const double scale = std::abs(want.input) + want.storey_damping + want.gap_damping;
      ASSERT_GT(std::abs(want.input), 1e-3 * scale);
      ASSERT_GT(want.storey_damping, 10 * share * scale);
      ASSERT_GT(want.gap_damping, share * scale);
      EXPECT_NEAR(got.input, want.input, 1e-12 * scale) << a << ' ' << b;
      EXPECT_NEAR(got.storey_damping, want.storey_damping, 1e-12 * scale) << a << ' ' << b;
      EXPECT_NEAR(got.gap_damping, want.gap_damping, 1e-12 * scale) << a << ' ' << b;
    }
  }
}

// A 2- and a 3-storey frame with non-proportional storey dashpots and one gap element in
// contact: complex modes, both quadratic forms and the ground input non-zero.
Model two_frames_in_contact(std::vector<Frame> more = {}) {
  Frame left = make_uniform_frame(2, 1.5, 900.0, 2.0, "L");
  left.damping[1] = 0.3;
  std::vector<Frame> frames{left, make_uniform_frame(3, 0.8, 2500.0, 0.5, "R")};
  frames.insert(frames.end(), more.begin(), more.end());
  return make_model(frames, GapProperties{.stiffness = 4000.0, .damping = 6.0, .gap = 0.01, .shortening = 0.02,
                                          .restitution = 0.5});
}

TEST(ExactEnergy, ClosedFormMatchesQuadratureOnLinearAndHarmonicPieces) {
  const Model model = two_frames_in_contact();
  ContactConfiguration config(model.gap_count(), PaperGap::link_mode(GapMode::open));
  config[1] = PaperGap::link_mode(GapMode::contact);  // floors L2 and R2
  Eigen::VectorXd x0(10);  // five floors, then their velocities
  x0 << 0.004, 0.012, -0.002, -0.006, 0.003, 0.2, 0.3, -0.25, -0.3, 0.1;
  expect_closed_form_matches_quadrature(model, config, x0);
}

// The same beside a floor that nothing holds (no spring, no dashpot, its gap open): an undamped
// rigid-body mode, a Jordan pair of A that the particular polynomial carries. Its velocity has
// an s² term under the ground ramp, whose input is a cubic moment.
TEST(ExactEnergy, ClosedFormMatchesQuadratureBesideAFreeFloor) {
  const Model model = two_frames_in_contact({make_uniform_frame(1, 0.02, 0.0, 0.0, "free")});
  ContactConfiguration config(model.gap_count(), PaperGap::link_mode(GapMode::open));
  ASSERT_EQ(config.size(), 3u);  // L1–R1, L2–R2, R1–free
  config[1] = PaperGap::link_mode(GapMode::contact);
  {
    const DofLayout layout(model);
    const ExactPhase exact(LinearPhase(model, layout, config, 1e-3));
    ASSERT_EQ(exact.rigid_modes().cols(), 1);
  }
  Eigen::VectorXd x0(12);  // six floors, level by level (DofLayout), then their velocities
  x0 << 0.004, -0.002, 0.05, 0.012, -0.006, 0.003, 0.2, -0.25, -0.4, 0.3, -0.3, 0.1;
  // The floor's input grows as its velocity does (1.5 s² m/s under the ramp): the dashpots' share
  // is smaller.
  expect_closed_form_matches_quadrature(model, config, x0, 1e-5);
}

}  // namespace
}  // namespace poundsim
