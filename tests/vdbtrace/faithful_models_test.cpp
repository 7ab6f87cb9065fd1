// The faithful models against the explicit needles they stand for (issue: every approximation
// a switch): one long paper bough seen side-on and at 60 and 30 degrees from its branch, each
// level's mean strip opacity under each layer model and bough law against the geometry
// method's needles.
#include "pine/analytic/bough_shader.h"
#include "pine/bake/tree_grids.h"
#include "pine/scenes/scene.h"
#include "pine/vdbtrace/cone_crossings.h"
#include "pine/vdbtrace/effects_plan.h"
#include "pine/vdbtrace/fragment.h"
#include "pine/vdbtrace/geometry_tracer.h"
#include "pine/vdbtrace/image_diff.h"
#include "pine/vdbtrace/layer_model.h"
#include "pine/vdbtrace/multiscale_tracer.h"
#include "pine/vdbtrace/needle_layout.h"
#include "pine/vdbtrace/reference_tracer.h"
#include "pine/vdbtrace/traced_scene.h"

#include "test_scenes.h"

#include <glm/geometric.hpp>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <string>

namespace pine::vdbtrace {
namespace {

constexpr double kPi = analytic::kPi;

// A paper bough (N 12, r 0.05, l 4.25, phi pi/8, dh 0.9) 200 cm long through the origin, its
// branch at `angle_deg` from the view direction, seen from 400 cm with a 9 degree field: its
// ends lie outside the frame, so the image's total opacity is the strip's mean opacity times
// its area, the same area for every method.
struct LongBough {
    scenes::Scene scene;
    TracedScene traced;
    LongBough(double angle_deg, const scenes::ModelChoices& model, unsigned seed = 7,
              const std::string& effects = R"("diffuse")",
              const std::string& towardsLight = "[0.3, -1, 0.6]")
    {
        scene = scenes::parseScene(R"({"name": "long bough",
  "camera": {"position": [0, -400, 0], "look_at": [0, 0, 0], "up": [0, 0, 1], "fov_deg": 9,
             "resolution": [320, 240]},
  "lights": [{"type": "directional", "direction": )" + towardsLight + R"(}],
  "ground": {"type": "none"}, "species": {}, "trees": [], "effects": [)" + effects + R"(],
  "render": {"background": [0, 0, 0]}})",
                                   "long-bough.json");
        scene.render.model = model;
        traced = buildTracedScene(scene);
        const double a = angle_deg * kPi / 180.0;
        const Vec3 axis(std::sin(a), std::cos(a), 0.0);
        BoughDescription d;
        d.spec.base_cm = -100.0 * axis;
        d.spec.tip_cm = 100.0 * axis;
        d.spec.needles = analytic::paperBough();
        d.seed = seed;
        traced.boughs.push_back(makeTracedBough(
            d, scene.camera.position_cm, traced.lights, boughLaw(model.boughLaw),
            layerModel(model.layerModel, layerCorrelated(model.layerCorrelation)),
            BoughLawNeeds::from(EffectsPlan::from(scene.effects))));
        indexPrimitives(traced);
    }
};

double totalOpacity(const RenderResult& r)
{
    double sum = 0.0;
    for (std::size_t i = 3; i < r.image.rgba.size(); i += 4) sum += r.image.rgba[i];
    return sum;
}

// The light the image sends, summed over its pixels (the green channel: the light is white and
// the needles grey, so any channel is the luminance up to a factor). The background is black.
double totalLight(const RenderResult& r)
{
    double sum = 0.0;
    for (std::size_t i = 1; i < r.image.rgba.size(); i += 4) sum += r.image.rgba[i];
    return sum;
}

double luminanceAt(const Image& image, int x, int y)
{
    const float* c = image.pixel(x, y);
    return luminance(Vec3(c[0], c[1], c[2]));
}

double needles(double angle_deg, unsigned seed)
{
    GeometryOptions g;
    g.samples = 16;
    return totalOpacity(renderGeometry(LongBough(angle_deg, {}, seed).traced, g));
}

double multiscale(double angle_deg, int level, const std::string& layers,
                  const std::string& law = "exact")
{
    scenes::ModelChoices options;
    options.layerModel = layers;
    options.boughLaw = law;
    MultiscaleOptions m;
    m.forceLevel = level;
    return totalOpacity(renderMultiscale(LongBough(angle_deg, options).traced, m));
}

TEST(FaithfulModels, EveryLevelCoversWhatTheNeedlesCover)
{
    // The needles' mean over 6 rolls (each cone's roll drives where its needles point): the
    // spread of that mean is printed and must stay under 1%, so that 3% measures the models.
    // Level 1 draws the needles themselves whatever the model. Under the paper's choices
    // level 2 covers about 0.8 of the needles (errata E13) and the clamped linear law
    // overshoots at level 3 (E11); both are printed, not asserted.
    for (const double angle : {90.0, 60.0, 30.0}) {
        constexpr int kRolls = 6;
        double sum = 0.0, sum2 = 0.0;
        for (unsigned seed = 1; seed <= kRolls; ++seed) {
            const double x = needles(angle, seed);
            sum += x;
            sum2 += x * x;
        }
        const double truth = sum / kRolls;
        const double spread =
            std::sqrt(std::max(0.0, sum2 / kRolls - truth * truth) / (kRolls - 1)) / truth;
        const double l1 = multiscale(angle, 1, "fibre") / truth;
        std::printf(
            "%3.0f deg from the branch, against the needles (spread of their mean "
            "%.2f%%): level 1 %.4f; paper level 2 %.4f, level 3 linear %.4f\n",
            angle, 100.0 * spread, l1, multiscale(angle, 2, "paper") / truth,
            multiscale(angle, 3, "paper", "linear") / truth);
        EXPECT_LT(spread, 0.01) << angle;
        EXPECT_NEAR(l1, 1.0, 0.03) << angle;
        for (const char* layers : {"fibre", "arcs"}) {
            const double l2 = multiscale(angle, 2, layers) / truth;
            const double l3 = multiscale(angle, 3, layers) / truth;
            std::printf("  %-5s level 2 %.4f, level 3 exact %.4f\n", layers, l2, l3);
            EXPECT_NEAR(l2, 1.0, 0.03) << angle << " " << layers;
            EXPECT_NEAR(l3, 1.0, 0.03) << angle << " " << layers;
        }
    }
}

const std::string kDiffuse = R"("diffuse")";
const std::string kSelfShadowed = R"("diffuse", "self_shadowing", "shadows")";

// The needles' light on the long bough side-on, lit towards `towards`, in diffuse light alone
// and self-shadowed: each the mean over 4 rolls at 16 spp.
struct NeedlesLight {
    double lit = 0.0, shadowed = 0.0;
};
NeedlesLight needlesLight(const char* towards)
{
    constexpr int kRolls = 4;
    NeedlesLight out;
    for (unsigned seed = 1; seed <= kRolls; ++seed) {
        GeometryOptions g;
        g.samples = 16;
        const auto light = [&](const std::string& effects) {
            return totalLight(
                renderGeometry(LongBough(90.0, {}, seed, effects, towards).traced, g));
        };
        out.lit += light(kDiffuse);
        out.shadowed += light(kSelfShadowed);
    }
    out.lit /= kRolls;
    out.shadowed /= kRolls;
    return out;
}

TEST(FaithfulModels, ALoneBoughUnderEveryLight)
{
    // The long bough side-on, lit from six directions, its needles' light against each level's
    // (the needles' mean over 4 rolls). In diffuse light alone the needles are lit whatever
    // lies between them and the light: level 1, which draws the needles, must then send their
    // light (needleDiffuse, section 4), and every level's is printed. Measured 1.002-1.008
    // under three lights, 1.030-1.039 along the branch and from behind (1.039 at 4x the
    // pixels too, its coverage within 0.1%: level 1's light per unit coverage, not its
    // strips' ends); bounded at 4.5%. Until the needles' ends were open (render.needle_ends)
    // the flat ends' light, 6% of the needles' along the branch, hid that excess. With
    // self-shadowing nothing else shades the bough: each level's ratio is the self-shadowing
    // model's error under that light (the explicit needles' shadow rays against the layer model's
    // transmittance through the bough), under each layer correlation, and with the "arcs" layer
    // model. Beside the camera the lines of the view and of the light pass the same gaps (the
    // hot spot): "needles" must then agree with the needles within 3% at every level, with
    // either model, where "independent" gets 0.84 of their light. The other lights are printed
    // for docs/models.md ("Layer correlation", "Crossing arcs"), not asserted: their 3% is
    // issue 9's open target.
    struct Light {
        const char* name;
        const char* towards;
        bool hotSpot = false;  ///< beside the view: asserted
    };
    const Light lights[] = {{"the camera's side, above, 34 deg from the view", "[0.3, -1, 0.6]"},
                            {"beside the camera, 3 deg", "[0, -1, 0.05]", true},
                            {"along the branch, 90 deg", "[1, 0, 0.3]"},
                            {"overhead, 90 deg", "[0, 0, 1]"},
                            {"behind, above, 146 deg", "[0.3, 1, 0.6]"},
                            {"behind, low, 174 deg", "[0, 1, 0.1]"}};
    const std::string& diffuse = kDiffuse;
    const std::string& selfShadowed = kSelfShadowed;
    const auto level = [](int n, const std::string& effects, const char* towards,
                          const char* correlation = "needles", const char* layers = "fibre") {
        scenes::ModelChoices model;
        model.layerCorrelation = correlation;
        model.layerModel = layers;
        MultiscaleOptions m;
        m.forceLevel = n;
        return totalLight(
            renderMultiscale(LongBough(90.0, model, 7, effects, towards).traced, m));
    };
    for (const Light& light : lights) {
        const auto [lit, shadowed] = needlesLight(light.towards);
        ASSERT_GT(lit, 0.0) << light.name;
        const double l1 = level(1, diffuse, light.towards) / lit;
        std::printf("lit from %s (the needles' self-shadowing lets %.3f through):\n"
                    "  diffuse alone: level 1 %.3f, level 2 %.3f, level 3 %.3f of the needles\n",
                    light.name, shadowed / lit, l1, level(2, diffuse, light.towards) / lit,
                    level(3, diffuse, light.towards) / lit);
        EXPECT_NEAR(l1, 1.0, 0.045) << light.name;
        for (const auto& [layers, correlation] :
             {std::pair{"fibre", "needles"}, std::pair{"fibre", "independent"},
              std::pair{"arcs", "needles"}}) {
            double ratio[3];
            for (int n = 1; n <= 3; ++n) {
                ratio[n - 1] =
                    level(n, selfShadowed, light.towards, correlation, layers) / shadowed;
            }
            std::printf(
                "  self-shadowed, %s, layer correlation %-11s: level 1 %.3f, level 2 "
                "%.3f, level 3 %.3f\n",
                layers, correlation, ratio[0], ratio[1], ratio[2]);
            if (std::string(correlation) == "needles" && light.hotSpot) {
                for (int n = 0; n < 3; ++n) {
                    EXPECT_NEAR(ratio[n], 1.0, 0.03) << light.name << " level " << n + 1;
                }
            }
        }
    }
}

}  // namespace
}  // namespace pine::vdbtrace

namespace pine::vdbtrace {
namespace {

// Two paper boughs 300 cm long, 15 cm apart, side-on from 400 cm through a frame 120 x 30 cm
// whose pixels are q dh wide: the same view at every q, so that only the level changes.
struct RecedingBoughs {
    scenes::Scene scene;
    TracedScene traced;
    double pixel_cm;  ///< a pixel's width at the boughs
    explicit RecedingBoughs(double q) : pixel_cm(q * 0.9)
    {
        const int height = std::max(2, int(std::lround(30.0 / pixel_cm)));
        const double fov = 2.0 * std::atan(0.5 * height * pixel_cm / 400.0) * 180.0 / kPi;
        scene = scenes::parseScene(R"({"name": "receding boughs",
  "camera": {"position": [0, -400, 0], "look_at": [0, 0, 0], "up": [0, 0, 1], "fov_deg": )" +
                                       std::to_string(fov) + R"(, "resolution": [)" +
                                       std::to_string(4 * height) + ", " + std::to_string(height) +
                                       R"(]},
  "lights": [{"type": "directional", "direction": [0.3, -1, 0.6]}],
  "ground": {"type": "none"}, "species": {}, "trees": [],
  "effects": ["diffuse", "self_shadowing"]})",
                                   "receding.json");
        traced = buildTracedScene(scene);
        const BoughLawNeeds needs = BoughLawNeeds::from(EffectsPlan::from(scene.effects));
        for (int k = 0; k < 2; ++k) {
            BoughDescription d;
            d.spec.base_cm = Vec3(-150.0, 0.0, 7.5 - 15.0 * k);
            d.spec.tip_cm = Vec3(150.0, 0.0, 7.5 - 15.0 * k);
            d.spec.needles = analytic::paperBough();
            d.seed = 3 + k;
            traced.boughs.push_back(makeTracedBough(
                d, scene.camera.position_cm, traced.lights, boughLaw(scene.render.model.boughLaw),
                *traced.layers, needs));
        }
        indexPrimitives(traced);
    }
};

TEST(FaithfulModels, ARecedingBoughNeitherPopsNorFades)
{
    // Footprint over cone spacing q from 0.05 (needles several pixels wide) to 20 (the bough
    // a few pixels tall) in steps of 1.25x: the boughs' covered width (the area they cover,
    // coverage summed over the pixels times a pixel's area at the boughs, over the frame's
    // width, which rounding to whole pixels changes a little) and their luminance likewise.
    // Neither moves by more than 2% between neighbouring distances (measured: 0.85% and 1.6%
    // with pixels split above q = 0.5, the default; 0.8% and 1.5% with one cone a pixel; split
    // above q = 1, 2.7%: where k changes, each k puts the cones at another phase of the pixel
    // grid, and level 2 near q = 0.75 moves with it).
    // Without the blend of levels (render.level_blend 1) the luminance stepped by 2.2% at
    // q = 0.25; without level 2 taking the law's coverage at the strip's edge the pixel
    // grid's phase moved level 2 by 3% near q = 1. The curve is printed.
    double previousCoverage = 0.0, previousLuminance = 0.0;
    for (double q = 0.05; q < 20.01; q *= 1.25) {
        const RecedingBoughs s(q);
        const RenderResult r = renderMultiscale(s.traced);
        double coverage = 0.0, lum = 0.0;
        const std::size_t pixels = r.image.rgba.size() / 4;
        for (std::size_t i = 0; i < pixels; ++i) {
            coverage += r.image.rgba[4 * i + 3];
            lum += luminance(Vec3(r.image.rgba[4 * i], r.image.rgba[4 * i + 1],
                                  r.image.rgba[4 * i + 2]));
        }
        const double frameWidth_cm = r.image.width * s.pixel_cm;
        coverage *= s.pixel_cm * s.pixel_cm / frameWidth_cm;
        lum *= s.pixel_cm * s.pixel_cm / frameWidth_cm;
        const int level = q < s.scene.render.needleLevelMax         ? 1
                          : q < s.scene.render.model.coneLevelMax ? 2
                                                                  : 3;
        std::printf("q %7.3f  %4dx%-4d  level %d  covered width %.4f cm  luminance %.6f\n", q,
                    r.image.width, r.image.height, level, coverage, lum);
        if (previousCoverage > 0.0) {
            EXPECT_NEAR(coverage / previousCoverage, 1.0, 0.02) << "q " << q;
            EXPECT_NEAR(lum / previousLuminance, 1.0, 0.02) << "q " << q;
        }
        previousCoverage = coverage;
        previousLuminance = lum;
    }
}

}  // namespace
}  // namespace pine::vdbtrace

namespace pine::vdbtrace {
namespace {

double reference(double angle_deg, const std::string& law)
{
    const LongBough s(angle_deg, {});
    bake::BoughSpec spec;
    const TracedBough& b = s.traced.boughs.front();
    spec.base_cm = b.base_cm;
    spec.tip_cm = b.tip_cm;
    spec.needles = b.geometry;
    bake::BakeSettings settings = referenceBake(0.25);
    settings.extinctionLaw = law;
    const bake::TreeGrids grids = bake::bakeBoughs({spec}, settings);
    ReferenceOptions options;
    options.subpixels = 2;
    return totalOpacity(renderReference(s.traced, grids, options));
}

// The reference's light on the long bough side-on (fibre law, 0.25 cm, 2 x 2 rays), with
// `effects` under the light towards `towards`.
double referenceLight(const std::string& effects, const char* towards)
{
    const LongBough s(90.0, {}, 7, effects, towards);
    bake::BoughSpec spec;
    const TracedBough& b = s.traced.boughs.front();
    spec.base_cm = b.base_cm;
    spec.tip_cm = b.tip_cm;
    spec.needles = b.geometry;
    const bake::TreeGrids grids = bake::bakeBoughs({spec}, referenceBake(0.25));
    ReferenceOptions options;
    options.subpixels = 2;
    return totalLight(renderReference(s.traced, grids, options));
}

TEST(FaithfulModels, TheReferencesNeedlesAreLitAsTheNeedlesAre)
{
    // The long bough side-on under four lights, the reference's light against the needles'
    // (their mean over 4 rolls), in diffuse light alone (within 5%) and through the bough
    // itself (within 5%; along the branch, 8%). A needle lies on its cone's layer, so the layers
    // the light reaching it crosses lie where the line has crossed a whole number of layers
    // from it, on its way out and, where it turns back through the layers past the axis, on
    // its way back: read from points between layers, the reference's self-shadowed needles got
    // 0.888, 0.743, 0.816 and 0.702 of the needles' light; with bands spread from the needle
    // and the last divided out, 0.980, 0.814, 0.885 and 0.790; with the layers' places kept
    // through the turn, 1.027, 0.861, 1.017 and 0.963; with the view's bands at an unknown
    // phase (its coverage 1.6% over the needles' where it was about 3%), 1.020, 0.827, 1.004
    // and 0.953 (docs/models.md, "The reference's light"). Those were against needles whose
    // flat ends reflected, 6% of their light along the branch, 3% from behind: against the
    // needles as the models have them (render.needle_ends "open") the reference gets 1.022,
    // 0.951, 1.004 and 1.000 self-shadowed, 1.014, 0.983, 1.019 and 1.027 in diffuse light
    // alone (along the branch 0.927 before).
    struct Light {
        const char* towards;
        double diffuseLeast;  ///< of the reference's light over the needles', diffuse alone
        double least;         ///< of the reference's self-shadowed light over the needles'
    };
    const Light lights[] = {{"[0.3, -1, 0.6]", 0.95, 0.95},
                            {"[1, 0, 0.3]", 0.95, 0.92},
                            {"[0, 0, 1]", 0.95, 0.95},
                            {"[0.3, 1, 0.6]", 0.95, 0.95}};
    for (const Light& light : lights) {
        const auto [lit, shadowed] = needlesLight(light.towards);
        const double d = referenceLight(kDiffuse, light.towards) / lit;
        const double s = referenceLight(kSelfShadowed, light.towards) / shadowed;
        std::printf(
            "reference lit towards %s, against the needles: diffuse alone %.3f, "
            "self-shadowed %.3f (the needles let %.3f through)\n",
            light.towards, d, s, shadowed / lit);
        EXPECT_GT(d, light.diffuseLeast) << light.towards;
        EXPECT_LT(d, 1.05) << light.towards;
        EXPECT_GT(s, light.least) << light.towards;
        EXPECT_LT(s, 1.05) << light.towards;
    }
}

TEST(FaithfulModels, TheReferenceFieldsAgainstTheNeedles)
{
    // The reference at 0.25 cm on the long bough side-on and at 60 and 30 degrees. The fibre
    // law (evenly spaced needles, each layer crossing stopping a line with probability n)
    // covers the needles within 3%. A quadrature across the strip, written apart from this
    // code, predicts the others side-on: the layer law 0.613 and the Poisson law 0.716, where
    // an independent Monte Carlo of the explicit needles gives 0.756 (DESIGN.md), 0.81 and
    // 0.95 of the needles; 3% leaves room for the voxels' boundary (O(h / R)).
    for (const double angle : {90.0, 60.0, 30.0}) {
        double truth = 0.0;
        for (unsigned seed = 1; seed <= 6; ++seed) truth += needles(angle, seed) / 6.0;
        const double fibre = reference(angle, "fibre") / truth;
        std::printf("reference %2.0f deg from the branch, against the needles: fibre law %.4f",
                    angle, fibre);
        EXPECT_NEAR(fibre, 1.0, 0.03) << angle;
        if (angle == 90.0) {
            const double poisson = reference(angle, "poisson") / truth;
            const double layer = reference(angle, "layer") / truth;
            std::printf(", Poisson law %.4f, layer law %.4f", poisson, layer);
            EXPECT_NEAR(poisson, 0.716 / 0.756, 0.03);
            EXPECT_NEAR(layer, 0.613 / 0.756, 0.03);
        }
        std::printf("\n");
    }
}

TEST(FaithfulModels, ALineThroughABoughAtEveryAngle)
{
    // What an occluding bough lets through: straight lines across the long bough at angle
    // alpha to its axis, towards its tip or its base, at every azimuth about it and offset
    // across it (its middle 40 cm, away from its ends), the mean transmittance of those that
    // meet its cones' region: the explicit needles (each line enters one's side or not, as the
    // ground truth's open-ended needles stop it), the fibre layer model (cone_crossings.h: the
    // bands where the cones lie) and the reference's field (its bands at an unknown phase,
    // layer_bands.h) at 0.25 and 0.125 cm, each over the lines within a coarse voxel of the
    // region. Measured: the layer model 0.929 to 1.040 of the needles down to 20 degrees
    // (0.949 to 1.040 against solid needles, whose ends stop lines along them); the field
    // 0.951-0.963 of the model at 0.25 cm and within 0.8% at 0.125. With its bands begun where a
    // line enters (until 2026-12-06) the field let through 0.914-0.93 of the model at 0.25 cm and
    // 0.967 side-on at 0.125 (docs/models.md, "The reference's light").
    const LongBough s(90.0, {});
    const TracedBough& b = s.traced.boughs.front();  // along x, from -100 to 100 cm
    const NeedleLayout needles(b);
    const double r = needles.radius(), l = needles.length(), R = b.radius_cm;
    const int N = needles.needlesPerCone();
    const LayerModel& fibre = layerModel("fibre", false);
    bake::BoughSpec spec;
    spec.base_cm = b.base_cm;
    spec.tip_cm = b.tip_cm;
    spec.needles = b.geometry;
    const bake::TreeGrids coarse = bake::bakeBoughs({spec}, referenceBake(0.25));
    const bake::TreeGrids fine = bake::bakeBoughs({spec}, referenceBake(0.125));
    FieldTransmittance coarseField(coarse), fineField(fine);
    constexpr long kLines = 12000;
    for (const double alpha : {90.0, 60.0, 45.0, 30.0, 20.0}) {
        for (const double towardsTip : {1.0, -1.0}) {
            if (alpha == 90.0 && towardsTip < 0.0) continue;  // the same lines
            std::mt19937_64 rng(1);
            std::uniform_real_distribution<double> u(0.0, 1.0);
            double met = 0.0, byNeedles = 0.0, byModel = 0.0, byCoarse = 0.0, byFine = 0.0;
            const double a = alpha * kPi / 180.0;
            for (long k = 0; k < kLines; ++k) {
                const double beta = 2.0 * kPi * u(rng);
                const Vec3 D(towardsTip * std::cos(a), std::sin(a) * std::cos(beta),
                             std::sin(a) * std::sin(beta));
                // Lines within a coarse voxel of the region: the field blurs its edge by that.
                const double reach = R + 0.25;
                const Vec3 p(-20.0 + 40.0 * u(rng), (2.0 * u(rng) - 1.0) * reach,
                             (2.0 * u(rng) - 1.0) * reach);
                const double far = 60.0;
                const Vec3 o = p - far * D;
                double tIn, tOut;
                if (!intersectCylinder(ConeRay{o, D, 0.0}, b.base_cm, b.conesEnd(), reach, tIn,
                                       tOut)) {
                    continue;
                }
                met += 1.0;
                // The cones whose needles reach the part of the line within the region.
                const double x0 = std::min(o.x + tIn * D.x, o.x + tOut * D.x) - l;
                const double x1 = std::max(o.x + tIn * D.x, o.x + tOut * D.x);
                const double dh = b.geometry.coneSpacing_cm;
                const long j0 = std::max(0L, long(std::floor((x0 - b.base_cm.x) / dh)) - 1);
                const long j1 =
                    std::min(needles.lastCone(), long(std::ceil((x1 - b.base_cm.x) / dh)) + 1);
                bool hit = false;
                for (long j = j0; j <= j1 && !hit; ++j) {
                    const Vec3 apex = needles.apex(j);
                    for (int i = 0; i < N && !hit; ++i) {
                        const Vec3 tip = apex + l * needles.direction(needles.azimuth(j, i));
                        double h;  // the needles as the ground truth draws them, open-ended
                        hit = entersCylinderSide(ConeRay{o, D, 0.0}, apex, tip, r, h);
                    }
                }
                byNeedles += hit ? 0.0 : 1.0;
                double T = 1.0;
                if (layeredInterval(b, o, D, tIn, tOut)) {
                    fibre.layers(b, o, D, tIn, tOut, [&](const LayerHit& layer) {
                        T *= 1.0 - layer.opacity;
                        return T > 0.0;
                    });
                }
                byModel += T;
                byCoarse += coarseField(o, D, 2.0 * far);
                byFine += fineField(o, D, 2.0 * far);
            }
            const double needlesT = byNeedles / met, modelT = byModel / met;
            std::printf(
                "%2.0f deg, towards the %s: the needles let through %.4f; the layer model "
                "%.3f of that; the field %.3f of the model's at 0.25 cm, %.3f at 0.125 cm\n",
                alpha, towardsTip > 0.0 ? "tip " : "base", needlesT, modelT / needlesT,
                byCoarse / byModel, byFine / byModel);
            // The needles' mean is a Monte Carlo of 12,000 lines (1% spread).
            EXPECT_NEAR(modelT / needlesT, 1.0, 0.08) << alpha;
            EXPECT_NEAR(byCoarse / byModel, 1.0, 0.06) << alpha;
            EXPECT_NEAR(byFine / byModel, 1.0, 0.015) << alpha;
        }
    }
}

}  // namespace
}  // namespace pine::vdbtrace

namespace pine::vdbtrace {
namespace {

// Two long paper boughs side-on, 6 cm apart one above the other, lit from above through each
// other (`towards`: towards the light), the lower one in the upper one's shadow; `alone`
// leaves the upper one out. With `twigs` each bough holds its twig (a branch 0.3 cm in radius
// on its axis; the firs' branches start at 0.45 cm); `resolution` "W, H" sets the frame's
// pixels (a pixel 0.17 cm wide at the default 320 x 240, 1.75 cm at 32 x 24). `shift_cm`
// moves the lower bough along its axis.
struct ShadowedBoughs {
    scenes::Scene scene;
    TracedScene traced;
    // segment_cm > 0: the upper bough a chain of boughs that long, end to end, as a fir's
    // branches are (each segment a bough, its cones reaching past its tip over the next).
    ShadowedBoughs(const std::string& towards, unsigned seed, bool alone = false,
                   bool twigs = false, const std::string& resolution = "320, 240",
                   double shift_cm = 0.0, double segment_cm = 0.0,
                   const std::string& occluderProfile = "cones")
    {
        scene = scenes::parseScene(R"({"name": "shadowed boughs",
  "camera": {"position": [0, -400, 0], "look_at": [0, 0, 0], "up": [0, 0, 1], "fov_deg": 6,
             "resolution": [)" + resolution + R"(]},
  "lights": [{"type": "directional", "direction": [)" + towards + R"(]}],
  "ground": {"type": "none"}, "species": {}, "trees": [],
  "effects": ["diffuse", "shadows", "self_shadowing"]})",
                                   "shadowed-boughs.json");
        scene.render.model.occluderProfile = occluderProfile;
        traced = buildTracedScene(scene);
        const BoughLawNeeds needs = BoughLawNeeds::from(EffectsPlan::from(scene.effects));
        const auto base = [&](int k) { return Vec3(-100.0 + k * shift_cm, 0.0, 3.0 - 6.0 * k); };
        const auto tip = [&](int k) { return base(k) + Vec3(200.0, 0.0, 0.0); };
        for (int k = alone ? 1 : 0; k < 2; ++k) {
            if (twigs) {
                traced.branches.push_back(TracedBranch{base(k), tip(k), 0.3});
            }
        }
        const auto add = [&](const Vec3& from, const Vec3& to, unsigned boughSeed) {
            BoughDescription d;
            d.spec.base_cm = from;
            d.spec.tip_cm = to;
            d.spec.needles = analytic::paperBough();
            d.seed = boughSeed;
            traced.boughs.push_back(makeTracedBough(
                d, scene.camera.position_cm, traced.lights,
                boughLaw(scene.render.model.boughLaw), *traced.layers, needs));
        };
        for (int k = alone ? 1 : 0; k < 2; ++k) {
            if (k == 0 && segment_cm > 0.0) {
                const Vec3 step(segment_cm, 0.0, 0.0);
                for (int j = 0; (j + 1) * segment_cm <= 200.0 + 1e-9; ++j) {
                    add(base(k) + double(j) * step, base(k) + double(j + 1) * step,
                        seed + 1000u * unsigned(j + 1));
                }
            } else {
                add(base(k), tip(k), seed + 10u * unsigned(k));
            }
        }
        indexPrimitives(traced);
    }
};

// The luminance of the frame's lower half (the lower bough) and of its upper half.
std::pair<double, double> halves(const RenderResult& r)
{
    double lower = 0.0, upper = 0.0;
    for (int y = 0; y < r.image.height; ++y) {
        for (int x = 0; x < r.image.width; ++x) {
            (2 * y < r.image.height ? upper : lower) += luminanceAt(r.image, x, y);
        }
    }
    return {lower, upper};
}

// The explicit needles' ShadowedBoughs, the mean over kRolls rolls: each bough's luminance
// (halves) and the light the upper one lets through to the lower one (its luminance over
// its luminance alone). Roll r moves the lower bough (r - 1) / kRolls of a cone spacing along
// its axis: boughs whose cones line up (one base, one dh) put the upper one's dense cone
// regions over the lower one's, where a tree's boughs fall at every phase. Lit straight from
// above, aligned they let through 0.150 (8 rolls), over the 8 phases 0.206.
struct NeedlesShadow {
    double lower = 0.0, upper = 0.0, through = 0.0;
};
NeedlesShadow needlesShadow(const std::string& towards, int samples, bool twigs = false,
                            const std::string& resolution = "320, 240", double segment_cm = 0.0)
{
    constexpr int kRolls = 8;
    const double dh = analytic::paperBough().coneSpacing_cm;
    NeedlesShadow out;
    for (unsigned seed = 1; seed <= kRolls; ++seed) {
        GeometryOptions g;
        g.samples = samples;
        const double shift = (seed - 1) * dh / kRolls;
        const auto [lo, up] = halves(renderGeometry(
            ShadowedBoughs(towards, seed, false, twigs, resolution, shift, segment_cm).traced, g));
        const double alone = halves(renderGeometry(ShadowedBoughs(towards, seed, true, twigs,
                                                                  resolution, shift, segment_cm)
                                                       .traced,
                                                   g))
                                 .first;
        out.lower += lo / kRolls;
        out.upper += up / kRolls;
        out.through += lo / alone / kRolls;
    }
    return out;
}

TEST(FaithfulModels, ABoughsShadowIsWhereItsNeedlesCastIt)
{
    // Lit from the camera's side, from straight above (the lower bough in deep shadow, every
    // needle's shadow line through the upper bough's most opaque middle) and from behind.
    // The needles' luminance of each bough (needlesShadow: 8 rolls and phases, 16 spp, each
    // needle's own shadow ray) against each level's. The shadow's error is measured on the
    // light it lets through, as a fraction of the unshadowed bough's: in deep shadow the ratio
    // of two small numbers says little. Measured 2026-12-07, the needles letting through
    // 0.824, 0.206 and 0.507: levels 1-3 0.827, 0.846, 0.802 from the camera's side; 0.183,
    // 0.170, 0.156 from above; 0.469, 0.456, 0.541 from behind; shadow_origin "bough" 0.811,
    // 0.187, 0.461. Bounded at 0.06. (The upper bough read even along its axis,
    // render.occluder_profile "even", its mean taking in its thin ends: 0.193, 0.180 and
    // 0.166 from above.) (The needles with their cones lined up let through 0.147
    // from above, which the levels had been measured against until then.) From behind the
    // needles' flat ends, at their tips, had been a larger share of the lit bough's light
    // (render.needle_ends). Levels 2-3 shade with the layer model's expected self-shadowing
    // and are dark against the needles when the light comes through the bough (measured
    // 0.940 and 0.925 from behind; 0.94 and 0.934 with layer_correlation "independent", whose
    // disjoint arcs of one cone are not anti-correlated; bounded at 9%). Before each hit's
    // shadow cone stood for where its needles lie (ShadowSamples) and the exact law's chords
    // were placed by the cone spacing's phase, the lower bough got 0.91 and 0.94 of the
    // needles' light from the camera's side at levels 1 and 3.
    for (const std::string towards : {"0.2, -0.3, 1", "0, 0, 1", "0.5, 0.3, 1"}) {
        const auto [lower, upper, through] = needlesShadow(towards, 16);
        // Levels 1-3 with shadow_origin "needles", and levels 2-3 with "bough" (each bough's
        // shadows once per frame: bough_shadows.h).
        for (const auto& [level, origin] :
             {std::pair{1, ShadowOrigin::Needles}, std::pair{2, ShadowOrigin::Needles},
              std::pair{3, ShadowOrigin::Needles}, std::pair{2, ShadowOrigin::Bough},
              std::pair{3, ShadowOrigin::Bough}}) {
            MultiscaleOptions m;
            m.forceLevel = level;
            const auto rendered = [&](bool alone) {
                ShadowedBoughs boughs(towards, 1, alone);
                boughs.traced.shadowOrigin = origin;
                return halves(renderMultiscale(boughs.traced, m));
            };
            const auto [lo, up] = rendered(false);
            const double alone = rendered(true).first;
            const char* name = origin == ShadowOrigin::Bough ? "bough" : "needles";
            std::printf("towards [%s] level %d, shadows from the %s, against the needles: upper "
                        "bough %.4f, lower (shadowed) %.4f, its error %+.4f of the upper's; the "
                        "shadow lets through %.4f (needles %.4f)\n",
                        towards.c_str(), level, name, up / upper, lo / lower,
                        (lo - lower) / upper, lo / alone, through);
            EXPECT_NEAR(up / upper, 1.0, 0.09) << towards << " level " << level << " " << name;
            EXPECT_NEAR(lo / alone, through, 0.06) << towards << " level " << level << " " << name;
        }
    }
}

TEST(FaithfulModels, AFarBoughsShadowIsWhereItsNeedlesCastIt)
{
    // The same two boughs, each with its twig, seen from far enough that a pixel (1.75 cm) is
    // as wide as a bough's radius (1.6 cm), as the paper forest's are at level 3, lit from
    // above and from above and aside. Measured: levels 2-3 let through 0.187 and 0.164 from
    // above, where the needles let through 0.199 over 8 phases of the boughs' cones
    // (needlesShadow), and 0.478 and 0.491 aside against 0.462 (read even along the axis,
    // 0.195, 0.172, 0.485 and 0.497). Until 2026-12-07 the needles
    // were rendered with the cones lined up alone, which let through 0.147 from above; each
    // occluder then read the footprint only as wide as the pixel's disc spreads across its
    // strip (none, lit from above), which took levels 2-3 to 0.154 and 0.133 from above and
    // 0.469 and 0.488 aside (the paper forest's and the three firs' per-tree luminance moved
    // by under 0.6%).
    for (const std::string towards : {"0, 0, 1", "0.3, 0.3, 1"}) {
        const double through = needlesShadow(towards, 64, true, "32, 24").through;
        for (const int level : {2, 3}) {
            MultiscaleOptions m;
            m.forceLevel = level;
            const auto lower = [&](bool alone, double shift_cm) {
                return halves(
                           renderMultiscale(
                               ShadowedBoughs(towards, 1, alone, true, "32, 24", shift_cm).traced,
                               m))
                    .first;
            };
            const double ratio = lower(false, 0.0) / lower(true, 0.0);
            // needlesShadow's phases: no level depends on them.
            const double half = 0.5 * analytic::paperBough().coneSpacing_cm;
            EXPECT_NEAR(lower(false, half) / lower(true, half), ratio, 1e-3)
                << towards << " level " << level << ": the phase moved it";
            std::printf("towards [%s] level %d at 1.75 cm a pixel, twigs in: the shadow lets "
                        "through %.4f (needles %.4f)\n",
                        towards.c_str(), level, ratio, through);
            EXPECT_NEAR(ratio, through, 0.04) << towards << " level " << level;
        }
    }
}

TEST(FaithfulModels, AChainsShadowIsWhereItsNeedlesCastIt)
{
    // The upper bough cut into a chain of 6 cm boughs, as a fir's branches are: each bough's
    // strip runs to its cones' end, 3.9 cm past its tip over the next one, where the needles
    // are as dense as along one long bough. Read where the cones reach (render.occluder_profile
    // "cones") the chain lets through what its needles let through; read even at each bough's
    // mean, the neighbours' overlaps compose as two independent strips and the rest at the
    // mean, and from above it lets through about a third more. Measured 2026-12-07 against
    // the needles' 0.185 from above and 0.499 from behind (8 rolls and phases): level 1 0.187
    // and 0.478, level 2 0.176 and 0.465; even, level 1 0.255 and 0.523.
    for (const std::string towards : {"0, 0, 1", "0.5, 0.3, 1"}) {
        const double through = needlesShadow(towards, 16, false, "320, 240", 6.0).through;
        const auto letThrough = [&](int level, const std::string& profile) {
            MultiscaleOptions m;
            m.forceLevel = level;
            const auto lower = [&](bool alone) {
                return halves(renderMultiscale(ShadowedBoughs(towards, 1, alone, false, "320, 240",
                                                              0.0, 6.0, profile)
                                                   .traced,
                                               m))
                    .first;
            };
            return lower(false) / lower(true);
        };
        for (const int level : {1, 2}) {
            const double cones = letThrough(level, "cones");
            std::printf(
                "towards [%s] level %d, a chain of 6 cm boughs read by its cones: the "
                "shadow lets through %.4f (needles %.4f)\n",
                towards.c_str(), level, cones, through);
            EXPECT_NEAR(cones, through, 0.04) << towards << " level " << level;
        }
        const double even = letThrough(1, "even");
        std::printf("towards [%s] level 1, the chain read even: %.4f\n", towards.c_str(), even);
        // From above every shadow line crosses the chain's overlaps, and even errs by 0.07.
        if (towards == "0, 0, 1") {
            EXPECT_GT(even - through, 0.04) << towards << ": reading it even no longer errs";
        }
    }
}

// The explicit needles at 16 spp, or the multiscale method forced to `level`.
RenderResult needlesOrLevel(const TracedScene& traced, bool needles, int level)
{
    if (needles) {
        GeometryOptions g;
        g.samples = 16;
        return renderGeometry(traced, g);
    }
    MultiscaleOptions m;
    m.forceLevel = level;
    return renderMultiscale(traced, m);
}

// How far row y of LongBough's frame lies from the bough's axis, in cm: the frame's rows span
// 2 * 400 tan(4.5 degrees) = 63 cm.
double rowFromAxis_cm(const Image& image, int y)
{
    const double rowsPerCm = image.height / (800.0 * std::tan(4.5 * kPi / 180.0));
    return std::abs(y + 0.5 - 0.5 * image.height) / rowsPerCm;
}

// One long paper bough side-on (LongBough at 90 degrees), lit from straight above, under an
// opaque rod 0.8 cm in radius running along it 6 cm above, moved 1 cm away from the camera:
// the rod's shadow falls on the bough's rear half (y 0.2 to 1.8, the needles reaching 1.6 from
// the axis) and spares its front. The luminance of the bough's rows (z within 3 cm of its
// axis) with the rod, over that without it, so that what the rod itself shows in the frame is
// left out.
double underTheRod(bool rod, int level, unsigned seed, bool needles)
{
    LongBough bough(90.0, {}, seed, R"("diffuse", "shadows", "self_shadowing")", "[0, 0, 1]");
    TracedScene& traced = bough.traced;
    if (rod) {
        traced.branches.push_back(TracedBranch{Vec3(-100, 1, 6), Vec3(100, 1, 6), 0.8});
        indexPrimitives(traced);
    }
    const RenderResult r = needlesOrLevel(traced, needles, level);
    double sum = 0.0;
    for (int y = 0; y < r.image.height; ++y) {
        if (rowFromAxis_cm(r.image, y) > 3.0) continue;
        for (int x = 0; x < r.image.width; ++x) sum += luminanceAt(r.image, x, y);
    }
    return sum;
}

TEST(FaithfulModels, ARodsShadowFallsOnTheRearHalfAlone)
{
    // The rod's shadow edge lies inside the bough's depth, where level 2 places each needle's
    // shadow line at its own depth and level 3 at three points along each half's chord
    // (shadowAcross). Measured 2026-12-05 in LongBough's frame: needles 0.817 (4 rolls); level
    // 2 0.795, level 3 0.796 (in a 160 x 120 frame 6 degrees high: 0.816, 0.801, 0.791).
    // Since each third of level 3's halves is lit by its own points and composited apart
    // (2026-12-07), the rod darkens the light the law's rear half reflects, where before it
    // darkened the mean over both halves weighted by what of each is lit: 0.782, further from
    // the needles and from level 2. No neighbour lies among this bough's needles, so this is
    // the halves lit apart alone, kept for what it gains on the forests (docs/models.md,
    // "Whole scenes"). Bounded at 0.04.
    // Without the rod's shadow they would read 1; with a rod over the whole bough, 0
    // (measured: direct light alone). Level 3's points weighted by where the exact law's lit
    // needles lie along the chord (not kept: docs/models.md, "Where along the chord") read, in that
    // smaller frame, 0.774 with three points a half and 0.824 with six.
    constexpr int kRolls = 4;
    double needles = 0.0;
    for (unsigned seed = 1; seed <= kRolls; ++seed) {
        needles += underTheRod(true, 0, seed, true) / underTheRod(false, 0, seed, true) / kRolls;
    }
    for (const int level : {2, 3}) {
        const double through =
            underTheRod(true, level, 1, false) / underTheRod(false, level, 1, false);
        std::printf(
            "a bough under a rod over its rear half, level %d: the rod lets through %.4f "
            "of the light (needles %.4f)\n",
            level, through, needles);
        EXPECT_NEAR(through, needles, 0.04) << "level " << level;
    }
}

// One long paper bough side-on (LongBough at 90 degrees), lit from the camera's side, with an
// opaque rod `radius_cm` in radius along it inside its front half, its axis `depth_cm` nearer the
// camera than the bough's (the front half's needles reach 1.6 cm towards the camera): the
// foliage each method shows over the rod's middle rows, where the rod covers the pixels, and
// the light of the bough's rows (z within 3 cm of its axis), each summed over the frame.
struct OverTheRod {
    double foliage, light;
};
OverTheRod rodInTheFrontHalf(int level, unsigned seed, bool needles, double radius_cm,
                             double depth_cm)
{
    LongBough bough(90.0, {}, seed, R"("diffuse", "shadows", "self_shadowing")", "[0.1, -1, 0.3]");
    TracedScene& traced = bough.traced;
    traced.branches.push_back(
        TracedBranch{Vec3(-100, -depth_cm, 0), Vec3(100, -depth_cm, 0), radius_cm});
    indexPrimitives(traced);
    const RenderResult r = needlesOrLevel(traced, needles, level);
    OverTheRod sum{0.0, 0.0};
    const std::vector<float>& foliage = r.image.aovs.at("foliage");
    for (int y = 0; y < r.image.height; ++y) {
        const double z = rowFromAxis_cm(r.image, y);
        for (int x = 0; x < r.image.width; ++x) {
            if (z < 0.5 * radius_cm) {
                sum.foliage += foliage[std::size_t(y) * r.image.width + x];
            }
            if (z < 3.0) sum.light += luminanceAt(r.image, x, y);
        }
    }
    return sum;
}

TEST(FaithfulModels, ARodInsideABoughsFrontHalfHidesTheNeedlesBehindIt)
{
    // Level 3 composites each half as three fragments, one at the middle of each third of its
    // chord (shadow_origin "needles"): the rod hides the thirds behind it. As one fragment a
    // half, at the bough's entry, the whole front half showed over the rod and the rod hid
    // the rear: measured 2026-12-07, the foliage over the rod 3.69 and 2.48 times the
    // needles' and the bough's light (the rod's own included) 0.808 and 0.865 of theirs (rod
    // 0.35 cm in radius 0.7 cm in front of the axis, 0.3 cm 0.5 cm in front), now 1.23 and
    // 1.65 times and 0.993 and 0.985. In the second the middle third lies 0.013 cm in front
    // of the rod: its foliage could read either way, the bound holds both. The thirds take even
    // shares of the half's opacity, where the needles thin out away from the axis (their length per
    // volume falls as 1 / rho), so the third in front of the rod still shows more than the needles
    // there.
    for (const auto& [radius, depth] : {std::pair{0.35, 0.7}, std::pair{0.3, 0.5}}) {
        constexpr int kRolls = 4;
        OverTheRod needles{0.0, 0.0};
        for (unsigned seed = 1; seed <= kRolls; ++seed) {
            const OverTheRod n = rodInTheFrontHalf(0, seed, true, radius, depth);
            needles.foliage += n.foliage / kRolls;
            needles.light += n.light / kRolls;
        }
        const OverTheRod m = rodInTheFrontHalf(3, 1, false, radius, depth);
        std::printf(
            "a rod %.2f cm in radius %.1f cm in front of a bough's axis, level 3 against "
            "the needles: the foliage over the rod %.3f, the bough's light %.3f\n",
            radius, depth, m.foliage / needles.foliage, m.light / needles.light);
        EXPECT_NEAR(m.light / needles.light, 1.0, 0.03) << radius << " cm at " << depth;
        EXPECT_LT(m.foliage / needles.foliage, 2.0) << radius << " cm at " << depth;
    }
}

// The walks through a bough with a solid branch of radius 0.4 (render.bark "solid"): needles
// inside the bark (within 0.4 of the axis, between the base and the tip) count for nothing, and
// lines that miss the bark count as without it.
TEST(FaithfulModels, TheBarkHidesTheNeedlesRootsAndNothingElse)
{
    scenes::Scene scene = scenes::parseScene(R"({"name": "bark",
  "camera": {"position": [0, -60, 0], "look_at": [0, 0, 0]},
  "lights": [{"type": "directional", "direction": [0, -1, 1]}],
  "ground": {"type": "none"}, "species": {}, "trees": []})",
                                             "bark.json");
    const TracedScene traced = buildTracedScene(scene);
    BoughDescription d;
    d.spec.base_cm = Vec3(0.0);
    d.spec.tip_cm = Vec3(12.0, 0.0, 0.0);
    d.spec.needles = analytic::paperBough();
    const TracedBough line = makeTracedBough(d, scene.camera.position_cm, traced.lights,
                                             *traced.boughLaw, *traced.layers);
    d.barkRadius_cm = 0.4;
    const TracedBough solid = makeTracedBough(d, scene.camera.position_cm, traced.lights,
                                              *traced.boughLaw, *traced.layers);
    const auto needlesMet = [](const TracedBough& b, const Vec3& o, const Vec3& dir,
                               double length = 1e9) {
        double tIn, tOut, n = 0.0;
        if (!layeredInterval(b, o, dir, tIn, tOut)) return 0.0;
        forEachConeBand(b, o, dir, tIn, std::min(tOut, length), [&](const ConeBand& band) {
            n += band.needles;
            return true;
        });
        return n;
    };
    // Along the axis 0.2 cm from it, within the branch: every needle it passes is a root.
    EXPECT_EQ(needlesMet(solid, Vec3(1.0, 0.2, 0.0), Vec3(1.0, 0.0, 0.0), 10.0), 0.0);
    EXPECT_GT(needlesMet(line, Vec3(1.0, 0.2, 0.0), Vec3(1.0, 0.0, 0.0), 10.0), 0.5);
    for (int k = 0; k < 40; ++k) {
        const double offset = 0.05 * k + 0.013;  // of the line from the axis, cm
        const Vec3 dir = glm::normalize(Vec3(0.3 * std::sin(k), 0.0, 1.0));
        const Vec3 o(6.0 + 0.1 * k, offset, -10.0);
        const double with = needlesMet(solid, o, dir), without = needlesMet(line, o, dir);
        if (offset > 0.4) {
            EXPECT_EQ(with, without) << "a line " << offset << " cm off the axis";
        } else {
            EXPECT_LT(with, without - 0.01) << "a line " << offset << " cm off the axis";
            EXPECT_GE(with, 0.0);
        }
        // The paper's layers: the crossings kept are those outside the bark, all of them.
        int kept = 0, outside = 0;
        double tIn, tOut;
        if (!layeredInterval(solid, o, dir, tIn, tOut)) continue;
        forEachConeCrossing(solid, o, dir, tIn, tOut, [&](long, double t) {
            EXPECT_FALSE(insideBark(solid, o + t * dir));
            ++kept;
        });
        forEachConeCrossing(line, o, dir, tIn, tOut, [&](long, double t) {
            if (!insideBark(solid, o + t * dir)) ++outside;
        });
        EXPECT_EQ(kept, outside);
    }
    // Beyond the tip the last cones' needles are not in the branch.
    EXPECT_FALSE(insideBark(solid, Vec3(12.5, 0.1, 0.0)));
    EXPECT_TRUE(insideBark(solid, Vec3(11.5, 0.1, 0.1)));
}

// Twigs 6 cm long on branches 0.3 cm thick, far apart, seen as the paper forest sees its
// boughs (a footprint of two cone spacings): in the needles' truth the branch hides the
// needles' roots, the darkest of them (7% of the coverage). With render.bark "solid" level 3
// covers what the needles cover within 3% (1.018); with "line" (the paper's axis) it covers
// the roots as well, 9-10% too much, and its self-shadowed needles are darker. Until the
// branch hid the rear half's share where it lies across the strip, not its mean over the
// footprint (its chords are longest over the axis, and more of it lies there), "solid" covered
// 1.049.
TEST(FaithfulModels, ABranchHidesItsNeedlesRoots)
{
    const std::string json = R"({"name": "twigs",
  "camera": {"position": [0, 0, 250], "look_at": [0, 1100, 40], "fov_deg": 30,
             "resolution": [160, 120]},
  "lights": [{"type": "directional", "direction": [-0.5, -0.6, 0.8]}],
  "ground": {"type": "none"},
  "species": {"twig": {
     "lsystem": {"axiom": "[&F]", "iterations": 0, "branch_angle_deg": 60, "segment": 6,
                 "trunk_radius": 0.3, "jitter_deg": 0},
     "needles": {"base": {"aperture_deg": 22.5, "length": 4.25, "radius": 0.05, "per_cone": 12,
                          "cone_spacing": 0.9}}}},
  "trees": [{"scatter": {"species": "twig", "count": 250, "region": [[-300, 800], [300, 1300]],
                         "min_spacing": 22, "seed": 3}}],
  "effects": ["diffuse", "self_shadowing"],
  "render": {"background": [0, 0, 0]}})";
    struct Measured {
        double coverage, luminance;  // the foliage's, and its own luminance per coverage
    };
    const auto measure = [](const RenderResult& r) {
        double coverage = 0.0, own = 0.0;
        for (const float f : r.image.aovs.at("foliage")) coverage += f;
        for (const float f : r.image.aovs.at("foliage_luminance")) own += f;
        return Measured{coverage, own / coverage};
    };
    scenes::Scene scene = scenes::parseScene(json, "twigs.json");
    GeometryOptions g;
    g.samples = 16;
    const Measured truth = measure(renderGeometry(buildTracedScene(scene), g));
    Measured level3[2];
    for (const bool solid : {true, false}) {
        scene.render.model.bark = solid ? "solid" : "line";
        MultiscaleOptions m;
        m.forceLevel = 3;
        level3[solid ? 0 : 1] = measure(renderMultiscale(buildTracedScene(scene), m));
    }
    std::printf("twigs on 0.3 cm branches, level 3 over the needles: solid coverage %.3f "
                "luminance %.3f, line %.3f %.3f\n",
                level3[0].coverage / truth.coverage, level3[0].luminance / truth.luminance,
                level3[1].coverage / truth.coverage, level3[1].luminance / truth.luminance);
    EXPECT_NEAR(level3[0].coverage / truth.coverage, 1.0, 0.03);
    EXPECT_GT(level3[1].coverage / truth.coverage, 1.07);
    EXPECT_LT(std::abs(level3[0].luminance / truth.luminance - 1.0),
              std::abs(level3[1].luminance / truth.luminance - 1.0));
}

// The tracer tests' fir, whose branches (1.3 to 2 cm) are as thick as its boughs' reach, seen
// where its boughs' footprints span the bands about the level thresholds in which two levels
// are mixed (render.level_blend). Each level's fragments are composited alone there, then
// mixed at the bough's front: the bough's own branch must be composited with them, where it
// hides what lies behind it, as it is outside the bands. Behind the mixed fragment it had
// hidden none of its bough: the fir covered 1.214 of the needles, 0.974 without the bands.
TEST(FaithfulModels, ABoughsBranchHidesItsNeedlesWithinALevelBlend)
{
    // One cone a pixel: split pixels (render.pixel_split_q) shade the fir's boughs below the
    // level 3 band.
    scenes::Scene scene = scenes::parseScene(test::firScene(R"("diffuse")", 96, 72), "fir.json");
    scene.render.model.pixelSplitQ = 0.0;
    const TracedScene traced = buildTracedScene(scene);
    const auto coverage = [](const RenderResult& r) {
        double sum = 0.0;
        for (const float f : r.image.aovs.at("foliage")) sum += f;
        return sum;
    };
    GeometryOptions g;
    g.samples = 64;
    const double needles = coverage(renderGeometry(traced, g));
    const RenderResult blended = renderMultiscale(traced);
    scenes::Scene unblended = scene;
    unblended.render.model.levelBlend = 1.0;
    const RenderResult apart = renderMultiscale(buildTracedScene(unblended));
    int mixed = 0;  // pixels whose foliage the bands change
    const std::vector<float>& a = blended.image.aovs.at("foliage");
    const std::vector<float>& b = apart.image.aovs.at("foliage");
    for (std::size_t i = 0; i < a.size(); ++i) mixed += std::abs(a[i] - b[i]) > 0.01f;
    const double within = coverage(blended), without = coverage(apart);
    std::printf(
        "the tests' fir over its needles: coverage %.3f with the level bands, %.3f "
        "without (%d pixels changed)\n",
        within / needles, without / needles, mixed);
    EXPECT_GT(mixed, 300);
    EXPECT_NEAR(within / needles, 1.0, 0.05);
    EXPECT_NEAR(within / without, 1.0, 0.06);
}

// Issue 9: no bough shadow or bough face black where the needles are lit. The paper's clamped
// linear law casts solid shadows and, with self-shadowing, darkens level 3 towards black
// (errata E11); the faithful models must not. Counted on 2 x 2 pixel blocks, a bough's width
// here, against 64 spp needles (compareImages' blackFoliage): a pixel of needles may be black
// where the truth's shadow rays passed between needles that a shadow cone reads as their mean.
// Measured 2026-12-07 at 160 x 120: faithful 0 of 254 blocks, --paper 10 of 257, the needles
// on another sample pattern 0 of 277.
TEST(FaithfulModels, NoBoughIsBlackWhereTheNeedlesAreLit)
{
    scenes::Scene scene = scenes::parseScene(
        test::firScene(R"("diffuse", "shadows", "self_shadowing")", 160, 120), "fir.json");
    const TracedScene traced = buildTracedScene(scene);
    GeometryOptions g;
    g.samples = 64;
    const RenderResult truth = renderGeometry(traced, g);
    const auto blackBlocks = [&](const RenderResult& r) {
        const ImageErrors e = compareImages(r.image, truth.image);
        const ImageErrors::BlackFoliage* twoByTwo = nullptr;
        for (const ImageErrors::BlackFoliage& b : e.blackFoliage) {
            if (b.k == 2) twoByTwo = &b;
        }
        EXPECT_NE(twoByTwo, nullptr);
        EXPECT_GT(twoByTwo ? twoByTwo->blocks : 0, 200u);
        return twoByTwo ? double(twoByTwo->black) / double(twoByTwo->blocks) : 1.0;
    };
    g.sampleSeed = 1;
    const double needles = blackBlocks(renderGeometry(traced, g));
    const double faithful = blackBlocks(renderMultiscale(traced));
    scene.render.model = scenes::ModelChoices::paper();
    const double paper = blackBlocks(renderMultiscale(buildTracedScene(scene)));
    std::printf(
        "2 x 2 blocks of foliage black where 64 spp needles are lit: needles %.3f, "
        "faithful %.3f, the paper's models %.3f\n",
        needles, faithful, paper);
    EXPECT_LE(needles, 0.01);
    EXPECT_LE(faithful, 0.01);
    EXPECT_GE(paper, 0.03);  // the check sees what it is for
}

}  // namespace
}  // namespace pine::vdbtrace
