#pragma once
/// @file
/// The paper's dimensionless description of two periodic frames and their gap elements
/// (Pasquino, Santini & Caliò, "Numerical applications"):
///
///     λ² = K1/M1   α = K2/K1   β = M2/M1   γ = C2/C1   ξ̄ = C1/(2 M1 λ)
///     δ̄ = δ λ²/g   η = k/K1    μ = c/(M1 λ)   ε̄ = ε λ²/g   and the restitution e
///
/// with g = 9.81 m/s². K, M, C are per storey and per floor, equal over each frame's height;
/// k, c are the same for every gap element. M1 is 1 kg unless given.
///
/// Example (the paper's Fig. 2c system):
/// @code
///   DimensionlessParameters p{.lambda2 = 200, .alpha = 0.25, .beta = 1, .gamma = 0.5, .xi = 0.05,
///                             .delta = 0.25, .eta = 0.125, .mu = 1, .epsilon = 0.5,
///                             .restitution = 0.75};
///   Model m = make_model(p, {1, 1});
/// @endcode

#include <array>
#include <optional>

#include "poundsim/fields.hpp"
#include "poundsim/model/model.hpp"

namespace poundsim {

struct DimensionlessParameters {
  double lambda2 = 0.0;       ///< λ² = K1/M1 [s⁻²], > 0.
  double alpha = 1.0;         ///< α = K2/K1, > 0.
  double beta = 1.0;          ///< β = M2/M1, > 0.
  double gamma = 1.0;         ///< γ = C2/C1, ≥ 0.
  double xi = 0.0;            ///< ξ̄ = C1/(2 M1 λ), ≥ 0.
  double delta = 0.0;         ///< δ̄ = δ λ²/g, ≥ 0.
  double eta = 0.0;           ///< η = k/K1, ≥ 0.
  double mu = 0.0;            ///< μ = c/(M1 λ), ≥ 0.
  double epsilon = 0.0;       ///< ε̄ = ε λ²/g, ≥ 0.
  double restitution = 1.0;   ///< e ∈ [0, 1].
  double mass1 = 1.0;         ///< M1 [kg], > 0: sets the scale of masses, forces and energies.

  /// The fields of a model file's [model.dimensionless] (fields.hpp); all but mass1 required.
  static constexpr auto fields() {
    using P = DimensionlessParameters;
    return std::tuple{
        NumberField{"lambda2", &P::lambda2, "s⁻²", positive, "λ² = K1/M1", true},
        NumberField{"alpha", &P::alpha, "", positive, "α = K2/K1", true},
        NumberField{"beta", &P::beta, "", positive, "β = M2/M1", true},
        NumberField{"gamma", &P::gamma, "", non_negative, "γ = C2/C1", true},
        NumberField{"xi", &P::xi, "", non_negative, "ξ̄ = C1/(2 M1 λ)", true},
        NumberField{"delta", &P::delta, "", non_negative, "δ̄ = δ λ²/g", true},
        NumberField{"eta", &P::eta, "", non_negative, "η = k/K1", true},
        NumberField{"mu", &P::mu, "", non_negative, "μ = c/(M1 λ)", true},
        NumberField{"epsilon", &P::epsilon, "", non_negative, "ε̄ = ε λ²/g", true},
        NumberField{"restitution", &P::restitution, "", unit_interval, "e", true},
        NumberField{"mass1", &P::mass1, "kg", positive, "M1, the scale of masses, forces and energies"},
    };
  }
  /// The physical values to_physical makes must be finite: each product that overflows is
  /// named with the keys it is made of.
  [[nodiscard]] std::optional<FieldRule> rule_violation() const;
};

/// Physical values of the dimensionless description.
struct PhysicalParameters {
  double m1, k1, c1;  ///< Frame 1: floor mass [kg], storey stiffness [N/m], storey dashpot [N·s/m].
  double m2, k2, c2;  ///< Frame 2, likewise.
  GapProperties gap;  ///< The gap elements.
};

/// Maps the dimensionless parameters to physical ones. Throws std::invalid_argument naming the
/// parameter when one is out of range.
PhysicalParameters to_physical(const DimensionlessParameters& p);

/// The inverse of to_physical for two uniform frames (used to report dimensionless values).
DimensionlessParameters to_dimensionless(const PhysicalParameters& p);

/// Two uniform frames with `storeys` floors each, joined by identical gap elements.
Model make_model(const DimensionlessParameters& p, std::array<int, 2> storeys);

}  // namespace poundsim
