#include "poundsim/analysis/response_metrics.hpp"


namespace poundsim {

Model bare_pounding(const Model& model) {
  Model bare = model;
  for (GapElement& g : bare.gaps) {
    // A slab striking a column keeps its contact law: a rigid stop's impacts act between floors.
    if (g.column) continue;
    // Whatever the element's law: the paper's rigid stop at its gap, with its restitution.
    const double restitution = std::visit([](const auto& law) { return law.restitution(); }, g.law);
    g.law = PaperGap{GapProperties{.gap = g.gap(), .restitution = restitution}};
  }
  return bare;
}

Model free_frames(const Model& model) {
  Model free = model;
  free.gaps.clear();
  return free;
}

double reference_weight(const Model& model) { return weight(model.frames.front()); }

BandPeaks band_peaks(const Model& model, const std::vector<FrfPoint>& points, double lo, double hi) {
  const auto frames = static_cast<std::size_t>(model.frame_count());
  const double w = reference_weight(model);
  BandPeaks b{std::vector<double>(frames, 0.0), std::vector<double>(frames, 0.0),
              std::vector<double>(frames, 0.0), 0, 0};
  // The band's ends are inclusive, to a relative 1e-12 (ratios computed as lo + i·step).
  const double low = lo * (1 - 1e-12), high = hi * (1 + 1e-12);
  for (const FrfPoint& p : points) {
    if (p.ratio < low || p.ratio > high) continue;
    ++b.points;
    if (p.periodicity == 0) ++b.non_periodic;
    for (std::size_t f = 0; f < frames; ++f) {
      if (p.interacting.base_shear[f] / w > b.interacting[f]) {
        b.interacting[f] = p.interacting.base_shear[f] / w;
        b.interacting_at[f] = p.ratio;
      }
      b.free[f] = std::max(b.free[f], p.free.base_shear[f] / w);
    }
  }
  return b;
}

}  // namespace poundsim
