#pragma once
/// @file
/// The separation distances of adjacent frames: at every pair of facing floors, the smallest
/// joint that avoids contact, from the frames' free responses, beside the code rules built from
/// their free peaks — the absolute sum, SRSS, 0.7 SRSS for floors at the same levels (EC8
/// §4.4.2.7) and the double difference combination (DDC, Jeng et al. 1992; Penzien 1997) with
/// the fundamental modes' correlation. docs/records.md explains them.

#include <cstddef>
#include <optional>
#include <vector>

#include "poundsim/integrate/response_monitor.hpp"
#include "poundsim/model/model.hpp"

namespace poundsim {

/// The correlation coefficient of two modes (ω [rad/s], ζ) under broad-band excitation
/// (Der Kiureghian's CQC coefficient), used by the double-difference combination (DDC) of
/// separation distances: Δ = √(u_A² + u_B² − 2ρ u_A u_B).
[[nodiscard]] double modal_correlation(double omega_a, double zeta_a, double omega_b, double zeta_b);

/// The separation at one pair of facing floors [m]: the smallest gap that avoids contact (exact
/// for linear frames up to the integrator) and the code rules from the free peaks.
struct FloorSeparation {
  std::size_t index = 0;                        ///< In ResponseStatistics::neighbours
  const NeighbourResponse* neighbour = nullptr;  ///< The free run's
  double min_gap = 0, left_peak = 0, right_peak = 0, correlation = 0, absolute_sum = 0, srss = 0, ddc = 0;
  /// 0.7 SRSS, for floors at the same levels; none for a slab facing a column, where the codes'
  /// reduction does not apply.
  std::optional<double> srss_same_levels;
};

/// The separation at every pair of facing floors of `model`, from its frames' free response
/// `free` (ResponseStatistics of the run without gap elements, numbered by `layout`).
[[nodiscard]] std::vector<FloorSeparation> separations(const Model& model, const DofLayout& layout,
                                                       const ResponseStatistics& free);

}  // namespace poundsim
