// The tracer's geometry: cylinder tests, strip coverage, the BVH against brute force, and the
// camera's footprint.
#include "pine/vdbtrace/bvh.h"
#include "pine/vdbtrace/cone_camera.h"
#include "pine/vdbtrace/geometry.h"
#include "pine/vdbtrace/multiscale_tracer.h"

#include <glm/geometric.hpp>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <set>

namespace pine::vdbtrace {
namespace {

// The brute force the BVH is checked against: a ray-box slab test with the box grown by
// `margin` on every side, dividing by the direction (the BVH multiplies by its reciprocal).
bool intersectBox(const ConeRay& ray, const Aabb& box, double margin, double tMax, double& tIn,
                  double& tOut)
{
    double t0 = 0.0, t1 = tMax;
    for (int i = 0; i < 3; ++i) {
        const double lo = box.lo[i] - margin, hi = box.hi[i] + margin;
        const double d = ray.direction[i], o = ray.origin[i];
        if (std::abs(d) < 1e-300) {
            if (o < lo || o > hi) return false;
            continue;
        }
        double a = (lo - o) / d, b = (hi - o) / d;
        if (a > b) std::swap(a, b);
        t0 = std::max(t0, a);
        t1 = std::min(t1, b);
        if (t0 > t1) return false;
    }
    tIn = t0;
    tOut = t1;
    return true;
}

TEST(Geometry, CylinderIntervalMatchesTheChord)
{
    // A ray across the z axis at offset d from it crosses a cylinder of radius r over
    // 2 sqrt(r^2 - d^2).
    const Vec3 a(0, 0, -5), b(0, 0, 5);
    for (const double d : {0.0, 0.3, 0.9}) {
        ConeRay ray{Vec3(-10, d, 0), Vec3(1, 0, 0), 0.0};
        double tIn, tOut;
        ASSERT_TRUE(intersectCylinder(ray, a, b, 1.0, tIn, tOut));
        EXPECT_NEAR(tOut - tIn, 2 * std::sqrt(1 - d * d), 1e-12);
        EXPECT_NEAR(0.5 * (tIn + tOut), 10.0, 1e-12);
        Passage p;
        ASSERT_TRUE(closestPassage(ray, a, b, p));
        EXPECT_NEAR(p.t, 10.0, 1e-12);
        EXPECT_NEAR(p.gap, d, 1e-12);
        EXPECT_NEAR(p.s, 0.5, 1e-12);
    }
    ConeRay miss{Vec3(-10, 1.5, 0), Vec3(1, 0, 0), 0.0};
    double tIn, tOut;
    EXPECT_FALSE(intersectCylinder(miss, a, b, 1.0, tIn, tOut));
    ConeRay aboveCap{Vec3(-10, 0, 6), Vec3(1, 0, 0), 0.0};
    EXPECT_FALSE(intersectCylinder(aboveCap, a, b, 1.0, tIn, tOut));
}

TEST(Geometry, AnOpenCylinderIsEnteredThroughItsSideOnly)
{
    // The solid's entry where it is through the side; a ray through an end (down the axis, or
    // obliquely through an end and out through the side) meets no open cylinder, nor one that
    // starts inside it.
    const Vec3 a(0, 0, -5), b(0, 0, 5);
    double t = 0.0, tIn, tOut;
    for (const Vec3& d : {Vec3(1, 0, 0), glm::normalize(Vec3(1, 0.2, 0.5))}) {
        const ConeRay side{Vec3(0.3, 0.1, 1.0) - 10.0 * d, d, 0.0};
        ASSERT_TRUE(entersCylinderSide(side, a, b, 1.0, t));
        ASSERT_TRUE(intersectCylinder(side, a, b, 1.0, tIn, tOut));
        EXPECT_NEAR(t, tIn, 1e-12);
    }
    const ConeRay down{Vec3(0.2, 0, 20), Vec3(0, 0, -1), 0.0};
    EXPECT_TRUE(intersectCylinder(down, a, b, 1.0, tIn, tOut));
    EXPECT_FALSE(entersCylinderSide(down, a, b, 1.0, t));
    const Vec3 slant = glm::normalize(Vec3(0.3, 0, -1));  // in at the top, out through the side
    const ConeRay endThenSide{Vec3(0, 0, 5) - 2.0 * slant, slant, 0.0};
    EXPECT_TRUE(intersectCylinder(endThenSide, a, b, 1.0, tIn, tOut));
    EXPECT_FALSE(entersCylinderSide(endThenSide, a, b, 1.0, t));
    const ConeRay inside{Vec3(0, 0, 0), Vec3(1, 0, 0), 0.0};
    EXPECT_TRUE(intersectCylinder(inside, a, b, 1.0, tIn, tOut));
    EXPECT_FALSE(entersCylinderSide(inside, a, b, 1.0, t));
}

TEST(Geometry, StripCoverageIsTheOverlapFraction)
{
    EXPECT_DOUBLE_EQ(stripCoverage(0.0, 0.1, 1.0), 0.2);    // thin strip inside the footprint
    EXPECT_DOUBLE_EQ(stripCoverage(0.0, 2.0, 1.0), 1.0);    // strip wider than the footprint
    EXPECT_DOUBLE_EQ(stripCoverage(0.5, 0.1, 1.0), 0.1);    // half out on one side
    EXPECT_DOUBLE_EQ(stripCoverage(0.7, 0.1, 1.0), 0.0);    // out
    // Sliding a strip across the footprint conserves its area: int coverage d(gap) = 2 h.
    double sum = 0.0;
    const int n = 20000;
    for (int i = 0; i < n; ++i) sum += stripCoverage(-1.0 + 2.0 * (i + 0.5) / n, 0.15, 0.5) * 2.0 / n;
    EXPECT_NEAR(sum, 0.3, 1e-6);
}

TEST(Bvh, FindsEveryBoxTheConeTouches)
{
    std::mt19937 rng(3);
    std::uniform_real_distribution<double> u(-50.0, 50.0), r(0.1, 3.0);
    std::vector<Aabb> boxes(2000);
    for (Aabb& b : boxes) {
        const Vec3 c(u(rng), u(rng), u(rng));
        const double h = r(rng);
        b.lo = c - Vec3(h);
        b.hi = c + Vec3(h);
    }
    const Bvh bvh(boxes);
    for (int k = 0; k < 200; ++k) {
        ConeRay ray{Vec3(u(rng), u(rng), -80.0), glm::normalize(Vec3(0.3 * u(rng) / 50, 0.3 * u(rng) / 50, 1.0)),
                    0.01};
        std::set<std::uint32_t> found;
        bvh.query(ray, 1e9, [&](std::uint32_t i) { found.insert(i); });
        for (std::uint32_t i = 0; i < boxes.size(); ++i) {
            // Brute force with the tightest margin the cone needs: its width at the box's far side.
            double tIn, tOut;
            const double far = glm::length(boxes[i].centre() - ray.origin) +
                               0.5 * glm::length(boxes[i].hi - boxes[i].lo);
            if (intersectBox(ray, boxes[i], 0.5 * ray.width(far), 1e9, tIn, tOut)) {
                EXPECT_TRUE(found.count(i)) << "box " << i << " missed";
            }
        }
    }
}

// The multiscale tracer's front-to-back walk: the same primitives as query, each bounded by
// its own ball or a tighter bound (primitiveEntry's, later along the ray), in the order
// sorting them all by (bound, index) gives, the caller's own entry (the ground) in its turn,
// those bounded by +infinity (the tracer's misses) never, and nothing after the visit that
// stops it. Cylinders of random lengths and radii whose balls stick far out of their boxes,
// some sharing a bound exactly.
TEST(Bvh, VisitsNearestFirstAsSortingWould)
{
    std::mt19937 rng(5);
    std::uniform_real_distribution<double> u(-50.0, 50.0), len(0.0, 30.0), r(0.01, 2.0);
    std::vector<Aabb> boxes;
    std::vector<Sphere> balls;
    for (int i = 0; i < 20000; ++i) {
        const Vec3 a(u(rng), u(rng), u(rng));
        const Vec3 dir = glm::normalize(Vec3(u(rng), u(rng), u(rng)));
        const Vec3 b = i % 7 == 0 ? a : a + len(rng) * dir;
        const double radius = r(rng);
        boxes.push_back(cylinderBounds(a, b, radius));
        balls.push_back(cylinderSphere(a, b, radius));
        if (i % 11 == 0) {  // a twin: the same ball, so the same bound
            boxes.push_back(boxes.back());
            balls.push_back(balls.back());
        }
    }
    const Bvh bvh(boxes, balls);
    NearestFirstQueue queue;
    std::size_t candidates = 0;  // over all rays
    for (int k = 0; k < 100; ++k) {
        const ConeRay ray{Vec3(u(rng), u(rng), -80.0),
                          glm::normalize(Vec3(0.5 * u(rng) / 50, 0.5 * u(rng) / 50, 1.0)),
                          k % 2 ? 0.0 : 0.02};
        const double tMax = k % 3 ? 1e9 : 90.0;
        const std::uint32_t ground = std::uint32_t(-1);
        const double tGround = 60.0 + k;
        using Entry = std::pair<double, std::uint32_t>;
        // Every fifth primitive missed, every third bounded later than its ball.
        const auto bound = [&](std::uint32_t i) {
            if (i % 5 == 0) return std::numeric_limits<double>::infinity();
            return nearestAlong(ray, balls[i]) + (i % 3 == 0 ? 0.1 * balls[i].radius : 0.0);
        };
        std::vector<Entry> sorted{{tGround, ground}};
        bvh.query(ray, tMax, [&](std::uint32_t i) {
            if (i % 5 != 0) sorted.push_back({bound(i), i});
        });
        std::sort(sorted.begin(), sorted.end());
        // Else never stopped: nothing may come after the last.
        const std::size_t stopAfter =
            k % 4 == 0 ? sorted.size() / 3 : std::numeric_limits<std::size_t>::max();
        std::vector<Entry> visited;
        queue.clear();
        queue.add(tGround, ground);
        bvh.nearestFirst(
            ray, tMax, queue, bound,
            [&](std::uint32_t i, double nearest) {
                visited.push_back({nearest, i});
                return visited.size() < stopAfter;
            });
        candidates += sorted.size();
        sorted.resize(std::min(stopAfter, sorted.size()));
        EXPECT_EQ(visited, sorted) << "ray " << k;
    }
    EXPECT_GT(candidates, 3000u);  // enough to order
}

TEST(ConeCamera, FootprintIsOnePixelAtTheCentre)
{
    scenes::Camera c;
    c.position_cm = Vec3(0, 0, 0);
    c.lookAt_cm = Vec3(0, 1, 0);
    c.up = Vec3(0, 0, 1);
    c.fovY_rad = 0.8;
    c.width = 400;
    c.height = 300;
    const ConeCamera camera(c);
    const ConeRay centre = camera.cone(200, 150);
    // At distance 1 along the view axis the image plane is 2 tan(fov/2) tall over 300 pixels.
    EXPECT_NEAR(centre.width(1.0), 2 * std::tan(0.4) / 300, 1e-5);
    // Neighbouring cones are one footprint apart where they land.
    const ConeRay next = camera.cone(201, 150);
    EXPECT_NEAR(glm::length(next.direction - centre.direction), centre.width(1.0), 1e-5);
    // Row 0 is at the top.
    EXPECT_GT(camera.cone(200, 0).direction.z, 0.0);
}

TEST(MultiscaleTracer, LevelFollowsTheFootprintAgainstTheConeSpacing)
{
    scenes::RenderSettings s;
    s.needleLevelMax = 0.25;
    s.model.coneLevelMax = 1.0;
    EXPECT_EQ(chooseLevel(0.1, 0.9, s), Level::Needle);
    EXPECT_EQ(chooseLevel(0.5, 0.9, s), Level::Cone);
    EXPECT_EQ(chooseLevel(0.9, 0.9, s), Level::Bough);
    EXPECT_EQ(chooseLevel(50.0, 0.9, s), Level::Bough);
    // Halving the spacing (denser boughs) moves the same footprint up a level, never down.
    for (double w = 0.01; w < 5.0; w *= 1.3) {
        EXPECT_GE(int(chooseLevel(w, 0.45, s)), int(chooseLevel(w, 0.9, s)));
    }
}

}  // namespace
}  // namespace pine::vdbtrace
