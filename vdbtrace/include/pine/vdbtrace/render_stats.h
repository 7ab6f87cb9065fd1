// What a render counted: a switched-off effect costs nothing (DESIGN.md), and the stats prove
// it. Integers only, so that sums over tiles do not depend on the order threads finish in.
#pragma once

#include <cstdint>

namespace pine::vdbtrace {

struct RenderStats {
    std::uint64_t coneRays = 0;         ///< camera rays: one per pixel, or per sub-ray / sample
    std::uint64_t shadowRays = 0;       ///< shadow rays (cones or, for geometry, point rays)
    /// Light attenuated by a bough's own layers: a counted march at levels 1-2, section 6.6's
    /// brackets at level 3.
    std::uint64_t selfShadowEvaluations = 0;
    std::uint64_t needleHits = 0;       ///< level 1: explicit needles covering a footprint
    std::uint64_t coneHits = 0;         ///< level 2: cone surfaces crossed
    std::uint64_t boughHits = 0;        ///< level 3: boughs shaded as volumes
    std::uint64_t branchHits = 0;
    std::uint64_t groundHits = 0;
    std::uint64_t voxelSpans = 0;       ///< reference method: voxel spans integrated
    std::uint64_t diffuseEvaluations = 0;
    std::uint64_t specularEvaluations = 0;
    std::uint64_t pixelsPerLevel[4] = {0, 0, 0, 0};  ///< by the level covering most: 0 = none
    std::uint64_t nanosecondsPerLevel[4] = {0, 0, 0, 0};  ///< time of those pixels

    RenderStats& operator+=(const RenderStats& o);
};

}  // namespace pine::vdbtrace
