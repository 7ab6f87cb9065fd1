// What every method's render returns, and the options every method shares.
#pragma once

#include "pine/vdbtrace/image.h"
#include "pine/vdbtrace/render_stats.h"
#include "pine/vdbtrace/tree_foliage_tally.h"

#include <functional>
#include <string>
#include <vector>

namespace pine::vdbtrace {

/// The AOVs every render writes beside RGBA, one float per pixel each (docs/vdbtrace.md):
/// "level" (coverage-weighted multiscale level in [1, 3], 0 where none shaded the pixel),
/// "depth" (cm along the ray, where the pixel's coverage passes 1/2; +infinity where it never
/// does), "diffuse" and
/// "specular" (luminance of each term), "foliage" (coverage by needles, at any scale), "tree"
/// (the index in the scene's trees of the tree whose foliage covers most of the pixel, -1
/// where none does or the method does not know: the reference's merged grids).
inline constexpr const char* kAovNames[] = {"level",   "depth",   "diffuse",         "specular",
                                            "foliage", "tree",    "foliage_luminance"};

/// A rectangle of the camera's pixels, [x0, x1) x [y0, y1), row 0 at the top.
struct PixelWindow {
    int x0 = 0, y0 = 0, x1 = 0, y1 = 0;
    bool empty() const { return x1 <= x0 || y1 <= y0; }
};

struct RenderOptions {
    int tileSize = 16;  ///< pixels along each side of a tile, the unit of parallel work
    /// Only these pixels (a crop), each as the whole frame would have it; empty: all.
    PixelWindow window;
    /// Called from worker threads with the fraction done, at most every 2%.
    std::function<void(double)> progress;
    /// What a method prepares before its pixels, where that is long (the reference's light
    /// grids): the stage's name and its fraction done, from worker threads, at most every 1%.
    std::function<void(const std::string& stage, double fraction)> preparing;
};

struct RenderResult {
    Image image;  ///< premultiplied RGBA plus kAovNames
    RenderStats stats;
    double seconds = 0.0;      ///< wall clock, including what the method prepares first
    double prepSeconds = 0.0;  ///< of `seconds`, that preparation (BVH, bake, light grids)
    /// Each tree's foliage, fragment by fragment (tree_foliage_tally.h); empty where the
    /// method knows no trees (a reference through files that name none).
    std::vector<TreeFoliageSum> treeFoliage;
};

}  // namespace pine::vdbtrace
