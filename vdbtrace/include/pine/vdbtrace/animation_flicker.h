// The methods rendered frame after frame along a moving camera, and the flicker of each
// sequence (flicker.h): the temporal part of `vdbtrace compare` (its dolly, dolly.h) and all of
// `vdbtrace animate-compare` (the scene's camera path, animation_report.h).
#pragma once

#include "pine/scenes/scene.h"
#include "pine/vdbtrace/compare_run.h"
#include "pine/vdbtrace/flicker.h"

#include <optional>
#include <string>
#include <vector>

namespace pine::vdbtrace {

/// A method and setting rendered along the frames.
struct AnimationSequence {
    const char* label;
    const char* method;
    int samples;  ///< geometry's samples per pixel (0: the method has none)
};
/// The paper's claim, section 7 and its video: the multiscale shaders do not flicker where a
/// ray tracer's few rays a pixel do (multiscale auto; geometry at 1 and 4 spp).
inline constexpr AnimationSequence kAnimationSequences[] = {{"multiscale_auto", "multiscale", 0},
                                                            {"geometry_1spp", "geometry", 1},
                                                            {"geometry_4spp", "geometry", 4}};

struct AnimationRow {
    std::string method;  ///< the sequence's label
    /// Over every pixel, by level band (levelBands of the multiscale frames, the same pixels
    /// for every method), and frame by frame.
    FlickerBreakdown flicker;
    /// With a truth: the flicker of this method's error, its frames less the truth's. The
    /// camera's motion is in both and cancels; what remains is how the method's error jumps
    /// from frame to frame (its aliasing), plus the truth's own noise.
    std::optional<FlickerBreakdown> errorFlicker;
    bool truth = false;               ///< the truth's own row (its flicker: the motion's)
    double secondsPerFrame = 0.0;     ///< the render's wall seconds (RenderResult::seconds)
    double cpuSecondsPerFrame = 0.0;  ///< the process's CPU seconds during the render
    std::vector<Image> kept;          ///< the frames asked to be kept, RGBA alone
};

struct AnimationFlicker {
    std::vector<AnimationRow> rows;  ///< one per kAnimationSequences, in order, then the truth
    int width = 0, height = 0;
};

/// Renders each sequence from every camera of `cameras` (the scene prepared again per frame:
/// each bough's shading sees the camera) and measures its flicker. Frames whose index is in
/// `keep` are kept in each row. `log` hears each frame. Throws ImageError with fewer than 3
/// cameras, and what preparing and rendering throw.
/// `window`: flickerBreakdown's (0: one line per pixel over the whole sequence; 3: the line
/// through each frame's neighbours). `truthSamples` > 0 adds a last row, geometry at that many
/// samples a pixel on its own sample seed, against which each method's error flickers.
AnimationFlicker measureAnimationFlicker(const scenes::Scene& scene,
                                         const std::vector<scenes::Camera>& cameras,
                                         const std::vector<int>& keep, int window, int truthSamples,
                                         const CompareLog& log);

}  // namespace pine::vdbtrace
