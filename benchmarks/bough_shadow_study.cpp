// A study, not a test: one bough's shadow on another, the occluder one long bough or a chain
// of short ones end to end, as the trees' branches are (each segment a bough whose cones reach
// l cos(phi) past its tip, into the next). The scene of
// FaithfulModels.ABoughsShadowIsWhereItsNeedlesCastIt: two paper boughs 200 cm long, 6 cm
// apart one above the other, side-on from 400 cm; the upper one may be cut into a chain.
// Prints the light the upper one lets through to the lower one (its luminance with the
// upper one over without it) for the explicit needles (16 spp, the mean over the rolls) and
// for levels 1-3 forced, and the upper one's luminance at each level over the needles'.
// Roll r of the needles moves the lower bough (r - 1) / rolls of a cone spacing along its
// axis: with their cones lined up (one base, one dh), the upper bough's dense cone regions
// lie over the lower one's, and lit straight from above one long bough let through 0.147
// (4 rolls, all lined up) where over 8 rolls and phases it lets through 0.206 (0.195 over the
// default 4). A tree's boughs fall at every phase; the levels do not depend on it.
//
//   bough_shadow_study [--light X Y Z] [--segment CM] [--rolls N] [--shadow-origin needles|bough]
//
// --segment 0 (the default) is one long bough; the paper fir's boughs are about 6 cm.
// docs/models.md ("Whole scenes") quotes it.
#include "pine/analytic/bough_shader.h"
#include "pine/scenes/scene.h"
#include "pine/support/tool_main.h"
#include "pine/vdbtrace/effects_plan.h"
#include "pine/vdbtrace/geometry_tracer.h"
#include "pine/vdbtrace/layer_model.h"
#include "pine/vdbtrace/multiscale_tracer.h"
#include "pine/vdbtrace/traced_scene.h"

#include "study_options.h"

#include <cstdio>
#include <string>
#include <utility>
#include <vector>

namespace {

using namespace pine::vdbtrace;

struct Options {
    Vec3 towardsLight{0.2, -0.3, 1.0};
    double segment_cm = 0.0;
    int rolls = 4;
    ShadowOrigin origin = ShadowOrigin::Needles;
};

TracedScene boughs(const Options& o, pine::scenes::Scene& scene, unsigned seed, bool upper,
                   double shift_cm = 0.0)
{
    char light[128];
    std::snprintf(light, sizeof light, "[%.17g, %.17g, %.17g]", o.towardsLight.x, o.towardsLight.y,
                  o.towardsLight.z);
    scene = pine::scenes::parseScene(std::string(R"({"name": "bough shadow study",
  "camera": {"position": [0, -400, 0], "look_at": [0, 0, 0], "up": [0, 0, 1], "fov_deg": 6,
             "resolution": [320, 240]},
  "lights": [{"type": "directional", "direction": )") +
                                         light + R"(}],
  "ground": {"type": "none"}, "species": {}, "trees": [],
  "effects": ["diffuse", "shadows", "self_shadowing"]})",
                                     "bough-shadow-study.json");
    TracedScene traced = buildTracedScene(scene);
    traced.shadowOrigin = o.origin;
    const BoughLawNeeds needs = BoughLawNeeds::from(EffectsPlan::from(scene.effects));
    const auto add = [&](const Vec3& base, const Vec3& tip, unsigned rollSeed) {
        BoughDescription d;
        d.spec.base_cm = base;
        d.spec.tip_cm = tip;
        d.spec.needles = pine::analytic::paperBough();
        d.seed = rollSeed;
        traced.boughs.push_back(makeTracedBough(d, scene.camera.position_cm, traced.lights,
                                                boughLaw(scene.render.model.boughLaw),
                                                *traced.layers, needs));
    };
    if (upper && o.segment_cm > 0.0) {
        for (int k = 0; - 100.0 + o.segment_cm * (k + 1) <= 100.0 + 1e-9; ++k) {
            add(Vec3(-100.0 + o.segment_cm * k, 0.0, 3.0),
                Vec3(-100.0 + o.segment_cm * (k + 1), 0.0, 3.0), seed * 1000u + unsigned(k));
        }
    } else if (upper) {
        add(Vec3(-100.0, 0.0, 3.0), Vec3(100.0, 0.0, 3.0), seed);
    }
    add(Vec3(-100.0 + shift_cm, 0.0, -3.0), Vec3(100.0 + shift_cm, 0.0, -3.0), seed + 10);
    indexPrimitives(traced);
    return traced;
}

// The luminance of the frame's lower half (the lower bough) and of its upper half.
std::pair<double, double> halves(const RenderResult& r)
{
    double lower = 0.0, upper = 0.0;
    for (int y = 0; y < r.image.height; ++y) {
        for (int x = 0; x < r.image.width; ++x) {
            const std::size_t i =
                4 * (std::size_t(y) * std::size_t(r.image.width) + std::size_t(x));
            const double l = 0.2126 * r.image.rgba[i] + 0.7152 * r.image.rgba[i + 1] +
                             0.0722 * r.image.rgba[i + 2];
            (2 * y < r.image.height ? upper : lower) += l;
        }
    }
    return {lower, upper};
}

}  // namespace

int main(int argc, char** argv)
{
    CLI::App app{
        "One bough's shadow on another, the occluder one long bough or a chain of short "
        "ones: the explicit needles against levels 1-3 (docs/models.md)"};
    std::vector<double> light{0.2, -0.3, 1.0};
    pine::study::addLightOption(app, light);
    Options o;
    app.add_option("--segment", o.segment_cm,
                   "Cut the upper bough into a chain of boughs this long, cm (0: one bough)")
        ->capture_default_str();
    app.add_option("--rolls", o.rolls,
                   "Needle rolls the explicit needles are averaged over, each at its own phase "
                   "of the two boughs' cones")
        ->capture_default_str()
        ->check(pine::tool::wholeNumberIn(1, 64));
    std::string origin = "needles";
    app.add_option("--shadow-origin", origin, "The multiscale levels' render.shadow_origin")
        ->capture_default_str()
        ->check(CLI::IsMember({"needles", "bough"}));
    return pine::tool::run("bough_shadow_study", app, argc, argv, [&] {
        pine::study::lightDirection(light);  // checked; the scene file normalises it
        o.towardsLight = Vec3(light[0], light[1], light[2]);
        o.origin = origin == "bough" ? ShadowOrigin::Bough : ShadowOrigin::Needles;
        if (!(o.segment_cm == 0.0 || (o.segment_cm >= 1.0 && o.segment_cm <= 200.0))) {
            throw pine::InputError("--segment must be 0 (one bough) or 1 to 200 cm");
        }
        pine::scenes::Scene scene;
        double through = 0.0, upper = 0.0;
        const double dh = pine::analytic::paperBough().coneSpacing_cm;
        for (int roll = 1; roll <= o.rolls; ++roll) {
            GeometryOptions g;
            g.samples = 16;
            const double shift = (roll - 1) * dh / o.rolls;
            const auto [lo, up] =
                halves(renderGeometry(boughs(o, scene, unsigned(roll), true, shift), g));
            const double alone =
                halves(renderGeometry(boughs(o, scene, unsigned(roll), false, shift), g)).first;
            through += lo / alone / o.rolls;
            upper += up / o.rolls;
        }
        std::printf(
            "towards the light (%g, %g, %g), the occluder %s, shadows from the %s: the "
            "needles let through %.4f (%d rolls and phases)\n",
            o.towardsLight.x, o.towardsLight.y, o.towardsLight.z,
            o.segment_cm > 0.0 ? "a chain" : "one bough",
            o.origin == ShadowOrigin::Bough ? "bough" : "needles", through, o.rolls);
        if (o.segment_cm > 0.0) std::printf("  chain of %g cm boughs\n", o.segment_cm);
        for (int level = 1; level <= 3; ++level) {
            MultiscaleOptions m;
            m.forceLevel = level;
            const auto [lo, up] = halves(renderMultiscale(boughs(o, scene, 1, true), m));
            const double alone = halves(renderMultiscale(boughs(o, scene, 1, false), m)).first;
            std::printf(
                "  level %d lets through %.4f; the occluder's own luminance %.3f of the "
                "needles'\n",
                level, lo / alone, up / upper);
        }
        return 0;
    });
}
