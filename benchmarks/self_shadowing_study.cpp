// A study, not a test: the layer model's self-shadowing (section 6, errata E13) against shadow
// rays through the explicit needles, point by point. One long paper bough side-on, as
// FaithfulModels.ALoneBoughUnderEveryLight renders it, but without rendering: points on the
// needles' sides (the ground truth's needles have open ends: render.needle_ends), each weighted by
// the Lambertian light it sends to the camera (n . L times n . V, zero unless both are positive)
// when a ray towards the camera leaves it through the other needles; each then gets the needles'
// answer (a ray towards the light through every other needle, hit or not) and the model's
// (LayerModel::transmittance from the needle's axis point, as level 1 shades it). Their weighted
// means reproduce that test's needles and level 1 within about 1% in seconds, and split the model's
// error by the distance from the branch.
//
//   self_shadowing_study [--light X Y Z] [--correlation needles|independent] [--points N]
//
// docs/models.md ("Layer correlation") quotes it.
#include "pine/analytic/bough_shader.h"
#include "pine/analytic/direction.h"
#include "pine/scenes/scene.h"
#include "pine/support/tool_main.h"
#include "pine/vdbtrace/effects_plan.h"
#include "pine/vdbtrace/geometry.h"
#include "pine/vdbtrace/layer_model.h"
#include "pine/vdbtrace/needle_layout.h"
#include "pine/vdbtrace/traced_scene.h"

#include "study_options.h"

#include <glm/geometric.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <string>
#include <vector>

namespace {

using pine::vdbtrace::Vec3;
constexpr double kPi = pine::analytic::kPi;

}  // namespace

int main(int argc, char** argv)
{
    using namespace pine::vdbtrace;
    CLI::App app{
        "The layer model's self-shadowing against shadow rays through the explicit "
        "needles, point by point, on one long paper bough side-on (docs/models.md)"};
    std::vector<double> light{0.3, -1.0, 0.6};  // the camera's side, above: the test's first light
    pine::study::addLightOption(app, light);
    std::string correlation = "needles";
    app.add_option("--correlation", correlation, "The layer model's layer_correlation")
        ->capture_default_str()
        ->check(CLI::IsMember(layerCorrelationNames()));
    std::string layerModelName = "fibre";
    app.add_option("--layer-model", layerModelName, "The layer model (render.layer_model)")
        ->capture_default_str()
        ->check(CLI::IsMember(layerModelNames()));
    long points = 400000;
    app.add_option("--points", points, "Random points on the needles")
        ->capture_default_str()
        ->check(pine::tool::wholeNumberIn(1000, 100000000));
    return pine::tool::run("self_shadowing_study", app, argc, argv, [&] {
        const Vec3 L = pine::study::lightDirection(light), V(0.0, -1.0, 0.0);
        const LayerModel& layers = layerModel(layerModelName, layerCorrelated(correlation));
        // The test's bough: N 12, r 0.05, l 4.25, phi pi/8, dh 0.9, 200 cm along x, seen from -y.
        const pine::scenes::Scene scene = pine::scenes::parseScene(R"({"name": "study",
  "camera": {"position": [0, -400, 0], "look_at": [0, 0, 0], "up": [0, 0, 1], "fov_deg": 9,
             "resolution": [32, 24]},
  "lights": [{"type": "directional", "direction": [0, 0, 1]}],
  "ground": {"type": "none"}, "species": {}, "trees": [], "effects": ["diffuse"]})",
                                                                   "study.json");
        const TracedScene traced = buildTracedScene(scene);
        BoughDescription d;
        d.spec.base_cm = Vec3(-100.0, 0.0, 0.0);
        d.spec.tip_cm = Vec3(100.0, 0.0, 0.0);
        d.spec.needles = pine::analytic::paperBough();
        d.seed = 7;
        const TracedBough b = makeTracedBough(d, scene.camera.position_cm, traced.lights,
                                              boughLaw("exact"), layers, {});
        const NeedleLayout needles(b);
        const double r = needles.radius(), l = needles.length();
        const int N = needles.needlesPerCone();
        const double reach = l * std::sin(b.geometry.cone.aperture_rad);  // R, cm
        // Whether a ray from x along D meets a needle other than (j, i): within the bough's
        // radius R it runs at most 2R / sin(angle to the branch) along it, and a needle reaches
        // l along it from its apex, so the cones within that of j hold all it can meet.
        const auto window = [&](const Vec3& D) {
            const double along = glm::length(glm::cross(D, b.axis));
            return long(std::ceil((2.0 * reach / std::max(along, 0.05) + l) /
                                  b.geometry.coneSpacing_cm)) +
                   1;
        };
        const long lightWindow = window(L), viewWindow = window(V);
        // As the ground truth draws them (render.needle_ends "open"): a shadow ray stops where
        // it enters a needle's side; a point inside another needle is hidden from the camera,
        // whose ray entered that needle first.
        const auto blocked = [&](const Vec3& x, const Vec3& D, long w, long j, int i,
                                 bool towardsLight) {
            for (long jj = std::max(0L, j - w); jj <= std::min(needles.lastCone(), j + w); ++jj) {
                const Vec3 apex = needles.apex(jj);
                for (int ii = 0; ii < N; ++ii) {
                    if (jj == j && ii == i) continue;
                    const Vec3 tip = apex + l * needles.direction(needles.azimuth(jj, ii));
                    const ConeRay ray{x, D, 0.0};
                    double tIn, tOut;
                    if (towardsLight
                            ? entersCylinderSide(ray, apex, tip, r, tIn)
                            : intersectCylinder(ray, apex, tip, r, tIn, tOut) && tOut > 0.0) {
                        return true;
                    }
                }
            }
            return false;
        };
        constexpr int kBins = 6;  // of the distance from the branch, 0 to R
        double weight[kBins] = {}, rays[kBins] = {}, model[kBins] = {};
        std::mt19937_64 random(1);
        std::uniform_real_distribution<double> u(0.0, 1.0);
        for (long k = 0; k < points; ++k) {
            // The middle of the bough: cones 60 to 159, away from its ends.
            const long j = 60 + long(u(random) * 100.0);
            const int i = std::min(N - 1, int(u(random) * N));
            const Vec3 dir = needles.direction(needles.azimuth(j, i));
            const Vec3 onAxis = needles.apex(j) + (l * u(random)) * dir;
            const Vec3 e1 = pine::analytic::anyPerpendicular(dir), e2 = glm::cross(dir, e1);
            const double theta = 2.0 * kPi * u(random);
            const Vec3 normal = std::cos(theta) * e1 + std::sin(theta) * e2;
            const double lit = glm::dot(normal, L), seen = glm::dot(normal, V);
            if (lit <= 0.0 || seen <= 0.0) continue;
            const Vec3 x = onAxis + (r * 1.0001) * normal;
            if (blocked(x, V, viewWindow, j, i, false)) continue;
            const double w = lit * seen;
            const Vec3 off = onAxis - b.base_cm;
            const double rho = glm::length(off - glm::dot(off, b.axis) * b.axis);
            const int bin = std::clamp(int(rho / reach * kBins), 0, kBins - 1);
            weight[bin] += w;
            rays[bin] += blocked(x, L, lightWindow, j, i, true) ? 0.0 : w;
            model[bin] += w * layers.transmittance(b, onAxis, L, j, V);
        }
        std::printf(
            "towards the light (%.3f, %.3f, %.3f), %.1f deg from the view; layer model %s, "
            "correlation %s; %ld points\n",
            L.x, L.y, L.z, std::acos(std::clamp(glm::dot(L, V), -1.0, 1.0)) * 180.0 / kPi,
            layerModelName.c_str(), correlation.c_str(), points);
        std::printf("%-16s %8s %10s %10s %8s\n", "rho (cm)", "weight", "needles", "model", "ratio");
        double W = 0.0, R = 0.0, M = 0.0;
        for (int k = 0; k < kBins; ++k) {
            if (!(weight[k] > 0.0)) continue;
            std::printf("%5.2f to %5.2f   %8.3f %10.4f %10.4f %8.3f\n", k * reach / kBins,
                        (k + 1) * reach / kBins, weight[k] / double(points), rays[k] / weight[k],
                        model[k] / weight[k], model[k] / rays[k]);
            W += weight[k];
            R += rays[k];
            M += model[k];
        }
        std::printf("%-16s %8.3f %10.4f %10.4f %8.3f\n", "all", W / double(points), R / W, M / W,
                    M / R);
        return 0;
    });
}
