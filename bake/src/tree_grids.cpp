#include "pine/bake/tree_grids.h"

namespace pine::bake {
namespace {

template <class GridT>
void setTyped(typename GridT::Ptr& member, const openvdb::GridBase::Ptr& grid, Field field)
{
    if (!grid) {
        member = nullptr;
        return;
    }
    member = openvdb::gridPtrCast<GridT>(grid);
    if (!member) {
        throw BakeError("grid '" + grid->getName() + "' has type " + grid->type() + ", expected " +
                        GridT::gridType() + " for field " + kFields[int(field)].name);
    }
}

}  // namespace

openvdb::GridBase::Ptr TreeGrids::grid(Field field) const
{
    switch (field) {
    case Field::Density: return density;
    case Field::LayerGradient: return layerGradient;
    case Field::LayerOpacity: return layerOpacity;
    case Field::NeedleDirection: return needleDirection;
    case Field::NeedleCoverage: return needleCoverage;
    case Field::NeedleAlbedo: return needleAlbedo;
    }
    return nullptr;
}

void TreeGrids::setGrid(Field field, const openvdb::GridBase::Ptr& grid)
{
    switch (field) {
    case Field::Density: return setTyped<openvdb::FloatGrid>(density, grid, field);
    case Field::LayerGradient: return setTyped<openvdb::Vec3SGrid>(layerGradient, grid, field);
    case Field::LayerOpacity: return setTyped<openvdb::FloatGrid>(layerOpacity, grid, field);
    case Field::NeedleDirection:
        return setTyped<openvdb::Vec3SGrid>(needleDirection, grid, field);
    case Field::NeedleCoverage: return setTyped<openvdb::FloatGrid>(needleCoverage, grid, field);
    case Field::NeedleAlbedo: return setTyped<openvdb::Vec3SGrid>(needleAlbedo, grid, field);
    }
}

double allocatedVoxels(const TreeGrids& g)
{
    if (!g.layerOpacity) return 0.0;
    const openvdb::FloatTree& tree = g.layerOpacity->tree();
    using Leaf = openvdb::FloatTree::LeafNodeType;
    return double(tree.leafCount()) * double(Leaf::SIZE) +
           double(tree.activeVoxelCount() - tree.activeLeafVoxelCount());
}

const char* unitName(LengthUnit unit) { return unit == LengthUnit::Metre ? "m" : "cm"; }

LengthUnit lengthUnit(const std::string& name)
{
    if (name == "m") return LengthUnit::Metre;
    if (name == "cm") return LengthUnit::Centimetre;
    throw BakeError("unknown length unit '" + name + "': expected 'm' or 'cm'");
}

}  // namespace pine::bake
