// Pounding under real ground motions: a linear record response against an independent
// calculation, and separation distances that are exactly the smallest gap without contact.

#include <cmath>
#include <filesystem>

#include <Eigen/Dense>
#include <gtest/gtest.h>

#include "poundsim/io/ground_motion.hpp"
#include "poundsim/analysis/response_metrics.hpp"
#include "poundsim/integrate/simulator.hpp"
#include "test_models.hpp"

namespace poundsim {
namespace {

namespace fs = std::filesystem;

const fs::path kRecords = fs::path(POUNDSIM_SOURCE_DIR) / "data" / "ground_motions";

RecordExcitation el_centro(double target_pga_g) {
  io::RecordOptions o;
  o.target_pga_g = target_pga_g;
  return io::read_ground_motion(kRecords / "RSN6_IMPVALL.I_I-ELC180.AT2", o).excitation;
}

/// One mode, q'' + 2ζω q' + ω² q = −Γ a_g(t) with a_g linear between samples: on each interval
/// the solution is the particular α + βτ plus a damped free vibration — exact (Nigam & Jennings).
std::vector<double> modal_response(double omega, double zeta, double gamma, const RecordExcitation& r) {
  const double wd = omega * std::sqrt(1 - zeta * zeta);
  std::vector<double> q(r.time.size(), 0.0);
  double u = 0, v = 0;
  for (std::size_t k = 0; k + 1 < r.time.size(); ++k) {
    const double h = r.time[k + 1] - r.time[k];
    const double f0 = -gamma * r.acceleration[k], f1 = -gamma * (r.acceleration[k + 1] - r.acceleration[k]) / h;
    const double beta = f1 / (omega * omega);
    const double alpha = (f0 - 2 * zeta * omega * beta) / (omega * omega);
    const double c1 = u - alpha, c2 = (v - beta + zeta * omega * c1) / wd;
    const double e = std::exp(-zeta * omega * h), c = std::cos(wd * h), s = std::sin(wd * h);
    u = alpha + beta * h + e * (c1 * c + c2 * s);
    v = beta + e * ((-zeta * omega * c1 + wd * c2) * c + (-zeta * omega * c2 - wd * c1) * s);
    q[k + 1] = u;
  }
  return q;
}

TEST(Records, LinearResponseMatchesModalSuperposition) {
  // A three-storey frame with stiffness-proportional damping (classical modes) under the El
  // Centro 1940 NS record; poundsim solves it in physical coordinates, the reference mode by mode.
  Frame frame = make_uniform_frame(3, 2.0e5, 1.5e8, 0.0);
  frame.damping = stiffness_proportional_damping(frame, 0.05);
  const Model model = make_model({frame}, GapProperties{});
  const RecordExcitation record = el_centro(0.3);

  const Eigen::VectorXd m = Eigen::Map<const Eigen::VectorXd>(frame.mass.data(), 3);
  const Eigen::MatrixXd k = stiffness_matrix(frame), c = damping_matrix(frame);
  const Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::MatrixXd> modes(k, Eigen::MatrixXd(m.asDiagonal()));
  Eigen::MatrixXd reference = Eigen::MatrixXd::Zero(3, static_cast<Eigen::Index>(record.time.size()));
  for (int r = 0; r < 3; ++r) {
    const Eigen::VectorXd phi = modes.eigenvectors().col(r);  // φᵀMφ = 1
    const double omega = std::sqrt(modes.eigenvalues()(r));
    const double zeta = phi.dot(c * phi) / (2 * omega);
    const double gamma = phi.dot(m);
    const std::vector<double> q = modal_response(omega, zeta, gamma, record);
    for (std::size_t j = 0; j < q.size(); ++j) reference.col(static_cast<Eigen::Index>(j)) += phi * q[j];
  }
  const double scale = reference.cwiseAbs().maxCoeff();

  for (const Integrator integrator : {Integrator::exact, Integrator::newmark}) {
    Simulator sim(model, record, TimeHistoryOptions{.dt = integrator == Integrator::exact ? 0.01 : 0.001,
                                                    .integrator = integrator});
    double worst = 0;
    for (std::size_t j = 1; j < record.time.size(); j += 7) {
      sim.advance_to(record.time[j]);
      worst = std::max(worst, (sim.state().u - reference.col(static_cast<Eigen::Index>(j))).cwiseAbs().maxCoeff());
    }
    // Exact: round-off; Newmark with h = 1 ms: its O((ωh)²) error over 50 s.
    EXPECT_LT(worst, (integrator == Integrator::exact ? 1e-10 : 2e-3) * scale) << to_string(integrator);
  }
}

TEST(Records, MinimumSeparationIsTheSmallestGapWithoutContact) {
  // The paper's Fig. 2 frames (λ² = 200 s⁻², M1 = 1 kg) under El Centro scaled to 0.2 g, bare
  // pounding with e = 0.75. The free frames' largest approach u₁ − u₂ is the smallest gap that
  // avoids contact: with exactly that gap nothing touches, 1 % less and the frames pound.
  DimensionlessParameters p = testing::fig2('b');
  const RecordExcitation record = el_centro(0.2);
  const double duration = record.time.back();
  for (const Integrator integrator : {Integrator::exact, Integrator::newmark}) {
    const TimeHistoryOptions options{.dt = integrator == Integrator::exact ? 0.01 : 0.002, .integrator = integrator};
    const Model model = make_model(p, {1, 1});
    Simulator free(free_frames(model), record, options);
    free.advance_to(duration);
    const double min_gap = free.statistics().neighbours.at(0).max_approach;
    ASSERT_GT(min_gap, 0.0);
    EXPECT_LT(free.energy_meter().max_relative_residual(), 1e-12);

    const auto run = [&](double gap) {
      Model m = model;
      parameters_of<PaperGap>(m.gaps[0]).gap = gap;
      Simulator sim(m, record, options);
      sim.advance_to(duration);
      EXPECT_LT(sim.energy_meter().max_relative_residual(), 1e-9) << to_string(integrator);
      return sim.statistics().events;
    };
    EXPECT_EQ(run(min_gap), 0) << to_string(integrator) << " min gap " << min_gap;
    EXPECT_GT(run(0.99 * min_gap), 0) << to_string(integrator);
  }
}

}  // namespace
}  // namespace poundsim
