#pragma once
/// @file
/// A planar shear-type frame (Pasquino, Santini & Caliò, Fig. 1).
///
/// Floors are numbered 1..n from the ground up; internally they are 0-based. Floor i carries the
/// lumped mass M_i [kg]; storey i, between floor i−1 and floor i (floor 0 is the ground), has the
/// lateral stiffness K_i [N/m] and the viscous dashpot C_i [N·s/m]. The degrees of freedom are the
/// floor displacements relative to the ground, positive to the right.
///
/// Example:
/// @code
///   Frame f = make_uniform_frame(3, /*mass=*/1.0, /*stiffness=*/400.0, /*damping=*/2.0);
///   double w1 = fundamental_frequency(f);  // rad/s
/// @endcode

#include <string>
#include <vector>

#include <Eigen/Core>

#include "poundsim/fields.hpp"
#include "poundsim/model/law.hpp"

namespace poundsim {

struct Frame {
  std::string name;               ///< Optional label, used in messages only.
  std::vector<double> mass;       ///< M_i [kg] of each floor, bottom up; M_i > 0.
  std::vector<double> stiffness;  ///< K_i [N/m] of the storey below floor i; K_i > 0.
  std::vector<double> damping;    ///< C_i [N·s/m] of the storey below floor i; C_i ≥ 0.
  /// h_i [m] of each storey, for interstorey drift ratios; empty when not given.
  std::vector<double> storey_height;
  /// Dashpots from each floor to the ground [N·s/m] (the mass-proportional part a₀M_i of
  /// Rayleigh damping); empty when none.
  std::vector<double> ground_damping;
  /// ζ_k of modal damping, one per mode (lowest first); empty when none. It adds the damping
  /// matrix C_m = M Φ diag(2ζ_k ω_k / μ_k) Φᵀ M (μ_k = φ_kᵀMφ_k), which couples every floor of the
  /// frame, to the storey and ground dashpots (frame_damping_matrix).
  std::vector<double> modal_damping_ratios;
  /// The storeys' law and each storey's parameters besides K_i and C_i (law.hpp); the linear
  /// storey by default.
  StoreyLawParameters storey_law;

  [[nodiscard]] int storeys() const { return static_cast<int>(mass.size()); }
  [[nodiscard]] bool operator==(const Frame&) const = default;

  /// The per-storey values a model file gives ([[frames]], docs/input.md); damping may instead
  /// come from a damping ratio, a rule of the reader's.
  static constexpr auto fields() {
    using F = PerStoreyField<Frame>;
    return std::tuple{
        F{"mass", &Frame::mass, "kg", positive, "floor masses M_i", true, "floor"},
        F{"stiffness", &Frame::stiffness, "N/m", positive, "storey stiffnesses K_i", true},
        F{"damping", &Frame::damping, "N·s/m", non_negative, "storey dashpots C_i"},
        F{"storey_height", &Frame::storey_height, "m", positive, "storey heights h_i"},
        F{"ground_damping", &Frame::ground_damping, "N·s/m", non_negative,
          "dashpots from each floor to the ground (Rayleigh's a₀M_i)", false, "floor"},
        F{"modal_damping_ratios", &Frame::modal_damping_ratios, "", below_one,
          "ζ_k of modal damping, per mode (one number: every mode)", false, "mode"},
    };
  }
};

/// A frame whose floors and storeys are all equal (the paper's "periodic" frames).
Frame make_uniform_frame(int storeys, double mass, double stiffness, double damping,
                         std::string name = {});

/// Throws std::invalid_argument naming the field when the frame is not physical: no storeys,
/// vectors of different lengths, M_i ≤ 0, K_i ≤ 0, C_i < 0 or any non-finite value, storey-law
/// parameters for another number of storeys, out of their ranges or breaking their rules.
void validate(const Frame& frame);

/// Total weight of the frame, g·ΣM_i [N] with g the standard gravity; the paper's W.
[[nodiscard]] double weight(const Frame& frame);

/// Tridiagonal stiffness matrix of the frame alone on a fixed base [N/m].
Eigen::MatrixXd stiffness_matrix(const Frame& frame);
/// The frame's damping matrix [N·s/m]: its storey dashpots (tridiagonal) plus
/// frame_damping_matrix.
Eigen::MatrixXd damping_matrix(const Frame& frame);
/// The damping that is not a storey's: diag(ground_damping) plus the modal damping matrix (dense)
/// [N·s/m]; zero when the frame has neither.
Eigen::MatrixXd frame_damping_matrix(const Frame& frame);
/// Whether the frame has damping besides its storey dashpots (ground or modal).
[[nodiscard]] bool has_frame_damping(const Frame& frame);

/// The damping ratio of each undamped mode, ζ_k = φ_kᵀCφ_k / (2 ω_k φ_kᵀMφ_k), lowest first.
Eigen::VectorXd modal_damping_ratios(const Frame& frame);

/// Rayleigh damping C = a₀M + a₁K with ratios ζ_i, ζ_j at modes i ≠ j (1-based):
/// a₀ = 2ω_iω_j(ζ_iω_j − ζ_jω_i)/(ω_j² − ω_i²), a₁ = 2(ζ_jω_j − ζ_iω_i)/(ω_j² − ω_i²).
struct RayleighCoefficients {
  double mass = 0.0;       ///< a₀ [1/s]
  double stiffness = 0.0;  ///< a₁ [s]
};
RayleighCoefficients rayleigh_coefficients(const Frame& frame, int mode_i, double ratio_i, int mode_j, double ratio_j);

/// Complex amplitudes U of the floors of the frame alone in steady state under the base
/// acceleration a_g = A sin(ω̄t): u(t) = Im(U e^{iω̄t}) with (K − ω̄²M + iω̄C) U = −M 1 A.
Eigen::VectorXcd harmonic_amplitudes(const Frame& frame, double amplitude, double omega);

/// Undamped natural circular frequencies [rad/s] of the frame alone on a fixed base, ascending.
Eigen::VectorXd natural_frequencies(const Frame& frame);

/// ω₁: the smallest natural circular frequency [rad/s].
double fundamental_frequency(const Frame& frame);

/// The fundamental mode of the frame alone: ω₁ [rad/s], its shape (unit top value) and its
/// damping ratio ζ₁ = φᵀCφ / (2 ω₁ φᵀMφ) (exact for proportional damping, the usual modal
/// estimate otherwise).
struct FundamentalMode {
  double omega = 0.0;
  Eigen::VectorXd shape;
  double damping_ratio = 0.0;
};
FundamentalMode fundamental_mode(const Frame& frame);

/// Storey dashpots that give the damping ratio ζ in the fundamental mode with damping proportional
/// to the storey stiffness, C_i = (2ζ/ω₁) K_i (a common engineering choice for shear frames).
std::vector<double> stiffness_proportional_damping(const Frame& frame, double damping_ratio);

}  // namespace poundsim
