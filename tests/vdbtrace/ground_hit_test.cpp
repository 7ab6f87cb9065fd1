// hitGround against an independent search: the first sign change of the ray's height above
// the ground, found by sampling finely, then bisected. Rays from all around a hill, some far
// outside its reach (where hitGround meets the base plane in closed form), some through a spike
// a centimetre wide.
#include "pine/vdbtrace/ground_hit.h"

#include <gtest/gtest.h>
#include <glm/geometric.hpp>

#include <cmath>
#include <random>

namespace pine::vdbtrace {
namespace {

// The first t in (0, tMax] where the ray is at or under the ground, sampled every `step` cm
// and bisected; false if none.
bool bruteForce(const scenes::Ground& g, const ConeRay& ray, double step, double tMax, double& t)
{
    const auto above = [&](double s) {
        const Vec3 p = ray.origin + s * ray.direction;
        return p.z - g.heightAt(p.x, p.y);
    };
    double a = 0.0;
    for (double b = step; b <= tMax; b += step) {
        if (above(b) <= 0.0) {
            for (int i = 0; i < 60; ++i) {
                const double m = 0.5 * (a + b);
                (above(m) > 0.0 ? a : b) = m;
            }
            t = b;
            return true;
        }
        a = b;
    }
    return false;
}

scenes::Ground hill(double peak, double radius)
{
    scenes::Ground g;
    g.kind = scenes::Ground::Kind::Hill;
    g.height_cm = -10.0;
    g.hillPeak_cm = peak;
    g.hillRadius_cm = radius;
    g.hillCentre_cm = scenes::Vec2(50.0, -20.0);
    return g;
}

TEST(GroundHit, AHillIsMetWhereItsHeightIsFirstReached)
{
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    int hits = 0, plane = 0;
    for (const auto& [peak, radius] : {std::pair{200.0, 300.0}, std::pair{300.0, 20.0}}) {
        const scenes::Ground g = hill(peak, radius);
        for (int i = 0; i < 400; ++i) {
            // Eyes up to 40 radii from the centre, from a fifth of the peak above the ground
            // under them to twice the peak above it.
            const double x = 50.0 + 40.0 * radius * u(rng), y = -20.0 + 40.0 * radius * u(rng);
            const Vec3 eye(x, y, g.heightAt(x, y) + peak * (1.1 + 0.9 * u(rng)));
            const Vec3 towards(50.0 + 3.0 * radius * u(rng), -20.0 + 3.0 * radius * u(rng),
                               g.height_cm + peak * 0.5 * (1.0 + u(rng)));
            const ConeRay ray{eye, glm::normalize(towards - eye), 0.0};
            double t = 0.0, expected = 0.0;
            Vec3 normal;
            const bool found = hitGround(g, ray, t, normal);
            const double span = 200.0 * radius;
            const bool truth = bruteForce(g, ray, 0.01 * std::min(radius, peak), span, expected);
            if (!truth && found && t > span) continue;  // past where the search looked
            ASSERT_EQ(found, truth) << "ray " << i << " from " << eye.x << " " << eye.y;
            if (!found) continue;
            ++hits;
            const Vec3 p = ray.origin + t * ray.direction;
            plane += std::hypot(p.x - 50.0, p.y + 20.0) > 8.0 * radius;
            EXPECT_NEAR(t, expected, 1e-6 * (1.0 + expected)) << "ray " << i;
            EXPECT_NEAR(glm::length(normal), 1.0, 1e-12);
        }
    }
    EXPECT_GT(hits, 300);  // both kinds of hit were tried
    EXPECT_GT(plane, 50);
}

TEST(GroundHit, ASpikeACentimetreWideIsMetOnlyWhereItStands)
{
    // Ten kilometres high, a centimetre wide: a ray past it meets the plane beyond it, one
    // aimed at it meets its side, one climbing beside it meets nothing. (Marched a centimetre a
    // step wherever they went, 768 rays like the last took 41 s; the closed-form plane beyond
    // the hill's reach is what these check, not the time.)
    const scenes::Ground g = hill(1e6, 1.0);
    double t = 0.0;
    Vec3 normal;
    const ConeRay past{Vec3(-500.0, -500.0, 200.0), glm::normalize(Vec3(1.0, 0.2, -0.3)), 0.0};
    ASSERT_TRUE(hitGround(g, past, t, normal));
    EXPECT_NEAR((past.origin + t * past.direction).z, g.height_cm, 1e-9);
    EXPECT_EQ(normal, Vec3(0.0, 0.0, 1.0));
    const Vec3 side(50.0, -20.0, 1000.0), eye(-950.0, -20.0, 1000.0);
    const ConeRay at{eye, glm::normalize(side - eye), 0.0};
    ASSERT_TRUE(hitGround(g, at, t, normal));
    double expected = 0.0;
    ASSERT_TRUE(bruteForce(g, at, 1e-3, 1100.0, expected));
    EXPECT_NEAR(t, expected, 1e-6);
    EXPECT_LT(t, 1000.0);  // on the spike's near side
    const ConeRay climbing{Vec3(45.0, -20.0, 10.0), glm::normalize(Vec3(-0.2, 0.1, 1.0)), 0.0};
    EXPECT_FALSE(hitGround(g, climbing, t, normal));
}

}  // namespace
}  // namespace pine::vdbtrace
