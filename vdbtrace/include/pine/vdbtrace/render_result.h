// What every method's render returns, and the options every method shares.
#pragma once

#include "pine/vdbtrace/image.h"
#include "pine/vdbtrace/render_stats.h"

#include <functional>

namespace pine::vdbtrace {

/// The AOVs every render writes beside RGBA, one float per pixel each (docs/vdbtrace.md):
/// "level" (coverage-weighted multiscale level in [1, 3], 0 where none shaded the pixel),
/// "depth" (cm, where the pixel's coverage passes 1/2; 0 where it never does), "diffuse" and
/// "specular" (luminance of each term), "foliage" (coverage by needles, at any scale), "tree"
/// (the index in the scene's trees of the tree whose foliage covers most of the pixel, -1
/// where none does or the method does not know: the reference's merged grids).
inline constexpr const char* kAovNames[] = {"level",   "depth",   "diffuse",
                                            "specular", "foliage", "tree"};

struct RenderOptions {
    int tileSize = 16;  ///< pixels along each side of a tile, the unit of parallel work
    /// Called from worker threads with the fraction done, at most every 2%.
    std::function<void(double)> progress;
};

struct RenderResult {
    Image image;  ///< premultiplied RGBA plus kAovNames
    RenderStats stats;
    double seconds = 0.0;      ///< wall clock, including what the method prepares first
    double prepSeconds = 0.0;  ///< of `seconds`, that preparation (BVH, bake, light grids)
};

}  // namespace pine::vdbtrace
