// A tree's baked proxy: OpenVDB grids of its boughs' layer field, written so that other tools
// open them (vdb_print, vdb_render, Houdini, Blender) and so that a damaged file is refused
// before OpenVDB reads it (DESIGN.md).
#pragma once

#include "pine/bake/layer_field.h"

#include <openvdb/openvdb.h>

#include <filesystem>
#include <stdexcept>
#include <string>
#include <vector>

namespace pine::bake {

class BakeError : public std::runtime_error {
public:
    using std::runtime_error::runtime_error;
};

/// Grid names, as written (density first, so tools that take the first grid find it).
namespace grid_names {
inline constexpr const char* kDensity = "density";                 ///< float, fog volume, in [0, 1]
inline constexpr const char* kLayerGradient = "layer_gradient";    ///< vec3s G, layers per cm
inline constexpr const char* kLayerOpacity = "layer_opacity";      ///< float A
inline constexpr const char* kNeedleDirection = "needle_direction";  ///< vec3s, unit
inline constexpr const char* kNeedleAlbedo = "needle_albedo";      ///< vec3s, linear RGB
}  // namespace grid_names

struct BakeSettings {
    double voxelSize_cm = 0.5;
    int pyramidLevels = 3;  ///< density at voxel sizes h, 2h, 4h, ...: "density_lod1", ...
};

/// A tree's grids in world space (cm), all on one transform of voxel size h, voxels sampled at
/// their centres. Where several boughs overlap a voxel keeps the one of largest mean
/// extinction. density = meanExtinction / densityScale_per_cm, so in [0, 1].
struct TreeGrids {
    openvdb::FloatGrid::Ptr density;
    openvdb::Vec3SGrid::Ptr layerGradient;
    openvdb::FloatGrid::Ptr layerOpacity;
    openvdb::Vec3SGrid::Ptr needleDirection;
    openvdb::Vec3SGrid::Ptr needleAlbedo;
    /// Coarser densities, lod 1, 2, ...: lod k has voxels of 2^k h, each the mean of its 8
    /// children, centred on their mean centre (its own transform, shifted by (2^k - 1) h / 2).
    std::vector<openvdb::FloatGrid::Ptr> densityPyramid;
    double densityScale_per_cm = 0.0;  ///< extinction per cm of density 1
    double voxelSize_cm = 0.5;
};

/// Voxelizes the boughs (not the branches: the tracers draw those as cylinders). Boughs are
/// split among TBB threads; the result does not depend on the split (ties keep the bough listed
/// first). Throws BakeError for a voxel size that is not finite and > 0, pyramid levels
/// outside [1, 16], or a bough outside its domain (non-finite, phi outside (0, pi/2], a
/// negative size, dh <= 0); zero-size boughs bake to nothing.
TreeGrids bakeBoughs(const std::vector<BoughSpec>& boughs, const BakeSettings& settings);

/// File metadata: what made the grids.
struct BakeProvenance {
    std::string scene;
    int tree = -1;
    unsigned seed = 0;
};

/// Throws BakeError (one line naming the path and why) unless a file can be created at
/// `file`: its folder exists and takes a new file (tried, not guessed from permission bits).
/// For tools, to refuse before the work rather than after it. (added)
void checkWritable(const std::filesystem::path& file);

/// Writes the grids atomically (temporary file in the same folder, then rename) with file
/// metadata (units, extinction convention, voxel size, scene, tree, seed, tool version) and a
/// manifest `PATH.json` beside it recording the file's size and checksum. Throws BakeError.
void writeTreeGrids(const TreeGrids& grids, const std::filesystem::path& path,
                    const BakeProvenance& provenance);

/// Reads grids written by writeTreeGrids, after checking the manifest's size and checksum:
/// a damaged or foreign file is refused with BakeError, never opened by OpenVDB. Also catches
/// what OpenVDB throws.
TreeGrids readTreeGrids(const std::filesystem::path& path);

}  // namespace pine::bake

namespace pine::bake {

/// The grids of several trees as one set (what a renderer marches through): all must share a
/// voxel size (BakeError otherwise); where two overlap, the first keeps the voxel, as within a
/// tree. The density pyramid is not merged; density keeps the largest scale of the inputs.
TreeGrids mergeTreeGrids(const std::vector<TreeGrids>& trees);

}  // namespace pine::bake
