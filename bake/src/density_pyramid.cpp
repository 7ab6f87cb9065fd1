#include "density_pyramid.h"

#include "box_opacity.h"

namespace pine::bake::detail {

openvdb::FloatGrid::Ptr halveResolution(const openvdb::FloatGrid& fine)
{
    openvdb::math::Transform::Ptr xform = fine.transform().copy();
    // The children's fine centres, 2I + {0, 1}, average to 2I + 1/2: coarse index I maps to
    // fine index 2I + 1/2 (each pre-operation acts on the index before what was there).
    xform->preTranslate(openvdb::Vec3d(0.5));
    xform->preScale(2.0);

    // The coarse voxel's mean chord, in the grid's length unit (density is per that unit).
    const double chord = kMeanChordOverSize * 2.0 * fine.voxelSize()[0];
    auto coarse = openvdb::FloatGrid::create(0.0f);
    coarse->setTransform(xform);
    auto acc = coarse->getAccessor();
    for (auto it = fine.cbeginValueOn(); it; ++it) {
        // A tile (pruned constant region) stands for all its voxels.
        openvdb::CoordBBox box;
        it.getBoundingBox(box);
        const float opacity = float(opacityOver(double(*it), chord) * 0.125);
        for (auto ijk = box.begin(); ijk; ++ijk) {
            // Arithmetic shift: floor division by 2, right for negative indices too.
            const openvdb::Coord c((*ijk).x() >> 1, (*ijk).y() >> 1, (*ijk).z() >> 1);
            acc.setValue(c, acc.getValue(c) + opacity);
        }
    }
    for (auto it = coarse->beginValueOn(); it; ++it) {
        it.setValue(float(extinctionStopping(double(*it), chord)));
    }
    return coarse;
}

}  // namespace pine::bake::detail
