// What a render or a bake will ask of the machine, estimated from the scene before any work
// (a 16384 x 16384 image, a forest of 100,000 trees or a 1e-3 cm voxel would otherwise end in
// std::bad_alloc after gigabytes): each species grown once and scaled by its placements.
#pragma once

#include "pine/scenes/scene.h"

#include <cstddef>
#include <limits>
#include <string>
#include <vector>

namespace pine::bake {

/// The most a directional light's shadow columns may take (vdbtrace's light_columns.h): the
/// tracer makes none above it (its shadow cones walk the BVH), and the estimate counts none.
inline constexpr std::size_t kShadowColumnsMax_bytes = std::size_t(96) << 20;

struct ResourceEstimate {
    struct Part {
        std::string what;  ///< "image 640 x 480", "2.45e+06 needle cylinders", ...
        double bytes = 0.0;
    };
    std::vector<Part> parts;
    double bytes() const;
    /// The largest part the user can lower (the program itself only when nothing else is).
    const Part& largest() const;
};

/// What the trees of `trees` (indices into scene.trees) hold, estimated by growing each
/// species once (its first placement among them stands for the others).
struct TreeTotals {
    double branches = 0.0, boughs = 0.0, needles = 0.0;
    double boughVolume_cm3 = 0.0;  ///< the cylinders the boughs' cones fill
};
TreeTotals estimateTrees(const scenes::Scene& scene, const std::vector<std::size_t>& trees);

/// The memory a render of `scene` by method `method` ("multiscale", "reference", "geometry")
/// will need, within a factor of about 1.5 of the peaks measured (docs/vdbtrace.md): the image
/// and its outputs, the trees as the tracer holds them, and the method's own (the multiscale
/// law profiles of every bough, or `lawProfileBudget_bytes` if less; the grown trees and the
/// explicit needles; the reference's voxels of `voxelSize_cm` with the light reaching each,
/// counted in the OpenVDB leaves that hold them (8^3 voxels allocated whole), or
/// with `voxelsRead` > 0, the voxels of the grids read (allocatedVoxels), held with the light
/// reaching each). Each species is grown once, for its first placement, which stands for all of
/// its placements.
/// With `instanceVariants` (the geometry method with Embree's curves), the needles of a
/// scatter's variant count once, whatever the trees that copy it (TreePlacement::variantOf).
ResourceEstimate estimateRender(
    const scenes::Scene& scene, const std::string& method, double voxelSize_cm,
    double voxelsRead = 0.0, bool instanceVariants = true,
    double lawProfileBudget_bytes = std::numeric_limits<double>::infinity());

/// The memory `vdbtrace compare` will need: the largest of its methods' renders (the reference
/// at `smallestVoxel_cm`), with `images` renders kept at once for the report.
ResourceEstimate estimateCompare(const scenes::Scene& scene, double smallestVoxel_cm,
                                 std::size_t images);

/// The memory a bake of `trees` (indices into scene.trees) at `voxelSize_cm` will need, with
/// up to `concurrent` trees in memory at once (each written before the next).
ResourceEstimate estimateBake(const scenes::Scene& scene, const std::vector<std::size_t>& trees,
                              double voxelSize_cm, std::size_t concurrent = 1);

/// 80% of the machine's physical memory, in bytes: --max-memory's default.
double defaultMemoryLimit();
/// --max-memory in GiB as bytes; 0 for defaultMemoryLimit().
double memoryLimit(double gib);

/// A count in a message: whole below a million, then as "1.2e+07"; "more than 1e308" past any.
std::string formatCount(double n);

/// "1.5 GiB", "12 MiB", "3 KiB", "1e-291 bytes" (under a GiB rounded up), "an unbounded amount"
/// (not finite).
std::string formatBytes(double bytes);

/// Throws InputError naming the estimate's largest part when the whole exceeds `limitBytes`:
/// "TASK: WHAT needs about X (Y in all), more than --max-memory Z allows (...)".
void checkMemory(const ResourceEstimate& estimate, double limitBytes, const std::string& task);

}  // namespace pine::bake
