// What the corrected law (corrected_bough_law.cpp) reads of the exact law beyond BoughLaw: its
// cells and the view's opacity split by the needles' azimuth.
#pragma once

#include "pine/vdbtrace/layer_model.h"
#include "pine/vdbtrace/traced_scene.h"

#include <vector>

namespace pine::vdbtrace {

/// Cells across the strip of each of the exact law's profiles.
inline constexpr int kExactLawCells = 12;

/// The exact law's view opacity of b seen along unit V (makeExactBoughLaw(density)), split by
/// which needles show: [half (front, rear)][cell][bin], bins of the needles' azimuth about the
/// axis evenly over (-pi, pi], measured from e_v = b.across x b.axis towards b.across. Without
/// self-shadowing what a light makes each half reflect is the sum over the bins of the share
/// times eqs. 1-2 at the bin's needle direction, whatever the light. Cells whose halves add up
/// past 1 are scaled back as shade() scales them. @throw std::invalid_argument for no bins.
std::vector<double> exactSeenByAzimuth(const TracedBough& b, const Vec3& V,
                                       const LayerModel& layers, int density, int bins);

}  // namespace pine::vdbtrace
