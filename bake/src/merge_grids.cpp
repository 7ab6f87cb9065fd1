#include "pine/bake/tree_grids.h"

#include <algorithm>
#include <cmath>
#include <optional>

namespace pine::bake {
namespace {

// Calls visit(ijk, value) for every active voxel of `grid`, a tile's one by one: a bake prunes
// its grids, so a leaf of one value (a species' albedo, a bough's layer opacity, one tree) is
// written and read as a tile.
template <class GridT, class Visit>
void forEachActiveVoxel(const GridT& grid, Visit&& visit)
{
    for (auto it = grid.cbeginValueOn(); it; ++it) {
        if (it.isVoxelValue()) {
            visit(it.getCoord(), *it);
            continue;
        }
        const openvdb::CoordBBox box = it.getBoundingBox();
        for (auto ijk = box.begin(); ijk; ++ijk) visit(*ijk, *it);
    }
}

// Copies into `into` the active voxels of `from` where `occupied` has none.
template <class GridT>
void fillInactiveTyped(GridT& into, const GridT& from, const openvdb::FloatGrid& occupied)
{
    auto out = into.getAccessor();
    auto taken = occupied.getConstAccessor();
    forEachActiveVoxel(from, [&](const openvdb::Coord& c, const typename GridT::ValueType& v) {
        if (!taken.isValueOn(c)) out.setValue(c, v);
    });
}

void fillInactive(const FieldInfo& info, const TreeGrids& into, const TreeGrids& from,
                  const openvdb::FloatGrid& occupied)
{
    if (info.vector) {
        fillInactiveTyped(static_cast<openvdb::Vec3SGrid&>(*into.grid(info.field)),
                          static_cast<const openvdb::Vec3SGrid&>(*from.grid(info.field)), occupied);
    } else {
        fillInactiveTyped(static_cast<openvdb::FloatGrid&>(*into.grid(info.field)),
                          static_cast<const openvdb::FloatGrid&>(*from.grid(info.field)), occupied);
    }
}

/// Where `from` and the trees before it (`occupied`) both hold a voxel, their needles are all
/// there, as where one tree's boughs overlap (bakeBoughs): the densities add, and the layered
/// fields are the denser's there (this tree's or the sum of those before it), its layer
/// gradient scaled by the sum over its own, and the voxel names the tree whose fields it keeps
/// (TreeGrids::tree).
void addOverlaps(const TreeGrids& into, const TreeGrids& from, const openvdb::FloatGrid& occupied)
{
    auto density = into.density->getAccessor();
    auto gradient = into.layerGradient->getAccessor();
    auto opacity = into.layerOpacity->getAccessor();
    auto needle = into.needleDirection->getAccessor();
    auto coverage = into.needleCoverage->getAccessor();
    auto albedo = into.needleAlbedo->getAccessor();
    const auto taken = occupied.getConstAccessor();
    const auto theirGradient = from.layerGradient->getConstAccessor();
    const auto theirOpacity = from.layerOpacity->getConstAccessor();
    const auto theirNeedle = from.needleDirection->getConstAccessor();
    const auto theirCoverage = from.needleCoverage->getConstAccessor();
    const auto theirAlbedo = from.needleAlbedo->getConstAccessor();
    std::optional<openvdb::Int32Grid::Accessor> tree;
    std::optional<openvdb::Int32Grid::ConstAccessor> theirTree;
    if (into.tree) tree = into.tree->getAccessor();
    if (from.tree) theirTree = from.tree->getConstAccessor();
    forEachActiveVoxel(*from.density, [&](const openvdb::Coord& c, float theirs) {
        if (!taken.isValueOn(c)) return;
        const float mine = density.getValue(c), sum = mine + theirs;
        if (theirs > mine) {
            gradient.setValue(c, theirGradient.getValue(c));
            opacity.setValue(c, theirOpacity.getValue(c));
            needle.setValue(c, theirNeedle.getValue(c));
            coverage.setValue(c, theirCoverage.getValue(c));
            albedo.setValue(c, theirAlbedo.getValue(c));
            if (tree) tree->setValue(c, theirTree ? theirTree->getValue(c) : -1);
        }
        const float kept = std::max(mine, theirs);
        if (kept > 0.0f) gradient.setValue(c, gradient.getValue(c) * (sum / kept));
        density.setValue(c, sum);
    });
}

}  // namespace

TreeGrids mergeTreeGrids(const std::vector<TreeGrids>& trees)
{
    if (trees.empty()) throw BakeError("no grids to merge");
    TreeGrids out;
    const TreeGrids& first = trees.front();
    out.voxelSize_cm = first.voxelSize_cm;
    out.extinctionLaw = first.extinctionLaw;
    for (const FieldInfo& info : kFields) {
        out.setGrid(info.field, first.grid(info.field)->deepCopyGrid());
    }
    // A tree index grid as soon as any input knows its trees; voxels of inputs that do not
    // stay -1 (unknown).
    if (std::any_of(trees.begin(), trees.end(), [](const TreeGrids& t) { return bool(t.tree); })) {
        out.tree = first.tree ? first.tree->deepCopy() : openvdb::Int32Grid::create(-1);
        out.tree->setTransform(first.density->transform().copy());
    }
    for (std::size_t i = 1; i < trees.size(); ++i) {
        const TreeGrids& t = trees[i];
        if (std::abs(t.voxelSize_cm - out.voxelSize_cm) > 1e-9 * out.voxelSize_cm) {
            throw BakeError("cannot merge grids of voxel sizes " +
                            std::to_string(out.voxelSize_cm) + " and " +
                            std::to_string(t.voxelSize_cm) + " cm");
        }
        if (t.extinctionLaw != out.extinctionLaw) {
            throw BakeError("cannot merge grids of extinction laws '" + out.extinctionLaw +
                            "' and '" + t.extinctionLaw + "'");
        }
        // What the trees before this one occupy, fixed while the fields are filled.
        const openvdb::FloatGrid::Ptr occupied = out.density->deepCopy();
        for (const FieldInfo& info : kFields) fillInactive(info, out, t, *occupied);
        if (t.tree) fillInactiveTyped(*out.tree, *t.tree, *occupied);
        addOverlaps(out, t, *occupied);
    }
    return out;
}

}  // namespace pine::bake
