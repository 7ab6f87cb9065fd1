// Scene files: values arrive where the header says, in its units; every bad input gets one line
// "FILE[:LINE:COL]: key.path: problem" (docs/scene-format.md, "Errors").
#include "test_support.h"

#include "pine/scenes/lsystem.h"
#include "pine/scenes/scene.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <numbers>
#include <string>
#include <vector>

namespace pine::scenes {
namespace {

using test::errorOf;
using test::errorOfText;
using test::fullScene;
using test::json;

constexpr double kDeg = std::numbers::pi / 180.0;

// Every message is a single line that starts with the file's name.
void expectOneLine(const std::string& message, const std::string& file = "test.json")
{
    EXPECT_EQ(message.find('\n'), std::string::npos) << message;
    EXPECT_EQ(message.rfind(file, 0), 0u) << message;
}

// The error for `j`, which must be one; the key path must appear in it.
std::string expectError(const json& j, const std::string& path, const std::string& problem)
{
    const std::string message = errorOf(j);
    EXPECT_NE(message, "") << "accepted, but " << path << " should be rejected";
    expectOneLine(message);
    EXPECT_NE(message.find(": " + path + ": "), std::string::npos) << message;
    EXPECT_NE(message.find(problem), std::string::npos) << message;
    return message;
}

json minimalScene()
{
    return json::parse(R"({
      "camera": {"position": [0, -500, 100], "look_at": [0, 0, 100]},
      "lights": [{"type": "directional", "direction": [0, 0, 1]}],
      "trees": []
    })");
}

// Follows `place` (object keys, or array indices written as digits) into `j`, writing the
// key path the parser reports ("trees[2].scatter") into `path`.
json* walkTo(json& j, const std::vector<std::string>& place, std::string& path)
{
    json* node = &j;
    for (const std::string& step : place) {
        const bool index = std::isdigit(static_cast<unsigned char>(step[0]));
        node = index ? &(*node)[std::stoul(step)] : &(*node)[step];
        path += index ? "[" + step + "]" : (path.empty() ? "" : ".") + step;
    }
    return node;
}

TEST(SceneParser, MinimalSceneTakesTheHeaderDefaults)
{
    const Scene s = parseScene(minimalScene().dump(), "dir/minimal.json");
    const Camera camera;
    const Ground ground;
    const RenderSettings render;
    EXPECT_EQ(s.name, "minimal");  // the file's stem
    EXPECT_EQ(s.source, "dir/minimal.json");
    EXPECT_DOUBLE_EQ(s.camera.fovY_rad, camera.fovY_rad);
    EXPECT_EQ(s.camera.width, 640);
    EXPECT_EQ(s.camera.height, 480);
    EXPECT_EQ(s.camera.up, Vec3(0, 0, 1));
    EXPECT_EQ(s.ground.kind, Ground::Kind::Plane);
    EXPECT_EQ(s.ground.height_cm, ground.height_cm);
    EXPECT_EQ(s.ground.albedo, ground.albedo);
    EXPECT_TRUE(s.effects.diffuse);
    EXPECT_FALSE(s.effects.specular || s.effects.shadows || s.effects.selfShadowing);
    EXPECT_EQ(s.render.background, render.background);
    EXPECT_EQ(s.render.needleLevelMax, render.needleLevelMax);
    EXPECT_EQ(s.render.model.coneLevelMax, render.model.coneLevelMax);
    EXPECT_TRUE(s.trees.empty());
    EXPECT_TRUE(s.species.empty());
}

TEST(SceneParser, RoundTripsEveryValueInMemoryUnits)
{
    const Scene s = parseScene(fullScene().dump(), "full.json");
    EXPECT_EQ(s.name, "full");

    EXPECT_EQ(s.camera.position_cm, Vec3(1, -400, 120));
    EXPECT_EQ(s.camera.lookAt_cm, Vec3(1, 0, 90));
    EXPECT_EQ(s.camera.up, Vec3(0, 0, 1));  // unit length in memory
    EXPECT_DOUBLE_EQ(s.camera.fovY_rad, 30 * kDeg);
    EXPECT_EQ(s.camera.width, 320);
    EXPECT_EQ(s.camera.height, 240);

    ASSERT_EQ(s.pointLights.size(), 1u);
    EXPECT_EQ(s.pointLights[0].position_cm, Vec3(10, 20, 300));
    EXPECT_EQ(s.pointLights[0].colour, Vec3(1, 0.5, 0.25));
    EXPECT_EQ(s.pointLights[0].intensity, 900);
    ASSERT_EQ(s.directionalLights.size(), 1u);
    EXPECT_EQ(s.directionalLights[0].towardsLight, Vec3(0, 0, 1));
    EXPECT_EQ(s.directionalLights[0].colour, Vec3(0.5, 0.5, 1));
    EXPECT_EQ(s.directionalLights[0].irradiance, 2);

    EXPECT_EQ(s.ground.kind, Ground::Kind::Hill);
    EXPECT_EQ(s.ground.height_cm, -10);
    EXPECT_EQ(s.ground.hillPeak_cm, 200);
    EXPECT_EQ(s.ground.hillRadius_cm, 300);
    EXPECT_EQ(s.ground.hillCentre_cm, Vec2(50, -20));
    EXPECT_EQ(s.ground.albedo, Vec3(0.2, 0.3, 0.1));

    ASSERT_EQ(s.species.count("fir"), 1u);
    const Species& f = s.species.at("fir");
    EXPECT_EQ(f.axiom, "A");
    ASSERT_EQ(f.rules.size(), 2u);
    EXPECT_EQ(f.rules.at('A'), "F[&B]/[&B]/[&B]!A");  // spaces dropped
    EXPECT_EQ(f.rules.at('B'), "FB");
    EXPECT_EQ(f.iterations, 4);
    EXPECT_DOUBLE_EQ(f.branchAngle_rad, 70 * kDeg);
    EXPECT_DOUBLE_EQ(f.divergence_rad, 120 * kDeg);
    EXPECT_EQ(f.segment_cm, 12);
    EXPECT_EQ(f.trunkRadius_cm, 2);
    EXPECT_EQ(f.lengthDecay, 0.9);
    EXPECT_EQ(f.radiusDecay, 0.8);
    EXPECT_EQ(f.branchRadiusRatio, 0.25);
    EXPECT_DOUBLE_EQ(f.jitter_rad, 3 * kDeg);
    EXPECT_DOUBLE_EQ(f.needlesAtBase.aperture_rad, 22.5 * kDeg);
    EXPECT_EQ(f.needlesAtBase.length_cm, 4.25);
    EXPECT_EQ(f.needlesAtBase.radius_cm, 0.05);
    EXPECT_EQ(f.needlesAtBase.perCone, 12);
    EXPECT_EQ(f.needlesAtBase.coneSpacing_cm, 0.9);
    // The tip sets two keys; the others come from the base, not from the header.
    EXPECT_DOUBLE_EQ(f.needlesAtTip.aperture_rad, 30 * kDeg);
    EXPECT_EQ(f.needlesAtTip.length_cm, 3);
    EXPECT_EQ(f.needlesAtTip.radius_cm, 0.05);
    EXPECT_EQ(f.needlesAtTip.perCone, 12);
    EXPECT_EQ(f.needlesAtTip.coneSpacing_cm, 0.9);
    EXPECT_EQ(f.barkAlbedo, 0.15);
    EXPECT_EQ(f.needleAlbedo, 0.4);
    EXPECT_EQ(f.needleSpecular, 0.2);
    EXPECT_EQ(f.specularExponent, 80);

    ASSERT_EQ(s.trees.size(), 7u);  // two placed, five scattered
    EXPECT_EQ(s.trees[0].species, "fir");
    EXPECT_EQ(s.trees[0].base_cm, Vec3(0, 0, 5));
    EXPECT_EQ(s.trees[0].height_cm, 150);
    EXPECT_DOUBLE_EQ(s.trees[0].rotation_rad, 90 * kDeg);
    EXPECT_EQ(s.trees[0].seed, 42u);
    // [x, y] stands on the hill; the defaults are height 0 (own size), rotation 0, seed 1.
    EXPECT_EQ(s.trees[1].base_cm, Vec3(100, 50, s.ground.heightAt(100, 50)));
    EXPECT_EQ(s.trees[1].height_cm, 0);
    EXPECT_EQ(s.trees[1].rotation_rad, 0);
    EXPECT_EQ(s.trees[1].seed, 1u);

    EXPECT_TRUE(s.effects.diffuse && s.effects.specular && s.effects.shadows &&
                s.effects.selfShadowing);
    EXPECT_EQ(s.render.background, Vec3(0.1, 0.2, 0.3));
    EXPECT_EQ(s.render.needleLevelMax, 0.5);
    EXPECT_EQ(s.render.model.coneLevelMax, 2);
}

TEST(SceneParser, EffectsListedAreTheOnlyOnesOn)
{
    json j = minimalScene();
    j["effects"] = {"shadows"};
    Scene s = parseScene(j.dump(), "e.json");
    EXPECT_FALSE(s.effects.diffuse);
    EXPECT_TRUE(s.effects.shadows);
    EXPECT_FALSE(s.effects.specular || s.effects.selfShadowing);
    j["effects"] = json::array();
    s = parseScene(j.dump(), "e.json");
    EXPECT_FALSE(s.effects.diffuse || s.effects.specular || s.effects.shadows ||
                 s.effects.selfShadowing);
}

TEST(SceneParser, ModelsAreFaithfulUnlessThePresetOrAKeySaysOtherwise)
{
    json j = minimalScene();
    const ModelChoices faithful = parseScene(j.dump(), "m.json").render.model;
    EXPECT_EQ(faithful.boughLaw, "exact");
    EXPECT_EQ(faithful.layerModel, "fibre");
    EXPECT_EQ(faithful.extinctionLaw, "fibre");
    EXPECT_EQ(faithful.shadowOrigin, "needles");
    EXPECT_EQ(faithful.levelBlend, 1.5);
    j["render"]["preset"] = "paper";
    const ModelChoices paper = parseScene(j.dump(), "m.json").render.model;
    EXPECT_EQ(paper.boughLaw, "linear");
    EXPECT_EQ(paper.layerModel, "paper");
    EXPECT_EQ(paper.extinctionLaw, "layer");
    EXPECT_EQ(paper.shadowOrigin, "axis");
    EXPECT_EQ(paper.levelBlend, 1.0);
    // One cone a pixel for the paper; the faithful render splits a pixel whose footprint spans
    // more than half a cone spacing at a bough.
    EXPECT_EQ(faithful.pixelSplitQ, 0.5);
    EXPECT_EQ(paper.pixelSplitQ, 0.0);
    // A key after the preset overrides it alone.
    j["render"]["layer_model"] = "fibre";
    const ModelChoices mixed = parseScene(j.dump(), "m.json").render.model;
    EXPECT_EQ(mixed.boughLaw, "linear");
    EXPECT_EQ(mixed.layerModel, "fibre");
    // Occluding boughs read where their cones reach, or even along the axis as printed.
    EXPECT_EQ(faithful.occluderProfile, "cones");
    EXPECT_EQ(paper.occluderProfile, "even");
    j["render"]["occluder_profile"] = "cones";
    EXPECT_EQ(parseScene(j.dump(), "m.json").render.model.occluderProfile, "cones");
    j["render"].erase("occluder_profile");
    // The level 3 threshold is one of the choices: the preset's unless the scene names it.
    EXPECT_EQ(faithful.coneLevelMax, 1.0);
    EXPECT_EQ(mixed.coneLevelMax, 1.0);
    j["render"]["cone_level_max"] = 3.0;
    EXPECT_EQ(parseScene(j.dump(), "m.json").render.model.coneLevelMax, 3.0);
    j["render"].erase("cone_level_max");
    j["render"]["level_blend"] = 2.5;  // the bands about 0.25 and 1 would overlap past 2
    expectError(j, "render.level_blend", "must be at most sqrt(cone_level_max / needle_level_max) (2)");
    j["render"]["level_blend"] = 0.5;
    expectError(j, "render.level_blend", "must be >= 1");
    j["render"].erase("level_blend");
    j["render"]["preset"] = "printed";
    expectError(j, "render.preset", "must be \"faithful\" or \"paper\"");
}

TEST(SceneParser, ScatterIsSeededInsideItsRegionAndOnTheGround)
{
    const json j = fullScene();
    const Scene a = parseScene(j.dump(), "a.json"), b = parseScene(j.dump(), "b.json");
    ASSERT_EQ(a.trees.size(), 7u);
    for (std::size_t i = 2; i < 7; ++i) {
        const TreePlacement& t = a.trees[i];
        EXPECT_EQ(t.species, "fir");
        EXPECT_GE(t.base_cm.x, -500);
        EXPECT_LT(t.base_cm.x, 500);
        EXPECT_GE(t.base_cm.y, -500);
        EXPECT_LT(t.base_cm.y, 500);
        EXPECT_EQ(t.base_cm.z, a.ground.heightAt(t.base_cm.x, t.base_cm.y));
        EXPECT_GE(t.height_cm, 80);
        EXPECT_LT(t.height_cm, 120);
        EXPECT_GE(t.rotation_rad, 0);
        EXPECT_LT(t.rotation_rad, 2 * std::numbers::pi);
        for (std::size_t k = 2; k < i; ++k) {
            const double d = std::hypot(t.base_cm.x - a.trees[k].base_cm.x,
                                        t.base_cm.y - a.trees[k].base_cm.y);
            EXPECT_GE(d, 50) << "trees " << k << " and " << i << " closer than min_spacing";
        }
        // Same file, same forest.
        EXPECT_EQ(t.base_cm, b.trees[i].base_cm);
        EXPECT_EQ(t.height_cm, b.trees[i].height_cm);
        EXPECT_EQ(t.seed, b.trees[i].seed);
    }
    json other = j;
    other["trees"][2]["scatter"]["seed"] = 10;
    const Scene c = parseScene(other.dump(), "c.json");
    EXPECT_NE(c.trees[2].base_cm, a.trees[2].base_cm);
}

TEST(SceneParser, ScatterVariantsAreCopiesOfTheirFirstTree)
{
    json j = fullScene();
    const Scene own = parseScene(j.dump(), "own.json");
    for (const auto& t : own.trees) EXPECT_EQ(t.variantOf, -1);  // without the key: unchanged
    j["trees"][2]["scatter"]["count"] = 40;
    j["trees"][2]["scatter"]["min_spacing"] = 20;
    j["trees"][2]["scatter"]["variants"] = 3;
    const Scene s = parseScene(j.dump(), "variants.json");
    ASSERT_EQ(s.trees.size(), 42u);
    int firsts = 0, copies = 0;
    for (std::size_t i = 2; i < s.trees.size(); ++i) {
        const auto& t = s.trees[i];
        EXPECT_EQ(t.base_cm.z, s.ground.heightAt(t.base_cm.x, t.base_cm.y));
        if (t.variantOf < 0) {
            ++firsts;
            continue;
        }
        ++copies;
        // A copy names an earlier first tree of the same scatter, whose tree it is, elsewhere.
        ASSERT_GE(t.variantOf, 2);
        ASSERT_LT(std::size_t(t.variantOf), i);
        const auto& first = s.trees[std::size_t(t.variantOf)];
        EXPECT_EQ(first.variantOf, -1);
        EXPECT_EQ(t.seed, first.seed);
        EXPECT_EQ(t.height_cm, first.height_cm);
        EXPECT_EQ(t.rotation_rad, first.rotation_rad);
        EXPECT_NE(t.base_cm, first.base_cm);
    }
    EXPECT_EQ(firsts, 3);  // 40 trees from 3 variants: each drawn (certainly, for this seed)
    EXPECT_EQ(copies, 37);
    j["trees"][2]["scatter"]["variants"] = 41;
    expectError(j, "trees[2].scatter.variants", "must be in [1, 40] (is 41)");
    j["trees"][2]["scatter"]["variants"] = 0;
    expectError(j, "trees[2].scatter.variants", "1");
    // A scatter turned off (count 0) keeps a variants key of 1, and only 1.
    j["trees"][2]["scatter"]["count"] = 0;
    j["trees"][2]["scatter"]["variants"] = 1;
    EXPECT_EQ(parseScene(j.dump(), "off.json").trees.size(), 2u);
    j["trees"][2]["scatter"]["variants"] = 2;
    expectError(j, "trees[2].scatter.variants", "must be in [1, 1] (is 2)");
}

TEST(SceneParser, ScatterThatCannotKeepItsSpacingSaysSo)
{
    json j = fullScene();
    j["trees"][2]["scatter"]["min_spacing"] = 2000;
    expectError(j, "trees[2].scatter.min_spacing", "cannot place 5 trees");
}

TEST(SceneParser, ScatterRegionWiderThanADoubleIsRefused)
{
    // Each corner finite, their distance not: the trees were placed at infinity (a render of
    // nothing, a needle count of -2^63, exit 0).
    json j = fullScene();
    j["trees"][2]["scatter"]["region"] = {{-1e308, 0}, {1e308, 10}};
    expectError(j, "trees[2].scatter.region", "x1 - x0 and y1 - y0 must be finite");
    j["trees"][2]["scatter"]["region"] = {{0, -1e308}, {10, 1e308}};
    expectError(j, "trees[2].scatter.region", "must be finite");
    j["trees"][2]["scatter"]["region"] = {{-1e307, -1e307}, {1e307, 1e307}};
    const Scene s = parseScene(j.dump(), "test.json");
    for (const TreePlacement& p : s.trees) {
        EXPECT_TRUE(std::isfinite(p.base_cm.x) && std::isfinite(p.base_cm.y)) << p.base_cm.x;
    }
}

TEST(SceneParser, MalformedJsonGivesLineAndColumn)
{
    // A trailing comma on line 3, at column 27.
    const std::string text = "{\n  \"camera\": {\n    \"position\": [0, 0, 1],,\n  }\n}";
    const std::string message = errorOfText(text, "bad.json");
    expectOneLine(message, "bad.json");
    EXPECT_EQ(message.rfind("bad.json:3:27: syntax error", 0), 0u) << message;

    // Trailing text: the column of the character where "tra..." stopped being a literal.
    const std::string garbage = errorOfText("{\"name\": \"x\"} trailing", "g.json");
    EXPECT_EQ(garbage.rfind("g.json:1:17: ", 0), 0u) << garbage;
    EXPECT_EQ(errorOfText("", "empty.json").rfind("empty.json:1:1: ", 0), 0u);
}

TEST(SceneParser, NumberTooLargeForADoubleNamesItsKeyAndPlace)
{
    // nlohmann reports 1e999 as a bare overflow; we name the key and its line and column.
    const std::string text =
        "{\n"
        "  \"camera\": {\"position\": [0, -500, 100], \"look_at\": [0, 0, 100]},\n"
        "  \"lights\": [{\"type\": \"directional\", \"direction\": [0, 0, 1]}],\n"
        "  \"trees\": [{\"species\": \"fir\", \"position\": [0, 0],\n"
        "             \"height\": 1e999}]\n"
        "}\n";
    const std::string message = errorOfText(text);
    expectOneLine(message);
    EXPECT_EQ(message, "test.json:5:24: trees[0].height: must be finite (number out of range: "
                       "1e999)");
    // An element of a vector: the path ends in its index; the column is the number's sign.
    const std::string inVector = errorOfText(R"({"camera": {"position": [0, -1e400, 0]}})");
    EXPECT_EQ(inVector.rfind("test.json:1:29: camera.position[1]: must be finite", 0), 0u)
        << inVector;
}

TEST(SceneParser, DuplicateKeyIsAnError)
{
    const std::string message =
        errorOfText(R"({"camera": {"position": [0, 0, 1], "position": [0, 0, 2]}})");
    expectOneLine(message);
    EXPECT_NE(message.find("camera.position: duplicate key"), std::string::npos) << message;
}

// A key nobody reads is an error wherever it sits (pbrt-v4's ReportUnused): a typo must never
// fall back to a default in silence.
TEST(SceneParser, RejectsAKeyNobodyReadsAnywhere)
{
    const std::vector<std::vector<std::string>> places = {
        {},
        {"camera"},
        {"lights", "0"},
        {"lights", "1"},
        {"ground"},
        {"species", "fir"},
        {"species", "fir", "lsystem"},
        {"species", "fir", "needles"},
        {"species", "fir", "needles", "base"},
        {"species", "fir", "needles", "tip"},
        {"trees", "0"},
        {"trees", "2"},
        {"trees", "2", "scatter"},
        {"render"},
    };
    for (const auto& place : places) {
        json j = fullScene();
        std::string path;
        json* node = walkTo(j, place, path);
        (*node)["colour_typo"] = 1;
        expectError(j, path.empty() ? "colour_typo" : path + ".colour_typo", "unknown key");
    }
    // A key that belongs to another kind of ground is as unread as a typo.
    json j = fullScene();
    j["ground"]["type"] = "plane";
    j["ground"].erase("radius");
    j["ground"].erase("centre");
    expectError(j, "ground.peak", "unknown key");
}

TEST(SceneParser, MissingRequiredValueIsNamed)
{
    for (const auto& [section, key] : std::vector<std::pair<std::string, std::string>>{
             {"camera", "position"}, {"camera", "look_at"}, {"", "camera"}, {"", "lights"},
             {"", "trees"}}) {
        json j = fullScene();
        (section.empty() ? j : j[section]).erase(key);
        expectError(j, section.empty() ? key : section + "." + key, "missing");
    }
    json j = fullScene();
    j["trees"][0].erase("species");
    expectError(j, "trees[0].species", "missing");
    j = fullScene();
    j["species"]["fir"]["lsystem"].erase("axiom");
    expectError(j, "species.fir.lsystem.axiom", "missing");
    j = fullScene();
    j["ground"].erase("radius");
    expectError(j, "ground.radius", "missing");
}

TEST(SceneParser, MissingKeyPointsAtItsLikelyTypo)
{
    json j = fullScene();
    j["camera"]["positon"] = j["camera"]["position"];
    j["camera"].erase("position");
    expectError(j, "camera.position", "\"positon\" a typo");
}

TEST(SceneParser, RejectsNegativeAndZeroSizes)
{
    const std::vector<std::pair<std::vector<std::string>, double>> bad = {
        {{"trees", "0", "height"}, -5},
        {{"species", "fir", "lsystem", "segment"}, 0},
        {{"species", "fir", "lsystem", "trunk_radius"}, -1},
        {{"species", "fir", "needles", "base", "length"}, -4.25},
        {{"species", "fir", "needles", "tip", "radius"}, 0},
        {{"species", "fir", "needles", "base", "cone_spacing"}, -0.9},
        {{"species", "fir", "needles", "base", "per_cone"}, 0},
        {{"ground", "radius"}, -300},
        {{"lights", "0", "intensity"}, -1},
        {{"trees", "2", "scatter", "min_spacing"}, -1},
        {{"camera", "fov_deg"}, 180},
        {{"camera", "fov_deg"}, 0},
        {{"species", "fir", "needles", "base", "aperture_deg"}, 95},
        {{"species", "fir", "bark_albedo"}, 1.5},
        {{"species", "fir", "specular_exponent"}, 1},
        {{"render", "cone_level_max"}, 0.1},
        {{"render", "pixel_split_q"}, -1},
    };
    for (const auto& [place, value] : bad) {
        json j = fullScene();
        std::string path;
        json* node = walkTo(j, place, path);
        *node = value;
        expectError(j, path, "must");
    }
}

TEST(SceneParser, RejectsALightTooBrightForFloatRadiance)
{
    // Radiance is written as float: a light whose colour times its strength passes 1e30 would
    // overflow only after the render. The bound is on the product, whichever factor is large.
    json j = fullScene();
    j["lights"][0]["intensity"] = 1e308;
    expectError(j, "lights[0].intensity", "more than float radiance can hold (at most 1e+30");
    j = fullScene();
    j["lights"][1]["colour"] = {1e16, 1, 1};
    j["lights"][1]["irradiance"] = 1e15;
    expectError(j, "lights[1].irradiance", "its largest channel 1e+16");
    j = fullScene();
    j["render"]["background"] = {0, 0, 1e31};
    expectError(j, "render.background[2]", "must be in [0, 1e+30]");
    // At the bound, accepted.
    j = fullScene();
    j["lights"][0]["colour"] = {1, 1, 1};
    j["lights"][0]["intensity"] = 1e30;
    EXPECT_EQ(errorOf(j), "");
}

TEST(SceneParser, RejectsWrongTypesAndShapes)
{
    json j = fullScene();
    j["camera"]["position"] = {0, 1};
    expectError(j, "camera.position", "array of 3 numbers");
    j = fullScene();
    j["camera"]["fov_deg"] = "wide";
    expectError(j, "camera.fov_deg", "must be a number");
    j = fullScene();
    j["trees"][0]["seed"] = 4.5;
    expectError(j, "trees[0].seed", "must be an integer (is 4.5)");
    j["trees"][0]["seed"] = 4.0;  // an integer written as a float is one
    EXPECT_EQ(parseScene(j.dump(), "s.json").trees[0].seed, 4u);
    j["trees"][0]["seed"] = "4";
    expectError(j, "trees[0].seed", "must be an integer, not string");
    j = fullScene();
    j["trees"][0]["seed"] = -1;
    expectError(j, "trees[0].seed", "must be in [0, 4294967295] (is -1)");
    j["trees"][0]["seed"] = 4294967296u;  // unsigned to the JSON reader: said as -1 is
    expectError(j, "trees[0].seed", "must be in [0, 4294967295] (is 4294967296)");
    j = fullScene();
    j["trees"][0]["position"] = {1, 2, 3, 4};
    expectError(j, "trees[0].position", "2 numbers");
    j = fullScene();
    j["lights"][0]["type"] = "spot";
    expectError(j, "lights[0].type", "\"point\" or \"directional\"");
    j = fullScene();
    j["ground"]["type"] = "mountain";
    expectError(j, "ground.type", "\"plane\", \"hill\" or \"none\"");
    j = fullScene();
    j["lights"] = json::array();
    expectError(j, "lights", "at least one light");
    j = fullScene();
    j["effects"] = {"diffuse", "shadow"};
    expectError(j, "effects[1]", "unknown effect \"shadow\"");
    j = fullScene();
    j["effects"] = {"diffuse", "diffuse"};
    expectError(j, "effects[1]", "named twice");
    j = fullScene();
    j["trees"][2]["scatter"]["region"] = {{500, 0}, {-500, 10}};
    expectError(j, "trees[2].scatter.region", "x0 <= x1");
}

TEST(SceneParser, RejectsUnknownSpecies)
{
    json j = fullScene();
    j["trees"][1]["species"] = "spruce";
    expectError(j, "trees[1].species", "unknown species \"spruce\" (defined: fir)");
    j = fullScene();
    j["trees"][2]["scatter"]["species"] = "pine";
    expectError(j, "trees[2].scatter.species", "unknown species \"pine\"");
}

TEST(SceneParser, NormalisesTinyAndHugeDirections)
{
    // Only a true zero vector has no direction: 1e-200 and 1e200 (whose squared lengths under-
    // and overflow) are directions like any other.
    for (const double scale : {1e-200, 1e200, 1e-308, 1.7e308}) {
        json j = fullScene();
        j["lights"][1]["direction"] = {0.0, -0.6 * scale, 0.8 * scale};
        j["camera"]["up"] = {0.0, 0.0, scale};
        const Scene s = parseScene(j.dump(), "tiny.json");
        ASSERT_EQ(s.directionalLights.size(), 1u) << scale;
        const Vec3 d = s.directionalLights[0].towardsLight;
        EXPECT_NEAR(d.x, 0.0, 1e-15) << scale;
        EXPECT_NEAR(d.y, -0.6, 1e-15) << scale;
        EXPECT_NEAR(d.z, 0.8, 1e-15) << scale;
        EXPECT_NEAR(s.camera.up.z, 1.0, 1e-15) << scale;
    }
}

TEST(SceneParser, RejectsZeroVectors)
{
    json j = fullScene();
    j["lights"][1]["direction"] = {0, 0, 0};
    expectError(j, "lights[1].direction", "zero vector");
    j = fullScene();
    j["camera"]["up"] = {0, 0, 0};
    expectError(j, "camera.up", "zero vector");
    j = fullScene();
    j["camera"]["look_at"] = j["camera"]["position"];
    expectError(j, "camera.look_at", "no view direction");
    j = fullScene();
    j["camera"]["up"] = {0, 1, 0};
    j["camera"]["look_at"] = {1, 0, 120};  // view along +y, parallel to up
    expectError(j, "camera.up", "parallel to the view direction");
    // Each coordinate finite, their difference not: no view direction either (it read as an
    // up parallel to it).
    j = fullScene();
    j["camera"]["position"] = {1e308, -1e308, 1e308};
    expectError(j, "camera.look_at", "too far from position");
}

TEST(SceneParser, RejectsZeroResolution)
{
    json j = fullScene();
    j["camera"]["resolution"] = {0, 480};
    expectError(j, "camera.resolution[0]", "must be in [1, 16384]");
    j["camera"]["resolution"] = {640, 0};
    expectError(j, "camera.resolution[1]", "must be in [1, 16384]");
    j["camera"]["resolution"] = {640};
    expectError(j, "camera.resolution", "[width, height]");
}

TEST(SceneParser, RejectsBadLSystems)
{
    json j = fullScene();
    j["species"]["fir"]["lsystem"]["rules"]["B"] = "F$B";
    expectError(j, "species.fir.lsystem.rules.B", "unknown symbol '$'");
    j = fullScene();
    j["species"]["fir"]["lsystem"]["rules"]["B"] = "F[B";
    expectError(j, "species.fir.lsystem.rules.B", "'[' without its ']'");
    j = fullScene();
    j["species"]["fir"]["lsystem"]["axiom"] = "A]";
    expectError(j, "species.fir.lsystem.axiom", "']' without its '['");
    j = fullScene();
    j["species"]["fir"]["lsystem"]["rules"]["AB"] = "F";
    expectError(j, "species.fir.lsystem.rules.AB", "one letter");
    // A rule that doubles the string 30 times would need 2^30 symbols: refused before growing.
    j = fullScene();
    j["species"]["fir"]["lsystem"]["rules"]["A"] = "AA";
    j["species"]["fir"]["lsystem"]["iterations"] = 30;
    expectError(j, "species.fir.lsystem.iterations", "grows past");
    // A bushy rule within those symbols: 2^17 - 1 segments, whose crowded boughs rendered for
    // minutes. Refused before growing unless lsystem.max_segments allows it.
    j = fullScene();
    j["species"]["fir"]["lsystem"]["rules"] = {{"A", "F[&A][^A]"}};
    j["species"]["fir"]["lsystem"]["axiom"] = "A";
    j["species"]["fir"]["lsystem"]["iterations"] = 17;
    expectError(j, "species.fir.lsystem.iterations", "more than 50000 segments (F)");
    j["species"]["fir"]["lsystem"]["max_segments"] = 131070;
    expectError(j, "species.fir.lsystem.iterations", "more than 131070 segments");
    j["species"]["fir"]["lsystem"]["max_segments"] = 131071;
    EXPECT_NO_THROW(parseScene(j.dump(), "test.json"));
    j["species"]["fir"]["lsystem"]["max_segments"] = 0;
    expectError(j, "species.fir.lsystem.max_segments", "must be in [1, 4000000]");
    // Bytes that are not text are shown as \xNN: a NUL ended the message where it was echoed,
    // a byte of a multi-byte character alone is no character, a key's newline split the line.
    j = fullScene();
    j["species"]["fir"]["lsystem"]["axiom"] = std::string("A\0\x1b[31m", 7);
    std::string message =
        expectError(j, "species.fir.lsystem.axiom", "unknown symbol '\\x00' (the turtle reads");
    j["species"]["fir"]["lsystem"]["axiom"] = "A\u00e9";
    expectError(j, "species.fir.lsystem.axiom", "unknown symbol '\\xc3' (the turtle reads");
    j = fullScene();
    j["species"]["fir"]["lsystem"]["rules"]["B\n\x1b"] = "F";
    message = expectError(j, "species.fir.lsystem.rules.B\\x0a\\x1b", "one letter");
    EXPECT_EQ(message.find('\x1b'), std::string::npos) << message;
    // Every scene error, not only a key's: the JSON reader's duplicate key.
    const std::string nul = std::string("a\0b", 3);
    message = errorOfText("{\"name\": \"x\", \"" + std::string("a\\u0000b") + "\": 1, \"" +
                              std::string("a\\u0000b") + "\": 2}",
                          "test.json");
    EXPECT_NE(message.find("a\\x00b"), std::string::npos) << message;
    EXPECT_EQ(message.find(nul), std::string::npos);
}

TEST(LSystem, ExpandedCountCountsWhatExpandingWouldHold)
{
    // Counted without building the string, checked against the string built.
    const std::map<char, std::string> rules = {{'A', "F[+A]B"}, {'B', "FFB"}};
    for (int iterations = 0; iterations <= 6; ++iterations) {
        const std::string grown = expandLSystem("A", rules, iterations);
        const auto count = [&](char c) {
            return std::size_t(std::count(grown.begin(), grown.end(), c));
        };
        EXPECT_EQ(expandedCount("A", rules, iterations, "F", 1000000), count('F'));
        EXPECT_EQ(expandedCount("A", rules, iterations, "[+", 1000000), count('[') + count('+'));
        EXPECT_EQ(expandedLength("A", rules, iterations), grown.size());
    }
    EXPECT_EQ(expandedCount("A", rules, 30, "F", 100), 101u);  // saturated
}

TEST(SceneParser, RejectsNeedlesThatCannotExist)
{
    json j = fullScene();
    j["species"]["fir"]["needles"]["base"]["radius"] = 5;
    expectError(j, "species.fir.needles.base.radius", "less than the needle length");
    // 40 needles of radius 0.2 cover 2 N r / (pi R) = 3 times their cone.
    j = fullScene();
    j["species"]["fir"]["needles"]["tip"]["per_cone"] = 40;
    j["species"]["fir"]["needles"]["tip"]["radius"] = 0.2;
    expectError(j, "species.fir.needles.tip", "needles overlap");
    // 11.6 needles of radius 0.2 would cover 0.985 of their cone, but every method draws 12:
    // 1.019.
    j["species"]["fir"]["needles"]["tip"]["per_cone"] = 11.6;
    expectError(j, "species.fir.needles.tip",
                "needles overlap on their cone: A = 2 N r / (pi l sin(phi)) = 1.018");
    // Fine at both ends, overlapping between them: 40 needles of radius 0.05 at the base and 4
    // of 0.5 at the tip each cover 0.78 of their cone, 22 of 0.275 half way cover 2.4.
    j = fullScene();
    j["species"]["fir"]["needles"]["base"] = {
        {"aperture_deg", 22.5}, {"length", 4.25}, {"radius", 0.05}, {"per_cone", 40}};
    j["species"]["fir"]["needles"]["tip"] = {
        {"aperture_deg", 22.5}, {"length", 4.25}, {"radius", 0.5}, {"per_cone", 4}};
    expectError(j, "species.fir.needles", "needles overlap on their cone 0.");
    expectError(j, "species.fir.needles", "of the way from base to tip");
    // Cones 1e-6 cm apart: a line through a bough would cross millions of layers.
    j = fullScene();
    j["species"]["fir"]["needles"]["base"]["cone_spacing"] = 1e-6;
    expectError(j, "species.fir.needles.base.cone_spacing", "more layers");
    j["species"]["fir"]["needles"]["base"]["cone_spacing"] = 0.01;  // a thousand: kept
    EXPECT_NO_THROW(parseScene(j.dump(), "dense-cones.json"));
}

TEST(SceneParser, RejectsAHeightForATreeThatGrowsNone)
{
    json j = fullScene();
    j["species"]["flat"] = {{"lsystem", {{"axiom", "[&FF]"}, {"branch_angle_deg", 90},
                                         {"jitter_deg", 0}, {"iterations", 0}}}};
    j["trees"][0]["species"] = "flat";
    expectError(j, "trees[0].height", "grows no height");
    j["trees"][0]["height"] = 0;  // its own size is fine
    EXPECT_EQ(errorOf(j), "");
}

TEST(SceneParser, AcceptsCommentsAsStrings)
{
    json j = fullScene();
    j["comment"] = "why this scene";
    j["camera"]["comment"] = "why this camera";
    j["species"]["fir"]["lsystem"]["rules"]["comment"] = "rules explained";
    EXPECT_EQ(errorOf(j), "");
    j["camera"]["comment"] = 3;
    expectError(j, "camera.comment", "must be a string");
}

TEST(LoadScene, MissingFileSaysSo)
{
    const test::TempDir dir;
    const auto file = dir.path() / "absent.json";
    try {
        loadScene(file);
        FAIL() << "no error for a missing file";
    } catch (const SceneError& e) {
        const std::string message = e.what();
        EXPECT_EQ(message, file.string() + ": cannot open: no such file");
    }
    EXPECT_THROW(loadScene(dir.path()), SceneError);  // a folder is no scene
}

TEST(LoadScene, ReadsAFileAndNamesItInErrors)
{
    const test::TempDir dir;
    const auto good = dir.write("forest-7.json", minimalScene().dump());
    const Scene s = loadScene(good);
    EXPECT_EQ(s.name, "forest-7");
    EXPECT_EQ(s.source, good);

    json bad = minimalScene();
    bad["camera"]["fov_deg"] = 200;
    const auto badFile = dir.write("bad.json", bad.dump());
    try {
        loadScene(badFile);
        FAIL() << "fov 200 accepted";
    } catch (const SceneError& e) {
        EXPECT_EQ(std::string(e.what()),
                  badFile.string() + ": camera.fov_deg: must be in (0, 180) (is 200)");
    }
}

}  // namespace
}  // namespace pine::scenes
