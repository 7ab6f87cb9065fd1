// `vdbtrace animate-compare`: the scene's camera path rendered by each method, and the temporal
// report (flicker per method and per level band, a plot over the frames, a strip of frames).
#pragma once

#include "pine/vdbtrace/animation_flicker.h"
#include "pine/vdbtrace/frame_sequence.h"

#include <filesystem>
#include <functional>
#include <optional>

namespace pine::vdbtrace {

struct AnimationCompareOptions {
    std::filesystem::path sceneFile, outDir;
    std::optional<FrameRange> frames;  ///< none: the path's own [first, last]
    int width = 0, height = 0;         ///< override of the camera's resolution (0: the scene's)
    int stripFrames = 4;               ///< frames shown in strip.png, first to last
    /// > 0: a truth, geometry at this many samples a pixel on its own seed, and each method's
    /// error flicker against it (animation_flicker.h); 0: none.
    int truthSamples = 0;
    /// Adds "self_shadowing" where the scene's effects name "shadows" (as compare: the
    /// explicit needles always self-shadow, checkEffects).
    bool addSelfShadowing = false;
    std::function<void(scenes::RenderSettings&)> model;  ///< the command line's overrides
    double maxMemoryBytes = 0.0;  ///< refuse, before any work, a run estimated to need more
    std::string machine = "unknown machine";
    CompareLog log;
    /// Draws flicker_frames.png from frames.csv in the folder; true if it did. Null: no plot.
    std::function<bool(const std::filesystem::path& dir)> plot;
};

/// Renders the scene's camera path (at least 3 frames) with every kAnimationSequences entry
/// into `outDir` (created): flicker.csv (per method and level band), frames.csv (per frame),
/// strip.png (stripFrames frames of each method, a row each), report.md, and
/// flicker_frames.png if `plot` draws it. Throws InputError for a scene without camera_path,
/// fewer than 3 frames, effects the methods cannot share, an unwritable folder or too little
/// memory (before any work), and what rendering throws.
AnimationFlicker runAnimationCompare(const AnimationCompareOptions& options);

}  // namespace pine::vdbtrace
