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
    const std::vector<TreeFoliage> t = foliageByTree(image, treeRegions(image));
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

}  // namespace
}  // namespace pine::vdbtrace
