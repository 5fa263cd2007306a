// A frame's damping (docs/model.md#damping): stiffness-proportional storey dashpots, Rayleigh
// damping from ratios at two modes, modal damping from a ratio per mode, each against the modal
// damping ratios it must give; a free decay in one mode against its closed form; the energy
// balance with the dashpots that are not links.
#include <cmath>
#include <numbers>
#include <string>
#include <vector>

#include <Eigen/Eigenvalues>
#include <gtest/gtest.h>

#include "poundsim/integrate/simulator.hpp"
#include "poundsim/io/input.hpp"
#include "poundsim/model/frame.hpp"
#include "poundsim/model/model.hpp"

namespace poundsim {
namespace {

/// ω_k/ω₁ of a uniform n-storey shear frame: sin((2k − 1)π/(4n + 2)) / sin(π/(4n + 2)).
double frequency_ratio(int n, int k) {
  const double unit = std::numbers::pi / (4.0 * n + 2.0);
  return std::sin((2 * k - 1) * unit) / std::sin(unit);
}

/// The frame of `keys` (its damping keys) read from a model file: 8 storeys of 1e5 kg, 1e8 N/m.
Frame frame_with(const std::string& keys) {
  const std::string text = "[[frames]]\nstoreys = 8\nmass = 1e5\nstiffness = 1e8\n" + keys +
                           "\n[analysis]\nkind = \"time_history\"\nduration = 1.0\ndt = 0.001\n"
                           "[excitation]\nkind = \"none\"\n";
  return io::read_input_string(text, "damping.toml", ".").model.frames.at(0);
}

std::string error_of(const std::string& keys) {
  try {
    (void)frame_with(keys);
  } catch (const InputError& e) {
    return e.what();
  }
  return "no error";
}

TEST(FrameDamping, StiffnessProportionalDampingGrowsWithTheMode) {
  // The complaint: 5 % in mode 1 is 15 % in mode 2 and 24 % in mode 3 of 8 storeys.
  const Eigen::VectorXd zeta = modal_damping_ratios(frame_with("damping_ratio = 0.05"));
  for (int k = 1; k <= 8; ++k) EXPECT_NEAR(zeta(k - 1), 0.05 * frequency_ratio(8, k), 1e-12) << "mode " << k;
  EXPECT_NEAR(zeta(1), 0.148, 5e-4);
  EXPECT_NEAR(zeta(2), 0.2415, 5e-4);
}

TEST(FrameDamping, RayleighGivesItsRatiosAtItsTwoModes) {
  const Frame frame = frame_with("rayleigh_ratios = [0.05, 0.05]\nrayleigh_modes = [1, 3]");
  const Eigen::VectorXd zeta = modal_damping_ratios(frame);
  EXPECT_NEAR(zeta(0), 0.05, 1e-12);
  EXPECT_NEAR(zeta(2), 0.05, 1e-12);
  EXPECT_LT(zeta(1), 0.05);  // between the two modes it is lower, beyond them higher
  EXPECT_GT(zeta(3), 0.05);
  // ζ_k = a₀/(2ω_k) + a₁ω_k/2 in every mode, and the dashpots are a₁K_i and a₀M_i.
  const RayleighCoefficients a = rayleigh_coefficients(frame, 1, 0.05, 3, 0.05);
  const Eigen::VectorXd omega = natural_frequencies(frame);
  for (int k = 0; k < 8; ++k) EXPECT_NEAR(zeta(k), a.mass / (2 * omega(k)) + a.stiffness * omega(k) / 2, 1e-12);
  EXPECT_DOUBLE_EQ(frame.damping[3], a.stiffness * 1e8);
  EXPECT_DOUBLE_EQ(frame.ground_damping[5], a.mass * 1e5);
}

TEST(FrameDamping, ModalDampingGivesEachModeItsRatio) {
  const Eigen::VectorXd all = modal_damping_ratios(frame_with("modal_damping_ratios = 0.05"));
  for (int k = 0; k < 8; ++k) EXPECT_NEAR(all(k), 0.05, 1e-12) << "mode " << k + 1;
  const Eigen::VectorXd each =
      modal_damping_ratios(frame_with("modal_damping_ratios = [0.02, 0.03, 0.04, 0.05, 0.06, 0.07, 0.08, 0.09]"));
  for (int k = 0; k < 8; ++k) EXPECT_NEAR(each(k), 0.02 + 0.01 * k, 1e-12) << "mode " << k + 1;
  // With storey dashpots it adds to theirs.
  const Eigen::VectorXd both = modal_damping_ratios(frame_with("damping = 1e6\nmodal_damping_ratios = 0.01"));
  const Eigen::VectorXd storeys = modal_damping_ratios(frame_with("damping = 1e6"));
  for (int k = 0; k < 8; ++k) EXPECT_NEAR(both(k), storeys(k) + 0.01, 1e-12);
}

TEST(FrameDamping, BadDampingKeysAreNamed) {
  EXPECT_NE(error_of("damping = 1e6\nrayleigh_ratios = [0.05, 0.05]\nrayleigh_modes = [1, 3]")
                .find("frames[1].rayleigh_ratios: sets the frame's dashpots by its rule: give it alone, not with damping"),
            std::string::npos);
  EXPECT_NE(error_of("damping_ratio = 0.05\nmodal_damping_ratios = 0.02").find("frames[1].damping_ratio"), std::string::npos);
  EXPECT_NE(error_of("rayleigh_ratios = [0.05, 0.05]\nrayleigh_modes = [1, 9]")
                .find("frames[1].rayleigh_modes: each must be a mode number 1 … 8 (got 9)"),
            std::string::npos);
  EXPECT_NE(error_of("rayleigh_ratios = [0.05, 0.05]\nrayleigh_modes = [2, 2]").find("the two modes must differ"),
            std::string::npos);
  // 1 % in mode 1 and 0 in mode 3 needs a negative a₁.
  EXPECT_NE(error_of("rayleigh_ratios = [0.05, 0.0]\nrayleigh_modes = [1, 3]").find("a negative coefficient"),
            std::string::npos);
  EXPECT_NE(error_of("modal_damping_ratios = 1.0").find("frames[1].modal_damping_ratios"), std::string::npos);
  EXPECT_NE(error_of("").find("missing key: damping"), std::string::npos);
}

TEST(FrameDamping, AModeDecaysAtItsModalRatioAndTheBalanceCloses) {
  // Released in its second mode's shape, a modally damped frame vibrates in that mode alone:
  // q(t) = e^{−ζωt}(cos ω_d t + ζ/√(1 − ζ²) sin ω_d t). Both integrators; the balance closes.
  Frame frame = make_uniform_frame(8, 1e5, 1e8, 0.0);
  frame.modal_damping_ratios.assign(8, 0.05);
  frame.ground_damping.assign(8, 0.0);
  const Model model = make_model({frame}, GapLaw{});
  const Eigen::VectorXd m = Eigen::VectorXd::Constant(8, 1e5);
  const Eigen::VectorXd inv_sqrt_m = m.cwiseSqrt().cwiseInverse();
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(inv_sqrt_m.asDiagonal() * stiffness_matrix(frame) *
                                                           inv_sqrt_m.asDiagonal());
  const double omega = std::sqrt(eig.eigenvalues()(1));
  Eigen::VectorXd shape = inv_sqrt_m.asDiagonal() * eig.eigenvectors().col(1);
  shape *= 0.01 / shape(7);  // 1 cm at the top
  InitialConditions ic;
  ic.displacement = {std::vector<double>(shape.data(), shape.data() + 8)};
  const double t = 0.37, zeta = 0.05, omega_d = omega * std::sqrt(1 - zeta * zeta);
  const double exact = 0.01 * std::exp(-zeta * omega * t) *
                       (std::cos(omega_d * t) + zeta / std::sqrt(1 - zeta * zeta) * std::sin(omega_d * t));
  for (const auto& [integrator, dt, tolerance] :
       {std::tuple{Integrator::exact, 1e-3, 1e-12}, std::tuple{Integrator::newmark, 1e-4, 2e-5}}) {
    Simulator sim(model, NoExcitation{}, TimeHistoryOptions{.dt = dt, .integrator = integrator}, ic);
    sim.advance_to(t);
    EXPECT_NEAR(sim.state().u(sim.layout().dof(0, 7)), exact, tolerance) << to_string(integrator);
    EXPECT_LT(sim.energy_meter().max_relative_residual(), 1e-10) << to_string(integrator);
    // What the dashpots took is what the frame lost.
    EXPECT_GT(sim.energy().storey_damping, 0.0);
  }
}

}  // namespace
}  // namespace poundsim
