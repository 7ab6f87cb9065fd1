// render.shadow_origin "bough": the shadow cone's points off its line (ShadowSamples across,
// sideways and towards the light) read every occluder as lines of their own would, and the
// per-bough shadows render the fir close to the per-hit cones with far fewer of them.
#include "pine/scenes/scene.h"
#include "pine/vdbtrace/bough_shadows.h"
#include "pine/vdbtrace/multiscale_tracer.h"
#include "pine/vdbtrace/surface_shading.h"
#include "pine/vdbtrace/traced_scene.h"

#include "test_scenes.h"

#include <gtest/gtest.h>
#include <glm/geometric.hpp>

#include <cmath>
#include <random>
#include <string>

namespace pine::vdbtrace {
namespace {

// A twig along x through the origin with a bough's needles around it, and above them, across
// the light, a branch and a second bough: the occluders a bough's needles see, one of them
// (the twig) among the needles themselves.
struct Occluders {
    scenes::Scene scene;
    TracedScene traced;
    Occluders()
    {
        scene = scenes::parseScene(R"({"name": "occluders",
  "camera": {"position": [0, -400, 0], "look_at": [0, 0, 0], "up": [0, 0, 1], "fov_deg": 6,
             "resolution": [32, 24]},
  "lights": [{"type": "directional", "direction": [0.3, -0.4, 1]}],
  "ground": {"type": "none"}, "species": {}, "trees": [],
  "effects": ["diffuse", "shadows"]})",
                                   "occluders.json");
        traced = buildTracedScene(scene);
        traced.branches = {{Vec3(-50.0, 0.0, 0.0), Vec3(50.0, 0.0, 0.0), 0.4},
                           {Vec3(1.0, -30.0, 6.0), Vec3(2.0, 30.0, 9.0), 0.7}};
        const BoughLawNeeds needs = BoughLawNeeds::from(EffectsPlan::from(scene.effects));
        for (const Vec3& at : {Vec3(0.0), Vec3(-3.0, 1.0, 4.0)}) {
            BoughDescription d;
            d.spec.base_cm = at + Vec3(-40.0, 0.0, 0.0);
            d.spec.tip_cm = at + Vec3(40.0, 3.0 * at.x, 0.0);
            d.spec.needles.cone = {0.4, 4.25, 0.05, 12};
            d.spec.needles.coneSpacing_cm = 0.9;
            traced.boughs.push_back(makeTracedBough(d, scene.camera.position_cm, traced.lights,
                                                    *traced.boughLaw, *traced.layers, needs));
        }
        indexPrimitives(traced);
    }
};

TEST(BoughShadows, PointsOffTheConesLineReadTheOccludersAsTheirOwnLines)
{
    // Random points about the twig, inside the needles' reach; each one's own narrow shadow
    // cone against one cone holding them all, offset across the light, sideways and towards
    // it. Points behind the twig (seen from the light) are in its shadow, points in front of
    // it not: only the offset towards the light tells them apart.
    const Occluders o;
    const TracedScene& s = o.traced;
    const std::size_t self = s.branches.size();  // the lower bough
    Vec3 L, irradiance;
    double distance;
    s.lights[0].at(Vec3(0.0), L, distance, irradiance);
    const Vec3 across = stripAcross(Vec3(1.0, 0.0, 0.0), L);
    const Vec3 sideways = glm::normalize(glm::cross(L, across));
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    constexpr double kFootprint = 0.05;
    int shadowedByTwig = 0;
    for (int trial = 0; trial < 20; ++trial) {
        const Vec3 x(u(rng) * 5.0, 0.0, 0.0);
        ShadowSamples samples;
        samples.across = across;
        samples.sideways = sideways;
        double single = 0.0, weights = 0.0;
        for (int k = 0; k < 12; ++k) {
            const Vec3 offset(0.0, 2.5 * u(rng), 2.5 * u(rng));
            if (glm::length(offset) < 0.6) continue;  // inside the twig
            const double weight = 0.5 + 0.5 * u(rng);
            samples.points.push_back({glm::dot(offset, across), weight,
                                      glm::dot(offset, sideways), glm::dot(offset, L)});
            const double T =
                shadowConeTransmittance(s, x + offset, 0, kFootprint, self, true, nullptr);
            single += weight * T;
            weights += weight;
            shadowedByTwig += std::abs(glm::dot(offset, across)) < 0.3 && glm::dot(offset, L) < 0;
        }
        const double together =
            shadowConeTransmittance(s, x, 0, kFootprint, self, true, &samples);
        EXPECT_NEAR(together, single / weights, 1e-7) << "trial " << trial;
    }
    EXPECT_GT(shadowedByTwig, 5);  // the twig's shadow was tested, not only the others'
}

TEST(BoughShadows, ABoughsShadowsAreReadBetweenSamplesAlongItsAxis)
{
    const Occluders o;
    const TracedScene& s = o.traced;
    RenderStats stats;
    const BoughShadows shadows(s, false);
    const std::size_t lower = s.branches.size();
    const TracedBough& b = s.boughs[0];
    const int count = BoughShadows::samplesAlong(b);
    ASSERT_EQ(count, BoughShadows::kMaxSamples);  // 90 cm long, 3.3 cm wide
    double low = 1.0, high = 0.0;
    for (int k = 0; k < count; ++k) {
        const Vec3 centre = b.base_cm + (k + 0.5) / count * (b.conesEnd() - b.base_cm);
        const double T = shadows.transmittance(lower, 0, centre, stats);
        low = std::min(low, T);
        high = std::max(high, T);
        if (k + 1 < count) {
            const Vec3 next = b.base_cm + (k + 1.5) / count * (b.conesEnd() - b.base_cm);
            const double between = shadows.transmittance(lower, 0, 0.5 * (centre + next), stats);
            const double T1 = shadows.transmittance(lower, 0, next, stats);
            EXPECT_NEAR(between, 0.5 * (T + T1), 1e-12) << k;
        }
    }
    // Traced once: one cone a sample, however many reads.
    EXPECT_EQ(stats.shadowRays, std::uint64_t(count));
    // The upper bough and the branch across shade part of it, not all.
    EXPECT_LT(low, 0.9 * high);
    EXPECT_GT(high, 0.5);
    // Past the ends, the end samples.
    const Vec3 before = b.base_cm - 10.0 * b.axis;
    const Vec3 first = b.base_cm + 0.5 / count * (b.conesEnd() - b.base_cm);
    EXPECT_EQ(shadows.transmittance(lower, 0, before, stats),
              shadows.transmittance(lower, 0, first, stats));
}

TEST(BoughShadows, RenderTheFirCloseToPerHitConesWithFewerCones)
{
    const std::string json = test::firScene(R"("diffuse", "shadows", "self_shadowing")");
    const scenes::Scene scene = scenes::parseScene(json, "test.json");
    TracedScene traced = buildTracedScene(scene);
    const RenderResult perHit = renderMultiscale(traced);
    traced.shadowOrigin = ShadowOrigin::Bough;
    const RenderResult perBough = renderMultiscale(traced);
    double a = 0.0, b = 0.0;
    for (std::size_t i = 0; i < perHit.image.rgba.size(); i += 4) {
        a += perHit.image.rgba[i + 1];
        b += perBough.image.rgba[i + 1];
    }
    std::printf("green sum: per hit %.2f, per bough %.2f; shadow cones %llu against %llu\n", a,
                b, (unsigned long long)perBough.stats.shadowRays,
                (unsigned long long)perHit.stats.shadowRays);
    EXPECT_NEAR(b / a, 1.0, 0.05);
    EXPECT_NE(perHit.image.rgba, perBough.image.rgba);
    EXPECT_LT(perBough.stats.shadowRays, perHit.stats.shadowRays);
}

}  // namespace
}  // namespace pine::vdbtrace
