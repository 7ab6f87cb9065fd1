// The scene files we ship: each loads, and each is the scene the paper describes.
#include "test_support.h"

#include "pine/scenes/tree.h"

#include <gtest/gtest.h>
#include <glm/geometric.hpp>

#include <algorithm>
#include <fstream>
#include <sstream>
#include <set>

namespace pine::scenes {
namespace {

// Pixel rows of a point, for a pinhole camera as the scene describes it (y down).
struct Projector {
    explicit Projector(const Camera& c)
        : position(c.position_cm), forward(glm::normalize(c.lookAt_cm - c.position_cm)),
          right(glm::normalize(glm::cross(forward, c.up))), up(glm::cross(right, forward)),
          halfWidth(0.5 * c.width), halfHeight(0.5 * c.height),
          pixelsPerUnit(0.5 * c.height / std::tan(0.5 * c.fovY_rad))
    {
    }
    glm::dvec2 pixel(const Vec3& p) const
    {
        const Vec3 d = p - position;
        const double z = glm::dot(d, forward);
        return {halfWidth + pixelsPerUnit * glm::dot(d, right) / z,
                halfHeight - pixelsPerUnit * glm::dot(d, up) / z};
    }
    Vec3 position, forward, right, up;
    double halfWidth, halfHeight, pixelsPerUnit;
};

// On-screen height of a tree: from its base to the top of its trunk, in pixels.
double pixelHeight(const Projector& camera, const Tree& tree, const Vec3& base)
{
    double top = base.z;
    for (const Segment& s : tree.segments) top = std::max({top, s.base_cm.z, s.tip_cm.z});
    return camera.pixel(base).y - camera.pixel(Vec3(base.x, base.y, top)).y;
}

TEST(ShippedScenes, EveryFileLoads)
{
    std::set<std::string> found;
    for (const auto& entry : std::filesystem::directory_iterator(test::scenesDir())) {
        if (entry.path().extension() != ".json") continue;
        SCOPED_TRACE(entry.path().string());
        Scene scene;
        EXPECT_NO_THROW(scene = loadScene(entry.path()));
        found.insert(entry.path().filename().string());
        // Every tree grows, every species placed exists.
        for (const TreePlacement& p : scene.trees) {
            ASSERT_EQ(scene.species.count(p.species), 1u);
            EXPECT_FALSE(growTree(scene.species.at(p.species), p).segments.empty());
        }
    }
    for (const char* name : {"bough.json", "three-firs.json", "paper-forest.json", "hill.json"}) {
        EXPECT_EQ(found.count(name), 1u) << name << " missing";
    }
}

TEST(ShippedScenes, PaperForestIsFigure11)
{
    const Scene s = loadScene(test::scenesDir() / "paper-forest.json");
    EXPECT_EQ(s.camera.width, 640);
    EXPECT_EQ(s.camera.height, 480);
    ASSERT_EQ(s.trees.size(), 80u);
    EXPECT_TRUE(s.effects.diffuse && s.effects.shadows);
    EXPECT_FALSE(s.effects.specular || s.effects.selfShadowing);

    // Section 7: N = 12, r = 0.05 cm, l = 4.25 cm, phi = pi/8, dh = 0.9 cm.
    const Species& fir = s.species.at("fir");
    for (const NeedleParameters& p : {fir.needlesAtBase, fir.needlesAtTip}) {
        EXPECT_EQ(p.perCone, 12);
        EXPECT_EQ(p.radius_cm, 0.05);
        EXPECT_EQ(p.length_cm, 4.25);
        EXPECT_NEAR(p.aperture_rad, std::numbers::pi / 8, 1e-15);
        EXPECT_EQ(p.coneSpacing_cm, 0.9);
    }

    // "80 fir-trees that are about 127 pixels high for the closest and 64 for the farthest":
    // within 5%, the scatter being random.
    const Projector camera(s.camera);
    double lowest = 1e300, highest = 0.0;
    int inFrame = 0;
    for (const TreePlacement& p : s.trees) {
        const double h = pixelHeight(camera, growTree(fir, p), p.base_cm);
        lowest = std::min(lowest, h);
        highest = std::max(highest, h);
        const glm::dvec2 base = camera.pixel(p.base_cm);
        if (base.x >= 0 && base.x < s.camera.width && base.y - h < s.camera.height) ++inFrame;
    }
    EXPECT_NEAR(lowest, 64.0, 0.05 * 64.0);
    EXPECT_NEAR(highest, 127.0, 0.05 * 127.0);
    EXPECT_GE(inFrame, 72);  // nearly all in view; a few cut by the frame's edges
}

TEST(ShippedScenes, ThreeFirsNearMiddleFar)
{
    const Scene s = loadScene(test::scenesDir() / "three-firs.json");
    ASSERT_EQ(s.trees.size(), 3u);
    const Projector camera(s.camera);
    std::vector<double> heights;
    for (const TreePlacement& p : s.trees) {
        heights.push_back(pixelHeight(camera, growTree(s.species.at(p.species), p), p.base_cm));
    }
    // Very close (taller than the image), middle, far: each level of the paper in one image.
    EXPECT_GT(heights[0], 0.9 * s.camera.height);
    EXPECT_GT(heights[1], 100.0);
    EXPECT_LT(heights[1], 300.0);
    EXPECT_LT(heights[2], 60.0);
    EXPECT_TRUE(s.effects.diffuse && s.effects.specular && s.effects.shadows &&
                s.effects.selfShadowing);
}

TEST(ShippedScenes, HillTreesStandOnTheHill)
{
    const Scene s = loadScene(test::scenesDir() / "hill.json");
    EXPECT_EQ(s.ground.kind, Ground::Kind::Hill);
    ASSERT_FALSE(s.trees.empty());
    double highest = -1e300;
    for (const TreePlacement& p : s.trees) {
        EXPECT_EQ(p.base_cm.z, s.ground.heightAt(p.base_cm.x, p.base_cm.y));
        highest = std::max(highest, p.base_cm.z);
    }
    EXPECT_GT(highest, s.ground.height_cm + 0.5 * s.ground.hillPeak_cm);  // some up the slope
}

TEST(ShippedScenes, BoughIsOneBranchCloseUp)
{
    const Scene s = loadScene(test::scenesDir() / "bough.json");
    ASSERT_EQ(s.trees.size(), 1u);
    ASSERT_EQ(s.pointLights.size(), 1u);
    EXPECT_TRUE(s.directionalLights.empty());
    EXPECT_TRUE(s.effects.diffuse && s.effects.specular && s.effects.shadows &&
                s.effects.selfShadowing);
    const Tree t = growTree(s.species.at(s.trees[0].species), s.trees[0]);
    for (const Segment& seg : t.segments) EXPECT_EQ(seg.order, 1);
    // The bough and its needles fill much of the frame's width.
    const Projector camera(s.camera);
    const double left = camera.pixel(Vec3(t.boundsMin_cm.x, 0, 30)).x;
    const double right = camera.pixel(Vec3(t.boundsMax_cm.x, 0, 30)).x;
    EXPECT_GT(right - left, 0.6 * s.camera.width);
    EXPECT_GT(left, 0.0);
    EXPECT_LT(right, s.camera.width);
}

TEST(ShippedScenes, DocumentedExampleLoads)
{
    // docs/scene-format.md's example is a scene, so the format's description cannot drift from
    // the parser without this failing.
    std::ifstream in(test::scenesDir().parent_path() / "docs" / "scene-format.md");
    ASSERT_TRUE(in) << "docs/scene-format.md not found";
    std::stringstream text;
    text << in.rdbuf();
    const std::string doc = text.str(), open = "```json\n";
    const auto start = doc.find(open);
    ASSERT_NE(start, std::string::npos);
    const auto end = doc.find("```", start + open.size());
    ASSERT_NE(end, std::string::npos);
    const std::string example = doc.substr(start + open.size(), end - start - open.size());
    Scene s;
    ASSERT_NO_THROW(s = parseScene(example, "docs-example.json"));
    EXPECT_EQ(s.trees.size(), 11u);
    EXPECT_EQ(s.pointLights.size(), 1u);
    EXPECT_EQ(s.directionalLights.size(), 1u);
}

}  // namespace
}  // namespace pine::scenes
