#include "pine/bake/tree_grids.h"

#include <cmath>

namespace pine::bake {
namespace {

// Copies into `into` the active voxels of `from` where `into` has none yet.
template <class GridT>
void fillInactive(GridT& into, const GridT& from, const openvdb::FloatGrid& occupied)
{
    auto out = into.getAccessor();
    auto taken = occupied.getConstAccessor();
    for (auto it = from.cbeginValueOn(); it; ++it) {
        if (!it.isVoxelValue()) continue;  // baked grids hold voxels, not tiles
        if (!taken.isValueOn(it.getCoord())) out.setValue(it.getCoord(), *it);
    }
}

}  // namespace

TreeGrids mergeTreeGrids(const std::vector<TreeGrids>& trees)
{
    if (trees.empty()) throw BakeError("bake: no grids to merge");
    TreeGrids out;
    const TreeGrids& first = trees.front();
    out.voxelSize_cm = first.voxelSize_cm;
    out.density = first.density->deepCopy();
    out.layerGradient = first.layerGradient->deepCopy();
    out.layerOpacity = first.layerOpacity->deepCopy();
    out.needleDirection = first.needleDirection->deepCopy();
    out.needleAlbedo = first.needleAlbedo->deepCopy();
    out.densityScale_per_cm = first.densityScale_per_cm;
    for (std::size_t i = 1; i < trees.size(); ++i) {
        const TreeGrids& t = trees[i];
        if (std::abs(t.voxelSize_cm - out.voxelSize_cm) > 1e-9 * out.voxelSize_cm) {
            throw BakeError("bake: cannot merge grids of voxel sizes " +
                            std::to_string(out.voxelSize_cm) + " and " +
                            std::to_string(t.voxelSize_cm) + " cm");
        }
        // What the trees before this one occupy, fixed while the fields are filled.
        const openvdb::FloatGrid::Ptr occupied = out.layerOpacity->deepCopy();
        fillInactive(*out.layerGradient, *t.layerGradient, *occupied);
        fillInactive(*out.needleDirection, *t.needleDirection, *occupied);
        fillInactive(*out.needleAlbedo, *t.needleAlbedo, *occupied);
        fillInactive(*out.density, *t.density, *occupied);
        fillInactive(*out.layerOpacity, *t.layerOpacity, *occupied);
        out.densityScale_per_cm = std::max(out.densityScale_per_cm, t.densityScale_per_cm);
    }
    return out;
}

}  // namespace pine::bake
