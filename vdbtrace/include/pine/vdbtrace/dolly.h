// `vdbtrace compare`, the temporal part: the camera dollies away from its look-at point and
// each method renders every frame; the flicker of each sequence (flicker.h) is its aliasing.
#pragma once

#include "pine/scenes/scene.h"
#include "pine/vdbtrace/compare_run.h"

#include <string>
#include <vector>

namespace pine::vdbtrace {

struct FlickerRow {
    std::string method;
    double flicker = 0.0, secondsPerFrame = 0.0;
};

struct DollyFlicker {
    std::vector<FlickerRow> rows;  ///< multiscale (auto), geometry at 1 and 4 spp
    int width = 0, height = 0;     ///< of the frames
};

/// settings.frames frames, camera distance x 1 to x settings.dollyEnd, at the scene's
/// resolution / settings.frameDivisor, its shape kept and its short side no less than 8 pixels
/// where the scene's is not; the scene is prepared again per frame (the per-bough
/// shading depends on the camera). `log` hears each frame.
DollyFlicker measureDollyFlicker(const scenes::Scene& base, const CompareSettings& settings,
                                 const CompareLog& log);

}  // namespace pine::vdbtrace
