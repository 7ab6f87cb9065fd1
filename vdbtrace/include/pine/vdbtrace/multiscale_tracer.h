// `vdbtrace render --method multiscale`: one cone per pixel, each hit shaded by the closed
// form whose scale fits the footprint (paper section 3.2), partial coverages composited
// front to back.
#pragma once

#include "pine/vdbtrace/effects_plan.h"
#include "pine/vdbtrace/image.h"
#include "pine/vdbtrace/traced_scene.h"

#include <functional>

namespace pine::vdbtrace {

/// The level a bough hit is shaded at, from q = footprint width / cone spacing (RenderSettings).
enum class Level { Needle = 1, Cone = 2, Bough = 3 };
Level chooseLevel(double footprint_cm, double coneSpacing_cm, const scenes::RenderSettings& s);

struct RenderOptions {
    int tileSize = 16;
    /// Called from worker threads with the fraction done, at most every 2%.
    std::function<void(double)> progress;
    /// Forces every bough hit to this level (0: choose by footprint) - for comparisons.
    int forceLevel = 0;
};

struct RenderResult {
    Image image;  ///< RGBA plus AOVs "level", "depth", "diffuse", "specular", "foliage"
    RenderStats stats;
    double seconds = 0.0;
};

RenderResult renderMultiscale(const TracedScene& scene, const RenderOptions& options = {});

}  // namespace pine::vdbtrace
