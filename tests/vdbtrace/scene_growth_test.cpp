// `bench --grow`'s scenes: each axis grows what it names and nothing else, checked on the
// scenes the parser makes of the grown documents.
#include "pine/scenes/scene.h"
#include "pine/scenes/tree.h"
#include "pine/support/input_error.h"
#include "pine/vdbtrace/scene_growth.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cmath>
#include <fstream>
#include <string>

namespace pine::vdbtrace {
namespace {

nlohmann::json paperForest()
{
    std::ifstream in(std::string(PINE_SOURCE_DIR) + "/scenes/paper-forest.json");
    return nlohmann::json::parse(in);
}

scenes::Scene parsed(const nlohmann::json& document)
{
    return scenes::parseScene(document.dump(), "grown.json");
}

TEST(SceneGrowth, TreesInTheRegionMultiplyAndStayInIt)
{
    const nlohmann::json forest = paperForest();
    const scenes::Scene base = parsed(forest);
    const scenes::Scene grown = parsed(growScene(forest, GrowthAxis::TreesInRegion, 4.0));
    ASSERT_EQ(base.trees.size(), 80u);
    EXPECT_EQ(grown.trees.size(), 320u);
    const auto& region = forest["trees"][0]["scatter"]["region"];
    for (const scenes::TreePlacement& t : grown.trees) {
        EXPECT_GE(t.base_cm.x, region[0][0].get<double>());
        EXPECT_LE(t.base_cm.x, region[1][0].get<double>());
        EXPECT_GE(t.base_cm.y, region[0][1].get<double>());
        EXPECT_LE(t.base_cm.y, region[1][1].get<double>());
    }
    EXPECT_DOUBLE_EQ(grown.camera.fovY_rad, base.camera.fovY_rad);
    EXPECT_EQ(grown.camera.width, base.camera.width);
}

TEST(SceneGrowth, TreesAtTheSameDensityFillARegionGrowingAwayFromTheCamera)
{
    const nlohmann::json forest = paperForest();
    const nlohmann::json grown = growScene(forest, GrowthAxis::TreesAtDensity, 4.0);
    const scenes::Scene s = parsed(grown);
    EXPECT_EQ(s.trees.size(), 320u);
    const auto& before = forest["trees"][0]["scatter"]["region"];
    const auto& after = grown["trees"][0]["scatter"]["region"];
    const auto area = [](const nlohmann::json& r) {
        return (r[1][0].get<double>() - r[0][0].get<double>()) *
               (r[1][1].get<double>() - r[0][1].get<double>());
    };
    // Four times the trees on four times the area; the edge nearest the camera (which stands
    // at y = 0, in front of the region) stays where it was, centred on the camera's x.
    EXPECT_NEAR(area(after) / area(before), 4.0, 1e-12);
    EXPECT_DOUBLE_EQ(after[0][1].get<double>(), before[0][1].get<double>());
    EXPECT_NEAR(after[0][0].get<double>() + after[1][0].get<double>(), 0.0, 1e-9);
    double farthest = 0.0;
    for (const scenes::TreePlacement& t : s.trees) {
        EXPECT_GE(t.base_cm.y, after[0][1].get<double>());
        EXPECT_LE(t.base_cm.y, after[1][1].get<double>());
        farthest = std::max(farthest, t.base_cm.y);
    }
    EXPECT_GT(farthest, before[1][1].get<double>());  // trees beyond the old region
}

TEST(SceneGrowth, ResolutionAndNeedlesGrowAlone)
{
    const nlohmann::json forest = paperForest();
    const scenes::Scene base = parsed(forest);
    const scenes::Scene pixels = parsed(growScene(forest, GrowthAxis::Resolution, 4.0));
    EXPECT_EQ(pixels.camera.width, 2 * base.camera.width);
    EXPECT_EQ(pixels.camera.height, 2 * base.camera.height);
    EXPECT_EQ(pixels.trees.size(), base.trees.size());

    const scenes::Scene needles = parsed(growScene(forest, GrowthAxis::NeedleDensity, 2.0));
    const scenes::Species& a = base.species.at("fir");
    const scenes::Species& b = needles.species.at("fir");
    EXPECT_DOUBLE_EQ(b.needlesAtBase.coneSpacing_cm, a.needlesAtBase.coneSpacing_cm / 2.0);
    EXPECT_DOUBLE_EQ(b.needlesAtTip.coneSpacing_cm, a.needlesAtTip.coneSpacing_cm / 2.0);
    EXPECT_EQ(b.needlesAtBase.perCone, a.needlesAtBase.perCone);
    // The same tree (same seed) bears twice the needles.
    const scenes::TreeCounts before = scenes::growTree(a, base.trees[0]).counts();
    const scenes::TreeCounts after = scenes::growTree(b, needles.trees[0]).counts();
    EXPECT_EQ(after.boughs, before.boughs);
    EXPECT_NEAR(after.needles / before.needles, 2.0, 1e-9);
}

TEST(SceneGrowth, RefusesWhatItCannotGrow)
{
    nlohmann::json lone = paperForest();
    lone["trees"] = nlohmann::json::array({{{"species", "fir"}, {"position", {0, 900}}}});
    try {
        (void)growScene(lone, GrowthAxis::TreesInRegion, 2.0);
        FAIL() << "a scene without a scatter was grown";
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("--grow trees-region"), std::string::npos);
    }
    EXPECT_THROW((void)growthAxis("forests"), InputError);
    EXPECT_THROW((void)growScene(lone, GrowthAxis::Resolution, 0.0), InputError);
    EXPECT_EQ(growthAxis("trees-density"), GrowthAxis::TreesAtDensity);
}

TEST(SceneGrowth, ExponentIsTheLogLogSlope)
{
    std::vector<double> x, y;
    for (int k = 0; k < 5; ++k) {
        x.push_back(std::pow(2.0, k));
        y.push_back(3.0 * std::pow(x.back(), 1.7));
    }
    EXPECT_NEAR(growthExponent(x, y), 1.7, 1e-12);
    y[2] *= 1.1;  // noise moves it, a little
    EXPECT_NEAR(growthExponent(x, y), 1.7, 0.05);
    EXPECT_TRUE(std::isnan(growthExponent({1.0}, {2.0})));
    EXPECT_TRUE(std::isnan(growthExponent({1.0, 2.0}, {0.0, 1.0})));
}

}  // namespace
}  // namespace pine::vdbtrace
