// Tiles rendered in parallel, their stats summed, progress told: the render driver's loop
// (render_driver.cpp).
#pragma once

#include "pine/vdbtrace/progress_steps.h"
#include "pine/vdbtrace/render_stats.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <functional>
#include <mutex>

namespace pine::vdbtrace {

/// How many tiles of `tile` x `tile` pixels (at least 1 x 1) a width x height image has.
inline int tileCount(int width, int height, int tile)
{
    tile = std::max(1, tile);
    return ((width + tile - 1) / tile) * ((height + tile - 1) / tile);
}

/// Calls renderTile(k, x0, y0, x1, y1, stats) for every tile k in [0, tileCount) of `tile` x
/// `tile` pixels of a width x height image ([x0, x1) x [y0, y1)), in scanline order of the
/// tiles, in parallel. Each tile counts into its own stats, summed into `total`: integers, so
/// the sum does not depend on the order in which the tiles finish, and each pixel is computed
/// alone, so neither does the image. `progress` hears the fraction done, in steps of 2%.
template <class RenderTile>
void forEachTile(int width, int height, int tile, const std::function<void(double)>& progress,
                 RenderStats& total, RenderTile&& renderTile)
{
    tile = std::max(1, tile);
    const int tilesX = (width + tile - 1) / tile;
    const int tiles = tileCount(width, height, tile);
    std::mutex statsMutex;
    ProgressSteps steps(std::size_t(tiles), 50);
    tbb::parallel_for(0, tiles, [&](int k) {
        RenderStats stats;
        const int x0 = (k % tilesX) * tile, y0 = (k / tilesX) * tile;
        renderTile(k, x0, y0, std::min(x0 + tile, width), std::min(y0 + tile, height), stats);
        {
            std::lock_guard<std::mutex> lock(statsMutex);
            total += stats;
        }
        double fraction;
        if (steps.finished(fraction) && progress) progress(fraction);
    });
}

}  // namespace pine::vdbtrace
