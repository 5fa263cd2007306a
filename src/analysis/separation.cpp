#include "poundsim/analysis/separation.hpp"

#include <algorithm>
#include <cmath>

namespace poundsim {

double modal_correlation(double omega_a, double zeta_a, double omega_b, double zeta_b) {
  const double r = omega_b / omega_a;
  const double numerator = 8 * std::sqrt(zeta_a * zeta_b) * (zeta_a + r * zeta_b) * std::pow(r, 1.5);
  const double denominator = (1 - r * r) * (1 - r * r) + 4 * zeta_a * zeta_b * r * (1 + r * r) +
                             4 * (zeta_a * zeta_a + zeta_b * zeta_b) * r * r;
  return denominator > 0 ? numerator / denominator : 1.0;
}

std::vector<FloorSeparation> separations(const Model& model, const DofLayout& layout, const ResponseStatistics& free) {
  std::vector<FloorSeparation> out;
  std::vector<FundamentalMode> modes;
  for (const Frame& fr : model.frames) modes.push_back(fundamental_mode(fr));
  for (std::size_t k = 0; k < free.neighbours.size(); ++k) {
    const NeighbourResponse& nb = free.neighbours[k];
    const int f = nb.left_frame, i = nb.floor;
    // A column point's peak is bounded by its floors' peaks interpolated to its height (the
    // codes interpolate displacements over a storey likewise).
    const auto peak_at = [&](int frame, int floor, bool column) {
      const double above = free.floors[static_cast<std::size_t>(layout.dof(frame, floor))].displacement.value;
      if (!column) return above;
      const double w = nb.column->weight;
      const double below = floor == 0 ? 0.0 : free.floors[static_cast<std::size_t>(layout.dof(frame, floor - 1))].displacement.value;
      return w * above + (1 - w) * below;
    };
    FloorSeparation sep;
    sep.index = k;
    sep.neighbour = &nb;
    sep.min_gap = std::max(0.0, nb.max_approach);
    sep.left_peak = peak_at(f, i, nb.column && nb.column->struck == Side::left);
    sep.right_peak = peak_at(f + 1, nb.right_floor, nb.column && nb.column->struck == Side::right);
    const FundamentalMode& a = modes[static_cast<std::size_t>(f)];
    const FundamentalMode& b = modes[static_cast<std::size_t>(f + 1)];
    sep.correlation = modal_correlation(a.omega, a.damping_ratio, b.omega, b.damping_ratio);
    const double u1 = sep.left_peak, u2 = sep.right_peak;
    sep.absolute_sum = u1 + u2;
    sep.srss = std::hypot(u1, u2);
    sep.ddc = std::sqrt(std::max(0.0, u1 * u1 + u2 * u2 - 2 * sep.correlation * u1 * u2));
    // The 0.7 SRSS of floors at the same levels does not apply to a slab facing a column.
    if (!nb.column) sep.srss_same_levels = 0.7 * sep.srss;
    out.push_back(sep);
  }
  return out;
}

}  // namespace poundsim
