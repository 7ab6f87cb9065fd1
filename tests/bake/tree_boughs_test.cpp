// From a scene's grown tree to the boughs bake voxelizes.
#include "pine/bake/tree_boughs.h"
#include "pine/bake/tree_grids.h"
#include "pine/scenes/scene.h"
#include "pine/scenes/tree.h"

#include <gtest/gtest.h>

#include <cmath>

namespace pine::bake {
namespace {

TEST(TreeBoughs, FollowTheSegmentsAtMidBoughInTheTracersHue)
{
    // bough.json's needle parameters vary from base to tip: the spec takes their middle.
    const scenes::Scene scene = scenes::loadScene(PINE_SOURCE_DIR "/scenes/bough.json");
    const scenes::TreePlacement& placement = scene.trees.at(0);
    const scenes::Species& species = scene.species.at(placement.species);
    const scenes::Tree tree = scenes::growTree(species, placement);
    const std::vector<BoughSpec> specs = treeBoughs(tree);
    ASSERT_EQ(specs.size(), tree.boughs.size());
    ASSERT_GT(specs.size(), 0u);
    for (std::size_t i = 0; i < specs.size(); ++i) {
        const scenes::Bough& bough = tree.boughs[i];
        const scenes::Segment& segment = tree.segments[bough.segment];
        EXPECT_EQ(specs[i].base_cm, segment.base_cm);
        EXPECT_EQ(specs[i].tip_cm, segment.tip_cm);
        EXPECT_DOUBLE_EQ(specs[i].needles.cone.aperture_rad,
                         0.5 * (bough.atBase.aperture_rad + bough.atTip.aperture_rad));
        EXPECT_DOUBLE_EQ(specs[i].needles.cone.needleLength_cm,
                         0.5 * (bough.atBase.length_cm + bough.atTip.length_cm));
        EXPECT_DOUBLE_EQ(specs[i].needles.coneSpacing_cm,
                         0.5 * (bough.atBase.coneSpacing_cm + bough.atTip.coneSpacing_cm));
        // vdbtrace's hued(kNeedleHue, albedo): hue (0.45, 1, 0.35) scaled so green = albedo.
        EXPECT_DOUBLE_EQ(specs[i].needleAlbedo.y, species.needleAlbedo);
        EXPECT_DOUBLE_EQ(specs[i].needleAlbedo.x, 0.45 * species.needleAlbedo);
        EXPECT_DOUBLE_EQ(specs[i].needleAlbedo.z, 0.35 * species.needleAlbedo);
    }
    // And they bake: the region of each bough holds voxels.
    const TreeGrids grids = bakeBoughs(specs, BakeSettings{0.5, 1});
    EXPECT_GT(grids.density->activeVoxelCount(), 100u * specs.size());
}

TEST(TreeBoughs, EveryMethodDrawsWholeNeedlesPerCone)
{
    // The explicit needles draw a whole number a cone; the closed forms, layers and bake take
    // the same N through boughGeometry, so that a fractional per_cone (or one varying along a
    // branch, read at a bough's middle) is not 1.5 needles to one method and 2 to another.
    for (const auto& [perCone, drawn] : {std::pair{1.5, 2.0},
                                         {1.0, 1.0},
                                         {10.3, 10.0},
                                         {10.5, 11.0},
                                         {12.0, 12.0},
                                         {11.7, 12.0}}) {
        scenes::NeedleParameters p;
        p.perCone = perCone;
        EXPECT_EQ(boughGeometry(p).cone.needlesPerCone, drawn) << perCone;
    }
}

}  // namespace
}  // namespace pine::bake
