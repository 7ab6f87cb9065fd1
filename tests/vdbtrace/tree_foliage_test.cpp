// The "tree" AOV and the per-tree foliage measures (tree_foliage.h): each method names the tree
// its foliage comes from, checked against each tree rendered alone; regions and sums checked
// against direct computation on small images.
#include "pine/vdbtrace/tree_foliage.h"
#include "pine/scenes/scene.h"
#include "pine/vdbtrace/fragment.h"
#include "pine/vdbtrace/geometry_tracer.h"
#include "pine/vdbtrace/multiscale_tracer.h"
#include "pine/vdbtrace/traced_scene.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

namespace pine::vdbtrace {
namespace {

Image withPlanes(int w, int h, const std::vector<float>& tree, const std::vector<float>& foliage)
{
    Image image(w, h);
    image.aov("tree") = tree;
    image.aov("foliage") = foliage;
    return image;
}

TEST(TreeFoliage, RegionsTakeTheNearestNamedPixel)
{
    // 6 x 1: tree 3 at x = 0, tree 1 at x = 4; x = 2 is as near to both: the earlier pixel's.
    const Image row = withPlanes(6, 1, {3, -1, -1, -1, 1, -1}, std::vector<float>(6, 0.0f));
    EXPECT_EQ(treeRegions(row), (std::vector<int>{3, 3, 3, 1, 1, 1}));
    // Nothing named: nothing assigned.
    const Image none = withPlanes(2, 2, {-1, -1, -1, -1}, std::vector<float>(4, 0.0f));
    EXPECT_EQ(treeRegions(none), (std::vector<int>(4, -1)));
    EXPECT_THROW(treeRegions(Image(2, 2)), ImageError);
}

TEST(TreeFoliage, SumsOverEachRegion)
{
    // 3 x 2, regions {0 0 1 / 0 1 1}; luminance of grey g is g.
    Image image = withPlanes(3, 2, {0, 0, 1, 0, 1, 1}, {0.5f, 1.0f, 0.25f, 0.0f, 0.75f, 1.0f});
    const float grey[6] = {0.2f, 0.4f, 0.8f, 0.9f, 0.1f, 0.3f};
    for (int i = 0; i < 6; ++i) {
        for (int c = 0; c < 3; ++c) image.rgba[4 * i + c] = grey[i];
    }
    const std::vector<TreeFoliage> t =
        foliageByTree(image, treeRegions(image), FoliageLuminance::Pixels);
    ASSERT_EQ(t.size(), 2u);
    EXPECT_EQ(t[0].tree, 0);
    EXPECT_EQ(t[0].pixels, 3u);
    EXPECT_NEAR(t[0].coverage, 1.5, 1e-6);
    EXPECT_NEAR(t[0].luminance, (0.2 * 0.5 + 0.4 * 1.0) / 1.5, 1e-6);
    EXPECT_EQ(t[1].pixels, 3u);
    EXPECT_NEAR(t[1].coverage, 2.0, 1e-6);
    EXPECT_NEAR(t[1].luminance, (0.8 * 0.25 + 0.1 * 0.75 + 0.3 * 1.0) / 2.0, 1e-6);
    // Against itself: no bias; one tree darker by half: -50% luminance, same coverage.
    Image darker = image;
    for (int i : {2, 4, 5}) {
        for (int c = 0; c < 3; ++c) darker.rgba[4 * i + c] *= 0.5f;
    }
    const std::vector<TreeBias> b = treeBiases(darker, image, 0.0);
    ASSERT_EQ(b.size(), 2u);
    EXPECT_NEAR(b[0].luminanceBias, 0.0, 1e-9);
    EXPECT_NEAR(b[1].luminanceBias, -0.5, 1e-6);
    EXPECT_NEAR(b[1].coverageBias, 0.0, 1e-9);

    // The foliage's own luminance: its AOV summed over the region, over the coverage summed.
    Image own = image;
    own.aov("foliage_luminance") = {0.1f, 0.3f, 0.05f, 0.0f, 0.2f, 0.4f};
    EXPECT_TRUE(hasOwnFoliageLuminance(own));
    const std::vector<TreeFoliage> o = foliageByTree(own, treeRegions(own));
    EXPECT_NEAR(o[0].luminance, (0.1 + 0.3 + 0.0) / 1.5, 1e-6);
    EXPECT_NEAR(o[1].luminance, (0.05 + 0.2 + 0.4) / 2.0, 1e-6);
    // Measured the pixels' way unless both images have it.
    EXPECT_NEAR(treeBiases(own, image, 0.0)[0].luminanceBias, 0.0, 1e-9);
    EXPECT_THROW(foliageByTree(image, treeRegions(image)), ImageError);
}

// The three firs at low resolution, all of them or only tree `only`: the others moved behind
// the camera, so that every tree keeps its index and its needles.
scenes::Scene threeFirs(int only = -1)
{
    scenes::Scene s = scenes::loadScene(std::string(PINE_SOURCE_DIR) + "/scenes/three-firs.json");
    s.camera.width = 128;
    s.camera.height = 96;
    for (std::size_t i = 0; i < s.trees.size(); ++i) {
        if (only >= 0 && int(i) != only) s.trees[i].base_cm.y -= 1e5;
    }
    return s;
}

TEST(TreeFoliage, EveryMethodNamesTheTreeItsFoliageComesFrom)
{
    // Where only tree i's own render has foliage, the whole scene's "tree" AOV must say i; a
    // pixel no tree covers says -1. Rendered with the multiscale method (every level appears
    // on this scene) and explicit needles.
    for (const bool geometry : {false, true}) {
        const auto render = [&](const scenes::Scene& s) {
            const TracedScene t = buildTracedScene(s);
            GeometryOptions g;
            g.samples = 1;
            return geometry ? renderGeometry(t, g) : renderMultiscale(t);
        };
        const scenes::Scene all = threeFirs();
        const RenderResult whole = render(all);
        std::vector<std::vector<float>> alone;
        for (int i = 0; i < 3; ++i) alone.push_back(render(threeFirs(i)).image.aovs.at("foliage"));
        const std::vector<float>& tree = whole.image.aovs.at("tree");
        int checked = 0, empty = 0;
        for (std::size_t p = 0; p < tree.size(); ++p) {
            int only = -1, covering = 0;
            for (int i = 0; i < 3; ++i) {
                if (alone[std::size_t(i)][p] > 0.0f) {
                    only = i;
                    ++covering;
                }
            }
            if (covering == 0) {
                EXPECT_EQ(tree[p], -1.0f) << "pixel " << p;
                ++empty;
            } else if (covering == 1 && whole.image.aovs.at("foliage")[p] > 0.0f) {
                EXPECT_EQ(tree[p], float(only)) << "pixel " << p << (geometry ? " geometry" : "");
                ++checked;
            }
        }
        EXPECT_GT(checked, 1000);
        EXPECT_GT(empty, 1000);
    }
}

TEST(TreeFoliage, TheFoliagesOwnLuminanceIsWhatFoliageFragmentsGive)
{
    // A branch half covering the footprint, then a needle fragment, then the ground: the
    // foliage gave what the needles reflect through the branch's gap, nothing of the others.
    FrontToBack c;
    c.add(Fragment{1.0, 0.5, Vec3(0.2), Vec3(0.0), 0, false, -1});
    c.add(Fragment{2.0, 0.4, Vec3(0.1, 0.2, 0.3), Vec3(0.04), 3, true, 0});
    c.add(Fragment{3.0, 1.0, Vec3(0.7), Vec3(0.0), 0, false, -1});
    const SampleValue v = c.value();
    EXPECT_NEAR(v.foliage, 0.5 * 0.4, 1e-12);
    EXPECT_NEAR(v.foliageLuminance, 0.5 * luminance(Vec3(0.14, 0.24, 0.34)), 1e-12);
}

TEST(TreeFoliage, TheFoliagesOwnLuminanceDoesNotSeeWhatLiesBehind)
{
    // The three firs with a white sky and ground, then black: each tree's own luminance is
    // unchanged (to float rounding), for explicit needles and the multiscale method alike,
    // where the pixels' measure moves with the backdrop wherever foliage covers a pixel in
    // part.
    for (const bool geometry : {false, true}) {
        std::vector<TreeFoliage> own[2], pixels[2];
        for (int dark = 0; dark < 2; ++dark) {
            scenes::Scene s = threeFirs();
            s.render.background = Vec3(dark ? 0.0 : 1.0);
            s.ground.albedo = Vec3(dark ? 0.0 : 1.0);
            const TracedScene t = buildTracedScene(s);
            GeometryOptions g;
            g.samples = 4;
            const Image image = geometry ? renderGeometry(t, g).image : renderMultiscale(t).image;
            const std::vector<int> regions = treeRegions(image);
            own[dark] = foliageByTree(image, regions, FoliageLuminance::Own);
            pixels[dark] = foliageByTree(image, regions, FoliageLuminance::Pixels);
        }
        ASSERT_EQ(own[0].size(), 3u);
        for (std::size_t k = 0; k < 3; ++k) {
            std::printf("%s tree %zu: own luminance %.5f / %.5f, the pixels' %.5f / %.5f (white "
                        "/ black backdrop)\n",
                        geometry ? "geometry" : "multiscale", k, own[0][k].luminance,
                        own[1][k].luminance, pixels[0][k].luminance, pixels[1][k].luminance);
            EXPECT_NEAR(own[0][k].luminance / own[1][k].luminance, 1.0, 1e-5);
            EXPECT_GT(pixels[0][k].luminance / pixels[1][k].luminance, 1.02);
        }
    }
}

}  // namespace
}  // namespace pine::vdbtrace
