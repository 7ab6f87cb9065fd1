// The multiscale tracer on small scenes: bounded, deterministic whatever the thread count, and
// computing exactly the effects the scene asks for.
#include "pine/scenes/scene.h"
#include "pine/analytic/bough_shader.h"
#include "pine/analytic/cone_shader.h"
#include "pine/vdbtrace/cone_camera.h"
#include "pine/vdbtrace/layer_model.h"
#include "pine/vdbtrace/methods.h"
#include "pine/vdbtrace/multiscale_tracer.h"
#include "pine/vdbtrace/traced_scene.h"

#include "test_scenes.h"

#include <gtest/gtest.h>
#include <tbb/global_control.h>
#include <glm/geometric.hpp>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <random>
#include <string>

namespace pine::vdbtrace {
namespace {

using test::firScene;

RenderResult render(const std::string& json, int forceLevel = 0)
{
    const scenes::Scene scene = scenes::parseScene(json, "test.json");
    const TracedScene traced = buildTracedScene(scene);
    MultiscaleOptions options;
    options.forceLevel = forceLevel;
    return renderMultiscale(traced, options);
}

// The fir with render.pixel_split_q set (its other render keys kept).
std::string splitFir(int width, int height, double splitQ)
{
    nlohmann::json j = nlohmann::json::parse(
        firScene(R"("diffuse", "specular", "shadows", "self_shadowing")", width, height));
    j["render"]["pixel_split_q"] = splitQ;
    return j.dump();
}

void expectBounded(const Image& image, const std::string& what)
{
    for (std::size_t i = 0; i < image.rgba.size(); ++i) {
        ASSERT_TRUE(std::isfinite(image.rgba[i])) << what << " at " << i;
        ASSERT_GE(image.rgba[i], 0.0f) << what << " at " << i;
        if (i % 4 == 3) {
            ASSERT_LE(image.rgba[i], 1.0f) << what << " alpha at " << i;
        }
    }
    for (const float level : image.aovs.at("level")) {
        ASSERT_TRUE(level == 0.0f || (level >= 1.0f && level <= 3.0f))
            << what << " level " << level;
    }
}

// The tracer never visits a primitive whose entry is -infinity. It may not: such a primitive
// must fail the test every fragment of it passes first, the cone's axis passing the segment
// (base to the cones' end for a bough, base to tip for a branch) with a strip coverage above
// 0 (addBough, SurfaceShading::branch). Cones aimed about each primitive's edge, its
// radius and half the footprint, where a bound that forgot either would show.
TEST(MultiscaleTracer, APrimitiveWithNoEntryCouldGiveNoFragment)
{
    const scenes::Scene scene =
        scenes::parseScene(firScene(R"("diffuse", "shadows")", 48, 36), "test.json");
    const TracedScene traced = buildTracedScene(scene);
    std::mt19937 rng(11);
    std::uniform_real_distribution<double> u(-1.0, 1.0), unit(0.0, 1.0);
    const std::size_t count = traced.branches.size() + traced.boughs.size();
    int missed = 0, met = 0;
    for (int k = 0; k < 40000; ++k) {
        const auto index = std::uint32_t(unit(rng) * double(count - 1));
        Vec3 a, b;
        double radius;
        if (traced.isBranch(index)) {
            a = traced.branches[index].base_cm;
            b = traced.branches[index].tip_cm;
            radius = traced.branches[index].radius_cm;
        } else {
            const TracedBough& bough = traced.bough(index);
            a = bough.base_cm;
            b = bough.conesEnd();
            radius = bough.radius_cm;
        }
        // Wide footprints too (spread up to 0.05 rad), from up to 200 cm away.
        const double spread = std::pow(10.0, -4.0 + 2.7 * unit(rng));
        const Vec3 towards = glm::normalize(Vec3(u(rng), u(rng), u(rng)));
        const Vec3 target = a + unit(rng) * (b - a);
        const double distance = 5.0 + 195.0 * unit(rng);
        const Vec3 origin = target - distance * towards;
        const Vec3 side = glm::normalize(glm::cross(towards, b - a + Vec3(1e-9, 0.0, 0.0)));
        const double edge = radius + 0.5 * spread * distance;
        const ConeRay ray{origin,
                          glm::normalize(target + edge * (0.8 + 0.4 * unit(rng)) * side - origin),
                          spread};
        Passage p;
        const bool gives =
            closestPassage(ray, a, b, p) && stripCoverage(p.gap, radius, ray.width(p.t)) > 0.0;
        const double entry = primitiveEntry(ray, traced, index);
        if (entry == -std::numeric_limits<double>::infinity()) {
            ++missed;
            ASSERT_FALSE(gives) << "primitive " << index << " cone " << k;
        } else {
            met += gives ? 1 : 0;
        }
    }
    // Both sides of the edge, many times.
    EXPECT_GT(missed, 4000);
    EXPECT_GT(met, 4000);
}

TEST(MultiscaleTracer, CompositingStaysBoundedAndUsesEveryLevel)
{
    // One cone a pixel, so that the fir's footprints call for every level.
    const RenderResult r = render(splitFir(96, 72, 0.0));
    expectBounded(r.image, "fir");
    EXPECT_GT(r.stats.needleHits, 0u);
    EXPECT_GT(r.stats.coneHits, 0u);
    EXPECT_GT(r.stats.boughHits, 0u);
    EXPECT_EQ(r.stats.coneRays, 96u * 72u);
    // The faithful default splits the pixels whose footprints span more than half a cone
    // spacing at a bough.
    const RenderResult split =
        render(firScene(R"("diffuse", "specular", "shadows", "self_shadowing")"));
    expectBounded(split.image, "fir, pixels split");
    EXPECT_GT(split.stats.coneRays, 96u * 72u);
}

TEST(MultiscaleTracer, ASplitPixelIsTheMeanOfTheFinerImagesPixels)
{
    // With a split threshold below every footprint, each pixel whose cone shows a bough, or
    // whose corners alone do, is traced again as 4 x 4 cones (the most): those of the image 4 times
    // finer, which splits none. Where the finer image shows foliage within the pixel, in its
    // corners alone too (its own cone's disc misses them), the pixel is their mean; the other
    // pixels keep their one cone. The tally of each tree's foliage counts the 16 cones, not the
    // first one too.
    constexpr int kW = 24, kH = 18, kSplit = scenes::ModelChoices::kMaxPixelSplit;
    const RenderResult coarse = render(splitFir(kW, kH, 1e-3));
    const RenderResult fine = render(splitFir(kSplit * kW, kSplit * kH, 0.0));
    ASSERT_EQ(fine.stats.coneRays, std::uint64_t(kSplit * kW * kSplit * kH));
    const std::uint64_t extra = coarse.stats.coneRays - std::uint64_t(kW * kH);
    EXPECT_GT(extra, 0u);
    constexpr int kMore = kSplit * kSplit;
    EXPECT_EQ(extra % kMore, 0u) << "each split pixel traces 16 cones more";
    const std::vector<float>& foliage = coarse.image.aovs.at("foliage");
    const std::vector<float>& fineFoliage = fine.image.aovs.at("foliage");
    const RenderResult one = render(splitFir(kW, kH, 0.0));  // what each pixel's cone meets
    const std::vector<float>& ownFoliage = one.image.aovs.at("foliage");
    int compared = 0, byCorners = 0;
    double worst = 0.0;
    for (int y = 0; y < kH; ++y) {
        for (int x = 0; x < kW; ++x) {
            double within = 0.0;  // the finer image's foliage over the pixel
            for (int s = 0; s < kSplit * kSplit; ++s) {
                within += fineFoliage[std::size_t((kSplit * y + s / kSplit) * kSplit * kW +
                                                  kSplit * x + s % kSplit)];
            }
            if (!(foliage[std::size_t(y * kW + x)] > 0.0f) && !(within > 0.0)) continue;
            ++compared;
            byCorners += ownFoliage[std::size_t(y * kW + x)] > 0.0f ? 0 : 1;
            for (int c = 0; c < 4; ++c) {
                double mean = 0.0;
                for (int s = 0; s < kSplit * kSplit; ++s) {
                    mean += fine.image.pixel(kSplit * x + s % kSplit, kSplit * y + s / kSplit)[c];
                }
                mean /= kSplit * kSplit;
                worst = std::max(worst, std::abs(coarse.image.pixel(x, y)[c] - mean) /
                                            std::max(std::abs(mean), 1e-3));
            }
        }
    }
    std::printf(
        "%d pixels split, %d with foliage compared (%d where the pixel's cone met none); "
        "worst relative difference %.2e\n",
        int(extra / kMore), compared, byCorners, worst);
    EXPECT_GT(compared, kW * kH / 8);
    EXPECT_GE(int(extra / kMore), compared);
    EXPECT_GT(byCorners, 0) << "no pixel showed foliage in its corners alone";
    EXPECT_LT(worst, 1e-5);
    double tallied = 0.0, shown = 0.0;
    for (const TreeFoliageSum& t : coarse.treeFoliage) tallied += t.coverage_px;
    for (const float f : foliage) shown += f;
    EXPECT_NEAR(tallied, shown, 1e-4 * shown);
}

TEST(MultiscaleTracer, NoPixelIsSplitWhereTheFootprintIsFineOrThePaperAsksOneCone)
{
    // The paper's one cone a pixel (pixel_split_q 0), and a threshold above every footprint.
    EXPECT_EQ(render(splitFir(24, 18, 0.0)).stats.coneRays, 24u * 18u);
    EXPECT_EQ(render(splitFir(24, 18, 1e3)).stats.coneRays, 24u * 18u);
    // A forced level is compared at the pixel's own footprint.
    const scenes::Scene scene = scenes::parseScene(splitFir(24, 18, 1e-3), "test.json");
    MultiscaleOptions forced;
    forced.forceLevel = 3;
    EXPECT_EQ(renderMultiscale(buildTracedScene(scene), forced).stats.coneRays, 24u * 18u);
}

TEST(MultiscaleTracer, ImageIsTheSameWhateverTheThreadCount)
{
    const std::string json = firScene(R"("diffuse", "specular", "shadows", "self_shadowing")");
    RenderResult one, two;
    {
        tbb::global_control limit(tbb::global_control::max_allowed_parallelism, 1);
        one = render(json);
    }
    {
        tbb::global_control limit(tbb::global_control::max_allowed_parallelism, 2);
        two = render(json);
    }
    EXPECT_EQ(one.image.rgba, two.image.rgba);
    EXPECT_EQ(one.image.aovs, two.image.aovs);
    EXPECT_EQ(one.stats.shadowRays, two.stats.shadowRays);
    EXPECT_EQ(one.stats.diffuseEvaluations, two.stats.diffuseEvaluations);
}

TEST(MultiscaleTracer, AVariantsCopiesNeedNoCopyOfItsTree)
{
    // The method's parts keep no grown tree: a variant's copies take their boughs and branches
    // from its first tree, moved, exactly as from a moved copy of it.
    const scenes::Scene scene = scenes::parseScene(test::variantForest(), "variants.json");
    const TracedScene copied = buildTracedScene(scene);
    const TracedScene lean = buildTracedScene(scene, renderMethod("multiscale").parts);
    ASSERT_EQ(lean.boughs.size(), copied.boughs.size());
    ASSERT_EQ(lean.branches.size(), copied.branches.size());
    int moved = 0;
    for (std::size_t i = 0; i < lean.boughs.size(); ++i) {
        const TracedBough &a = lean.boughs[i], &b = copied.boughs[i];
        EXPECT_EQ(a.base_cm, b.base_cm);
        EXPECT_EQ(a.tip_cm, b.tip_cm);
        EXPECT_EQ(a.across, b.across);
        EXPECT_EQ(a.seed, b.seed);
        EXPECT_EQ(a.barkRadius_cm, b.barkRadius_cm);
        EXPECT_EQ(a.tree, b.tree);
        moved += scene.trees[std::size_t(a.tree)].variantOf >= 0;
    }
    EXPECT_GT(moved, 0);
    for (std::size_t i = 0; i < lean.branches.size(); ++i) {
        EXPECT_EQ(lean.branches[i].base_cm, copied.branches[i].base_cm);
        EXPECT_EQ(lean.branches[i].tip_cm, copied.branches[i].tip_cm);
        EXPECT_EQ(lean.branches[i].radius_cm, copied.branches[i].radius_cm);
    }
    // A count is an expected value from the boughs' lengths: a moved copy's lengths differ by
    // rounding.
    for (std::size_t i = 0; i < scene.trees.size(); ++i) {
        EXPECT_NEAR(lean.treeCounts[i].needles, copied.treeCounts[i].needles,
                    1e-12 * copied.treeCounts[i].needles);
        EXPECT_EQ(lean.treeCounts[i].branches, copied.treeCounts[i].branches);
    }
    const RenderResult a = renderMultiscale(lean, {}), b = renderMultiscale(copied, {});
    EXPECT_EQ(a.image.rgba, b.image.rgba);
}

TEST(MultiscaleTracer, ALawProfileDroppedIsComputedAgainTheSame)
{
    // Law profiles kept within a budget of one byte: each bough's view and profile from the
    // light is dropped as soon as another is computed, and computed again when asked again.
    const scenes::Scene scene = scenes::parseScene(
        firScene(R"("diffuse", "specular", "shadows", "self_shadowing")", 48, 36), "test.json");
    TracedSceneParts tiny = renderMethod("multiscale").parts;
    tiny.lawProfileBudget_bytes = 1;
    const TracedScene kept = buildTracedScene(scene, renderMethod("multiscale").parts);
    const TracedScene dropped = buildTracedScene(scene, tiny);
    MultiscaleOptions level3;
    level3.forceLevel = 3;
    const RenderResult a = renderMultiscale(kept, level3), b = renderMultiscale(dropped, level3);
    EXPECT_EQ(a.image.rgba, b.image.rgba);
    EXPECT_EQ(a.image.aovs, b.image.aovs);
    EXPECT_EQ(a.stats.shadowRays, b.stats.shadowRays);
    const LawProfileCounts once = lawProfileCounts(kept), again = lawProfileCounts(dropped);
    EXPECT_EQ(once.views.dropped, 0u);
    EXPECT_EQ(once.fromLights.dropped, 0u);
    EXPECT_GT(once.views.computed, 0u);
    EXPECT_GT(once.fromLights.computed, 0u);
    EXPECT_GT(again.views.computed, once.views.computed);
    EXPECT_GT(again.fromLights.computed, once.fromLights.computed);
    EXPECT_GT(again.views.dropped + again.fromLights.dropped, 0u);
}

TEST(MultiscaleTracer, ItsLeanTracedSceneRendersTheSameImage)
{
    // The method's parts release the grown trees (keeping their counts), and a bough's view
    // keeps only the profiles the scene's effects read: the same image, and each dropped
    // profile is 0 where the full effects keep a sampled one.
    const scenes::Scene scene =
        scenes::parseScene(firScene(R"("diffuse", "shadows")", 48, 36), "test.json");
    const TracedScene full = buildTracedScene(scene);
    const TracedScene lean = buildTracedScene(scene, renderMethod("multiscale").parts);
    ASSERT_FALSE(full.trees.empty());
    EXPECT_TRUE(lean.trees.empty());
    ASSERT_EQ(lean.treeCounts.size(), full.trees.size());
    for (std::size_t i = 0; i < full.trees.size(); ++i) {
        EXPECT_EQ(lean.treeCounts[i].needles, full.trees[i].counts().needles);
        EXPECT_EQ(lean.treeCounts[i].branches, full.trees[i].counts().branches);
    }
    const RenderResult a = renderMultiscale(full, {}), b = renderMultiscale(lean, {});
    EXPECT_EQ(a.image.rgba, b.image.rgba);
    EXPECT_EQ(a.image.aovs, b.image.aovs);
    EXPECT_GT(b.stats.boughHits, 0u);

    const scenes::Scene every = scenes::parseScene(
        firScene(R"("diffuse", "specular", "shadows", "self_shadowing")", 48, 36), "test.json");
    const TracedScene all = buildTracedScene(every, renderMethod("multiscale").parts);
    const std::shared_ptr<const BoughView> allView = all.boughs.front().view();
    const std::shared_ptr<const BoughView> leanView = lean.boughs.front().view();
    const BoughLighting& kept = allView->lighting.at(0);
    const BoughLighting& dropped = leanView->lighting.at(0);
    EXPECT_FALSE(kept.diffuse.front.isConstant());
    EXPECT_FALSE(kept.specular.front.isConstant());
    EXPECT_FALSE(kept.transfer.front.isConstant());
    EXPECT_FALSE(dropped.diffuse.front.isConstant());
    for (const StripProfile* p : {&dropped.specular.front, &dropped.specular.rear,
                                  &dropped.transfer.front, &dropped.transfer.rear}) {
        EXPECT_TRUE(p->isConstant());
        EXPECT_EQ(p->mean(), 0.0);
    }
}

TEST(MultiscaleTracer, SwitchedOffShadowsCastNoShadowRay)
{
    const RenderResult off = render(firScene(R"("diffuse")"));
    const RenderResult on = render(firScene(R"("diffuse", "shadows")"));
    EXPECT_EQ(off.stats.shadowRays, 0u);
    EXPECT_GT(on.stats.shadowRays, 0u);
    // Shadows only remove light.
    double litOff = 0.0, litOn = 0.0;
    for (std::size_t i = 0; i < off.image.rgba.size(); i += 4) {
        litOff += off.image.rgba[i + 1];
        litOn += on.image.rgba[i + 1];
    }
    EXPECT_LT(litOn, litOff);
}

TEST(MultiscaleTracer, SwitchedOffSpecularCostsNothingAndLeavesDiffuseUnchanged)
{
    const RenderResult off = render(firScene(R"("diffuse", "shadows")"));
    const RenderResult on = render(firScene(R"("diffuse", "shadows", "specular")"));
    EXPECT_EQ(off.stats.specularEvaluations, 0u);
    EXPECT_GT(on.stats.specularEvaluations, 0u);
    EXPECT_EQ(off.image.aovs.at("diffuse"), on.image.aovs.at("diffuse"));
    for (const float s : off.image.aovs.at("specular")) ASSERT_EQ(s, 0.0f);
    EXPECT_EQ(off.stats.shadowRays, on.stats.shadowRays);  // the same plan otherwise
}

TEST(MultiscaleTracer, SwitchedOffSelfShadowingMarchesNothing)
{
    const RenderResult off = render(firScene(R"("diffuse")"));
    const RenderResult on = render(firScene(R"("diffuse", "self_shadowing")"));
    EXPECT_EQ(off.stats.selfShadowEvaluations, 0u);
    EXPECT_GT(on.stats.selfShadowEvaluations, 0u);
    EXPECT_EQ(off.image.aovs.at("foliage"), on.image.aovs.at("foliage"));  // coverage unchanged
}

TEST(MultiscaleTracer, SwitchedOffDiffuseEvaluatesNoDiffuse)
{
    const RenderResult r = render(firScene(R"("specular")"));
    EXPECT_EQ(r.stats.diffuseEvaluations, 0u);
    EXPECT_GT(r.stats.specularEvaluations, 0u);
}

TEST(MultiscaleTracer, NeedleAndConeLevelsAgreeOnHowMuchTheFoliageCovers)
{
    // Forced to one level everywhere, the fir's total coverage: levels 1 and 2 both cross the
    // true cones (explicit needles of width 2r, or continuous cones of opacity A = 2Nr/(pi R),
    // the needles' mean coverage), so they must agree up to the needles' sampling.
    const std::string json = firScene(R"("diffuse")", 160, 120);
    double coverage[3] = {0, 0, 0};
    for (int level = 1; level <= 2; ++level) {
        const RenderResult r = render(json, level);
        for (const float f : r.image.aovs.at("foliage")) coverage[level] += f;
    }
    EXPECT_NEAR(coverage[1] / coverage[2], 1.0, 0.15) << coverage[1] << " " << coverage[2];
}

// One long bough along x, seen side-on from -y, unlit: only coverage matters.
struct SideOnBough {
    scenes::Scene scene;
    TracedScene traced;
    explicit SideOnBough(const BoughLaw& law = boughLaw("linear"),
                         const std::string& effects = R"("diffuse")")
    {
        scene = scenes::parseScene(R"({"name": "side-on bough",
  "camera": {"position": [0, -30, 0], "look_at": [0, 0, 0], "up": [0, 0, 1], "fov_deg": 30,
             "resolution": [120, 90]},
  "lights": [{"type": "directional", "direction": [0, -1, 0.2]}],
  "ground": {"type": "none"}, "species": {}, "trees": [], "effects": [)" + effects + "]}",
                                   "side-on.json");
        // The paper's layers: these tests check section 6 and errata E11-E12 as printed.
        scene.render.model = scenes::ModelChoices::paper();
        traced = buildTracedScene(scene);
        BoughDescription d;
        d.spec.base_cm = Vec3(-40, 0, 0);
        d.spec.tip_cm = Vec3(40, 0, 0);
        d.spec.needles = analytic::paperBough();
        traced.boughs.push_back(
            makeTracedBough(d, scene.camera.position_cm, traced.lights, law, *traced.layers));
        indexPrimitives(traced);
    }
};

// A law of fixed numbers, to see where each of them goes.
class FixedLaw final : public BoughLaw {
public:
    BoughShading shade(const TracedBough&, const Vec3&, const std::vector<Vec3>& towardsLights,
                       const LayerModel&, const BoughLawNeeds&) const override
    {
        ++calls;
        BoughShading s;
        s.alpha = {StripProfile::constant(0.3), StripProfile::constant(0.2)};
        for (std::size_t i = 0; i < towardsLights.size(); ++i) {
            BoughLightTransfer light;
            light.transfer = {StripProfile::constant(0.1), StripProfile::constant(0.05)};
            s.lights.push_back(light);
        }
        return s;
    }
    StripProfile opacityFromLight(const TracedBough&, const Vec3&,
                                  const LayerModel&) const override
    {
        ++opacityCalls;
        return StripProfile::constant(0.5);
    }
    mutable std::atomic<int> calls = 0, opacityCalls = 0;
};

TEST(BoughLaw, EveryBoughLevelQuantityComesFromTheLawOnceAndOnlyWhenNeeded)
{
    // The view opacity, each light's transfer and the opacity seen from the light all come
    // from the law the bough was made with: level 3 shows exactly its numbers. Each is asked
    // of the law once, when first needed: a bough is made without calling it.
    const FixedLaw law;
    SideOnBough s(law, R"("diffuse", "self_shadowing")");
    EXPECT_EQ(law.calls, 0);
    EXPECT_EQ(law.opacityCalls, 0);
    const TracedBough& b = s.traced.boughs.front();
    MultiscaleOptions level3;
    level3.forceLevel = 3;
    const RenderResult r = renderMultiscale(s.traced, level3);
    EXPECT_EQ(law.calls, 1);  // from two threads, many pixels
    EXPECT_EQ(law.opacityCalls, 0);  // no shadow cone meets the only bough
    EXPECT_EQ(b.view()->alpha.front.mean(), 0.3);
    EXPECT_EQ(b.view()->lighting.at(0).transfer.rear.mean(), 0.05);
    EXPECT_EQ(b.opacityFromLight(0)->mean(), 0.5);
    EXPECT_EQ(b.opacityFromLight(0)->mean(), 0.5);
    EXPECT_EQ(law.calls, 1);
    EXPECT_EQ(law.opacityCalls, 1);
    const float* centre = r.image.pixel(r.image.width / 2, r.image.height / 2);
    EXPECT_NEAR(centre[3], 1.0 - (1.0 - 0.3) * (1.0 - 0.2), 1e-6);
    // With self-shadowing each half reflects the law's transfer (not its opacity), the rear
    // seen through the front: G = (0.1 I_front + (1 - 0.3) 0.05 I_rear) a_G E_G / pi.
    const std::shared_ptr<const BoughView> view = b.view();
    const BoughLighting& lit = view->lighting.at(0);
    const double E = s.traced.lights.at(0).power.y, albedo = b.needleAlbedo.y;
    const double expected =
        (0.1 * lit.front.diffuse + 0.7 * 0.05 * lit.rear.diffuse) * albedo / analytic::kPi * E;
    EXPECT_NEAR(centre[1], expected, 1e-6 * expected);
}

// Calls f, which must throw an InputError whose message holds `text`.
template <class F>
void expectInputError(F&& f, const std::string& text)
{
    try {
        f();
        ADD_FAILURE() << "no InputError";
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find(text), std::string::npos) << e.what();
    }
}

TEST(BoughLaw, UnknownNameIsRefusedWithTheKnownOnes)
{
    expectInputError([] { boughLaw("quadratic"); }, "exact, linear, corrected");
    // The first registered is the scene's default.
    EXPECT_EQ(boughLawNames().front(), scenes::ModelChoices{}.boughLaw);
    EXPECT_EQ(layerModelNames().front(), scenes::ModelChoices{}.layerModel);
    // A scene that names an unknown one is refused before any work, with its key.
    scenes::Scene scene = scenes::parseScene(firScene(R"("diffuse")", 16, 12), "fir.json");
    scene.render.model.layerModel = "foam";
    expectInputError([&] { buildTracedScene(scene); },
                     "fir.json: render.layer_model: unknown layer model 'foam' (known: fibre, "
                     "arcs, paper)");
    EXPECT_EQ(shadowOriginNames().front(), scenes::ModelChoices{}.shadowOrigin);
    scene.render.model = {};
    scene.render.model.shadowOrigin = "sun";
    expectInputError([&] { buildTracedScene(scene); },
                     "fir.json: render.shadow_origin: unknown shadow origin 'sun' (known: "
                     "needles, axis, bough)");
    EXPECT_EQ(layerCorrelationNames().front(), scenes::ModelChoices{}.layerCorrelation);
    scene.render.model = {};
    scene.render.model.layerCorrelation = "some";
    expectInputError([&] { buildTracedScene(scene); },
                     "fir.json: render.layer_correlation: unknown layer correlation 'some' "
                     "(known: needles, independent)");
    EXPECT_EQ(needleEndNames().front(), scenes::ModelChoices{}.needleEnds);
    EXPECT_EQ(scenes::ModelChoices::paper().needleEnds, "flat");  // the published truth
    scene.render.model = {};
    scene.render.model.needleEnds = "round";
    expectInputError([&] { buildTracedScene(scene); },
                     "fir.json: render.needle_ends: unknown needle ends 'round' (known: open, "
                     "flat)");
    EXPECT_EQ(occluderProfileNames().front(), scenes::ModelChoices{}.occluderProfile);
    EXPECT_EQ(scenes::ModelChoices::paper().occluderProfile, "even");
    scene.render.model = {};
    scene.render.model.occluderProfile = "ends";
    expectInputError([&] { buildTracedScene(scene); },
                     "fir.json: render.occluder_profile: unknown occluder profile 'ends' (known: "
                     "cones, even)");
}

TEST(MultiscaleTracer, ConeLevelCrossesTheTrueCones)
{
    // Seen side-on, a ray at offset x from the axis meets the true cones' hyperbolas
    // h - h_j = sqrt(x^2 + y^2) cot(phi) over a change of (R - |x|) cot(phi) per half chord:
    // N in {floor(n), ceil(n)} crossings, mean n = 2 (R - |x|) cot(phi) / dh. Along the bough
    // the offsets of the cones vary, so each row's mean opacity must be
    // 1 - [(1 - f) T^floor(n) + f T^ceil(n)], T = 1 - A, f = frac(n). (Section 6.2's asymptotes
    // would give 2 sqrt(R^2 - x^2) cot(phi) / dh instead: errata E12.)
    SideOnBough s;
    MultiscaleOptions options;
    options.forceLevel = 2;
    const RenderResult r = renderMultiscale(s.traced, options);
    const TracedBough& b = s.traced.boughs.front();
    const ConeCamera camera(s.scene.camera);
    const double T = 1.0 - b.layerOpacity, R = b.radius_cm;
    const double cotPhi = 1.0 / std::tan(b.geometry.cone.aperture_rad),
                 dh = b.geometry.coneSpacing_cm;
    int rows = 0;
    for (int y = 0; y < camera.height(); ++y) {
        Passage p;
        const ConeRay ray = camera.cone(camera.width() / 2, y);
        if (!closestPassage(ray, b.base_cm, b.tip_cm, p) || p.gap + 0.5 * ray.width(p.t) > R)
            continue;
        const double n = 2.0 * (R - p.gap) * cotPhi / dh, f = n - std::floor(n);
        const double expected =
            1.0 - ((1 - f) * std::pow(T, std::floor(n)) + f * std::pow(T, std::floor(n) + 1));
        double mean = 0.0;
        const int x0 = camera.width() / 4, x1 = 3 * camera.width() / 4;  // away from the ends
        for (int x = x0; x < x1; ++x) mean += r.image.pixel(x, y)[3];
        mean /= (x1 - x0);
        // 60 pixels along the bough sample ~10 cone periods: the mean carries ~1/10 of the
        // per-pixel spread of one crossing (A = 0.23).
        EXPECT_NEAR(mean, expected, 0.04) << "row " << y << " offset " << p.gap << " n " << n;
        ++rows;
    }
    EXPECT_GT(rows, 10);
}

TEST(MultiscaleTracer, BoughLevelCompositesSection66sHalves)
{
    // Level 3 inside the bough's strip: front then rear half, 1 - (1 - alpha_FV)(1 - alpha_RV),
    // the same on every row (section 6.6 averages over the chords).
    SideOnBough s;
    MultiscaleOptions options;
    options.forceLevel = 3;
    const RenderResult r = renderMultiscale(s.traced, options);
    const TracedBough& b = s.traced.boughs.front();
    const std::shared_ptr<const BoughView> view = b.view();
    const FrontRearProfile& alpha = view->alpha;
    const double expected = 1.0 - (1.0 - alpha.front.mean()) * (1.0 - alpha.rear.mean());
    const float centre = r.image.pixel(r.image.width / 2, r.image.height / 2)[3];
    EXPECT_NEAR(centre, expected, 1e-6);
}

TEST(MultiscaleTracer, BranchBeyondTheGroundIsNotShaded)
{
    // A branch under the ground plane is hidden by it: it is neither shaded nor sent shadow
    // rays, though the BVH offers it. The same branch above the ground is.
    const scenes::Scene scene = scenes::parseScene(R"({"name": "buried branch",
  "camera": {"position": [0, -60, 12], "look_at": [0, 0, 0], "up": [0, 0, 1], "fov_deg": 30,
             "resolution": [48, 36]},
  "lights": [{"type": "directional", "direction": [0, -1, 1]}],
  "ground": {"type": "plane", "height": 0}, "species": {}, "trees": [],
  "effects": ["diffuse", "shadows"]})", "buried.json");
    for (const double z : {-1.5, 1.5}) {
        TracedScene traced = buildTracedScene(scene);
        traced.barks.push_back(Vec3(0.3));
        traced.branches.push_back(
            {Vec3(-20, 0, z), Vec3(20, 0, z), 1.0, std::uint32_t(traced.barks.size() - 1)});
        // A conservative box, as a BVH node's may be: it reaches above the ground.
        Aabb box = cylinderBounds(Vec3(-20, 0, z), Vec3(20, 0, z), 1.0);
        box.grow(Vec3(0, -10, 3));
        traced.bvh = Bvh({box});
        const RenderResult r = renderMultiscale(traced);
        EXPECT_GT(r.stats.groundHits, 0u);
        if (z < 0.0) {
            EXPECT_EQ(r.stats.branchHits, 0u);
        } else {
            EXPECT_GT(r.stats.branchHits, 0u);
        }
    }
}

TEST(MultiscaleTracer, EveryShippedSceneRendersFiniteAndBounded)
{
    const std::filesystem::path dir = std::filesystem::path(PINE_SOURCE_DIR) / "scenes";
    int found = 0;
    for (const auto& entry : std::filesystem::directory_iterator(dir)) {
        if (entry.path().extension() != ".json") continue;
        ++found;
        scenes::Scene scene = scenes::loadScene(entry.path());
        // A thumbnail of the same view keeps the test quick.
        const double scale = 64.0 / scene.camera.width;
        scene.camera.width = 64;
        scene.camera.height = std::max(1, int(scene.camera.height * scale));
        const TracedScene traced = buildTracedScene(scene);
        const RenderResult r = renderMultiscale(traced);
        expectBounded(r.image, entry.path().filename().string());
    }
    EXPECT_GE(found, 4);
}

TEST(TracedScene, EachBoughKnowsTheBranchItGrowsOn)
{
    // Level 3 reads where its own branch hides its rear half from that branch's primitive: the
    // branch's fragment is drawn from it. Five firs from two variants, whose copies are moved.
    const TracedScene traced =
        buildTracedScene(scenes::parseScene(test::variantForest(), "v.json"));
    ASSERT_GT(traced.boughs.size(), 100u);
    std::vector<int> growsOn(traced.branches.size(), 0);
    for (const TracedBough& b : traced.boughs) {
        ASSERT_LT(b.branch, traced.branches.size());
        const TracedBranch& branch = traced.branches[b.branch];
        EXPECT_EQ(branch.base_cm, b.base_cm);
        EXPECT_EQ(branch.tip_cm, b.tip_cm);
        EXPECT_EQ(branch.tree, b.tree);
        EXPECT_GT(b.barkRadius_cm, 0.0);  // render.bark "solid", the default
        EXPECT_EQ(std::min(branch.radius_cm, b.radius_cm), b.barkRadius_cm);
        ++growsOn[b.branch];
    }
    // One bough a branch at most; the trunk's segments bear none.
    EXPECT_EQ(*std::max_element(growsOn.begin(), growsOn.end()), 1);
    EXPECT_GT(std::count(growsOn.begin(), growsOn.end(), 0), 0);
}

TEST(TracedScene, TheFirstTreeItCannotHoldIsNamed)
{
    // Tree 0 is bough.json's; trees 1 to 40 reach past kMaxCoordinate_cm. The trees are
    // described in parallel: whichever thread meets one first, the error names the lowest.
    std::ifstream in(std::string(PINE_SOURCE_DIR) + "/scenes/bough.json");
    std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    const std::string tree = R"({"species": "branch", "position": [0, 0, 30], "seed": 1})";
    std::string trees = tree;
    for (int k = 1; k <= 40; ++k) {
        trees += R"(, {"species": "branch", "position": [)" + std::to_string(k) + R"(e9, 0, 30]})";
    }
    const std::size_t at = text.find(tree);
    ASSERT_NE(at, std::string::npos);
    text.replace(at, tree.size(), trees);
    const scenes::Scene scene = scenes::parseScene(text, "many.json");
    ASSERT_EQ(scene.trees.size(), 41u);
    for (int run = 0; run < 4; ++run) {
        try {
            (void)buildTracedScene(scene);
            ADD_FAILURE() << "trees at 1e9 cm and more were traced";
        } catch (const InputError& e) {
            EXPECT_EQ(
                std::string(e.what()).rfind("many.json: tree 1: a branch reaches (1e+09, 0, "), 0u)
                << e.what();
        }
    }
    // Within the bound, traced.
    scenes::Scene near = scene;
    near.trees.resize(2);
    near.trees[1].base_cm = Vec3(kMaxCoordinate_cm - 100.0, 0.0, 30.0);
    EXPECT_NO_THROW((void)buildTracedScene(near));
}

}  // namespace
}  // namespace pine::vdbtrace
