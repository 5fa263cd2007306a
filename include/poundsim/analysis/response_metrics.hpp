#pragma once
/// @file
/// Figures of merit of a response, for parametric studies and the optimiser: the peak of each
/// frame's base shear over a band of frequencies, and the model references they are compared
/// with — the frames free (no gap elements) and bare pounding (gap elements without spring,
/// dashpot or stroke: k = c = ε = 0, same gap and restitution).

#include <vector>

#include "poundsim/analysis/frequency_response.hpp"
#include "poundsim/model/model.hpp"

namespace poundsim {

/// The same frames with every gap element replaced by a rigid stop (the paper's element with
/// k = c = ε = 0) at its gap, with its law's restitution — except a slab striking a column, which
/// keeps its contact law (impacts with restitution act between floors: docs/model.md#slab-to-column).
[[nodiscard]] Model bare_pounding(const Model& model);

/// The same frames without gap elements.
[[nodiscard]] Model free_frames(const Model& model);

/// Weight of frame 1 [N] (the paper's normalisation W).
[[nodiscard]] double reference_weight(const Model& model);

/// The largest steady-state |V| of each frame over lo ≤ ω̄/ω₁ ≤ hi, all branches, divided by W;
/// and the same for the free frames. Frames without a point in the band get 0.
struct BandPeaks {
  std::vector<double> interacting;     ///< max V/W per frame
  std::vector<double> interacting_at;  ///< ω̄/ω₁ where it occurs
  std::vector<double> free;            ///< max V_free/W per frame
  int points = 0;                      ///< frequencies in the band
  int non_periodic = 0;                ///< of which not periodic
};
[[nodiscard]] BandPeaks band_peaks(const Model& model, const std::vector<FrfPoint>& points,
                                   double lo, double hi);

}  // namespace poundsim
