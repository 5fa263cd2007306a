#include "poundsim/model/frame.hpp"

#include <cmath>
#include <complex>
#include <stdexcept>
#include <utility>

#include <Eigen/Eigenvalues>
#include <Eigen/LU>
#include <fmt/format.h>

#include "poundsim/units.hpp"

namespace poundsim {

Frame make_uniform_frame(int storeys, double mass, double stiffness, double damping,
                         std::string name) {
  if (storeys < 1) {
    throw std::invalid_argument(fmt::format("frame needs at least one storey, got {}", storeys));
  }
  const auto n = static_cast<std::size_t>(storeys);
  return Frame{std::move(name), std::vector<double>(n, mass), std::vector<double>(n, stiffness),
               std::vector<double>(n, damping), {}, {}, {}, {}};
}

void validate(const Frame& frame) {
  const std::string label = frame.name.empty() ? std::string("frame") : "frame '" + frame.name + "'";
  if (frame.mass.empty()) throw std::invalid_argument(label + ": no storeys");
  if (frame.stiffness.size() != frame.mass.size() || frame.damping.size() != frame.mass.size()) {
    throw std::invalid_argument(fmt::format(
        "{}: mass, stiffness and damping need one value per floor (got {}, {} and {})", label,
        frame.mass.size(), frame.stiffness.size(), frame.damping.size()));
  }
  if (!frame.storey_height.empty() && frame.storey_height.size() != frame.mass.size()) {
    throw std::invalid_argument(fmt::format("{}: storey_height needs one value per storey", label));
  }
  if (!frame.ground_damping.empty() && frame.ground_damping.size() != frame.mass.size()) {
    throw std::invalid_argument(fmt::format("{}: ground_damping needs one value per floor", label));
  }
  if (!frame.modal_damping_ratios.empty() && frame.modal_damping_ratios.size() != frame.mass.size()) {
    throw std::invalid_argument(fmt::format("{}: modal_damping_ratios needs one value per mode", label));
  }
  if (const std::optional<std::string> violation = first_violation(frame)) {
    throw std::invalid_argument(fmt::format("{}: {}", label, *violation));
  }
  std::visit(
      [&](const auto& law) {
        using Parameters = typename std::decay_t<decltype(law)>::Law::Parameters;
        if (law.values.empty()) {
          // Every storey takes the law's defaults, which not every law can run with (a yielding
          // storey has no default yield force).
          if (const auto rule = Parameters{}.rule_violation()) {
            throw std::invalid_argument(fmt::format("{}: {}", label, rule->message));
          }
          return;
        }
        if (law.values.size() != frame.mass.size()) {
          throw std::invalid_argument(fmt::format("{}: the storey law's parameters are given for {} storeys, the frame has {}",
                                                  label, law.values.size(), frame.mass.size()));
        }
        for (std::size_t i = 0; i < law.values.size(); ++i) {
          if (const auto violation = first_violation(law.values[i])) {
            throw std::invalid_argument(fmt::format("{}: storey {}: {}", label, i + 1, *violation));
          }
          if (const auto rule = law.values[i].rule_violation()) {
            throw std::invalid_argument(fmt::format("{}: storey {}: {}", label, i + 1, rule->message));
          }
        }
      },
      frame.storey_law);
}

namespace {
Eigen::MatrixXd chain_matrix(const std::vector<double>& storey) {
  const auto n = static_cast<Eigen::Index>(storey.size());
  Eigen::MatrixXd k = Eigen::MatrixXd::Zero(n, n);
  for (Eigen::Index i = 0; i < n; ++i) {
    const double ki = storey[static_cast<std::size_t>(i)];
    k(i, i) += ki;
    if (i > 0) {
      k(i - 1, i - 1) += ki;
      k(i - 1, i) -= ki;
      k(i, i - 1) -= ki;
    }
  }
  return k;
}
}  // namespace

double weight(const Frame& frame) {
  double m = 0;
  for (const double x : frame.mass) m += x;
  return m * standard_gravity;
}

Eigen::MatrixXd stiffness_matrix(const Frame& frame) { return chain_matrix(frame.stiffness); }
Eigen::MatrixXd damping_matrix(const Frame& frame) {
  Eigen::MatrixXd c = chain_matrix(frame.damping);
  if (has_frame_damping(frame)) c += frame_damping_matrix(frame);
  return c;
}

bool has_frame_damping(const Frame& frame) {
  return !frame.ground_damping.empty() || !frame.modal_damping_ratios.empty();
}

namespace {
/// ω_k and the mass-normalised modes φ_k (φᵀMφ = 1) of the frame alone, lowest first.
std::pair<Eigen::VectorXd, Eigen::MatrixXd> normal_modes(const Frame& frame) {
  const Eigen::VectorXd m = Eigen::Map<const Eigen::VectorXd>(frame.mass.data(), frame.storeys());
  const Eigen::VectorXd inv_sqrt_m = m.cwiseSqrt().cwiseInverse();
  const Eigen::MatrixXd a = inv_sqrt_m.asDiagonal() * stiffness_matrix(frame) * inv_sqrt_m.asDiagonal();
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(a);
  return {eig.eigenvalues().cwiseMax(0.0).cwiseSqrt(), inv_sqrt_m.asDiagonal() * eig.eigenvectors()};
}
}  // namespace

Eigen::MatrixXd frame_damping_matrix(const Frame& frame) {
  const int n = frame.storeys();
  Eigen::MatrixXd c = Eigen::MatrixXd::Zero(n, n);
  for (std::size_t i = 0; i < frame.ground_damping.size(); ++i) {
    c(static_cast<Eigen::Index>(i), static_cast<Eigen::Index>(i)) += frame.ground_damping[i];
  }
  if (!frame.modal_damping_ratios.empty()) {
    // C_m = M Φ diag(2ζ_k ω_k) Φᵀ M with φ_kᵀMφ_k = 1: φ_kᵀ C_m φ_l = 2ζ_k ω_k δ_kl.
    const auto [omega, phi] = normal_modes(frame);
    const Eigen::VectorXd m = Eigen::Map<const Eigen::VectorXd>(frame.mass.data(), n);
    const Eigen::MatrixXd m_phi = m.asDiagonal() * phi;
    Eigen::VectorXd weight(n);
    for (int k = 0; k < n; ++k) weight(k) = 2.0 * frame.modal_damping_ratios[static_cast<std::size_t>(k)] * omega(k);
    c += m_phi * weight.asDiagonal() * m_phi.transpose();
  }
  return c;
}

Eigen::VectorXd modal_damping_ratios(const Frame& frame) {
  validate(frame);
  const auto [omega, phi] = normal_modes(frame);
  const Eigen::MatrixXd c = damping_matrix(frame);
  Eigen::VectorXd zeta(omega.size());
  for (Eigen::Index k = 0; k < omega.size(); ++k) zeta(k) = phi.col(k).dot(c * phi.col(k)) / (2.0 * omega(k));
  return zeta;
}

RayleighCoefficients rayleigh_coefficients(const Frame& frame, int mode_i, double ratio_i, int mode_j,
                                           double ratio_j) {
  const Eigen::VectorXd omega = natural_frequencies(frame);
  const double wi = omega(mode_i - 1), wj = omega(mode_j - 1);
  const double denominator = wj * wj - wi * wi;
  return {.mass = 2.0 * wi * wj * (ratio_i * wj - ratio_j * wi) / denominator,
          .stiffness = 2.0 * (ratio_j * wj - ratio_i * wi) / denominator};
}

Eigen::VectorXcd harmonic_amplitudes(const Frame& frame, double amplitude, double omega) {
  using Complex = std::complex<double>;
  const Eigen::VectorXd m = Eigen::Map<const Eigen::VectorXd>(frame.mass.data(), frame.storeys());
  const Eigen::MatrixXcd dynamic = stiffness_matrix(frame).cast<Complex>() -
                                   Eigen::MatrixXcd((omega * omega * m).asDiagonal()) +
                                   Complex(0, omega) * damping_matrix(frame).cast<Complex>();
  return dynamic.partialPivLu().solve((-amplitude * m).cast<Complex>());
}

Eigen::VectorXd natural_frequencies(const Frame& frame) {
  validate(frame);
  // M is diagonal: the symmetric form M^-1/2 K M^-1/2 has the same eigenvalues ω².
  const Eigen::VectorXd inv_sqrt_m =
      Eigen::Map<const Eigen::VectorXd>(frame.mass.data(), frame.storeys()).cwiseSqrt().cwiseInverse();
  const Eigen::MatrixXd a = inv_sqrt_m.asDiagonal() * stiffness_matrix(frame) * inv_sqrt_m.asDiagonal();
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(a, Eigen::EigenvaluesOnly);
  return eig.eigenvalues().cwiseMax(0.0).cwiseSqrt();
}

double fundamental_frequency(const Frame& frame) { return natural_frequencies(frame)(0); }

FundamentalMode fundamental_mode(const Frame& frame) {
  validate(frame);
  const Eigen::VectorXd m = Eigen::Map<const Eigen::VectorXd>(frame.mass.data(), frame.storeys());
  const auto [omega, phi] = normal_modes(frame);
  FundamentalMode mode;
  mode.omega = omega(0);
  mode.shape = phi.col(0);
  mode.shape /= mode.shape(frame.storeys() - 1);
  const double generalised_mass = mode.shape.dot(m.asDiagonal() * mode.shape);
  mode.damping_ratio =
      mode.shape.dot(damping_matrix(frame) * mode.shape) / (2.0 * mode.omega * generalised_mass);
  return mode;
}

std::vector<double> stiffness_proportional_damping(const Frame& frame, double damping_ratio) {
  const double w1 = fundamental_frequency(frame);
  std::vector<double> c(frame.stiffness.size());
  for (std::size_t i = 0; i < c.size(); ++i) c[i] = 2.0 * damping_ratio / w1 * frame.stiffness[i];
  return c;
}

}  // namespace poundsim
