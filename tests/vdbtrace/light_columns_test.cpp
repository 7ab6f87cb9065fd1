// A directional light's shadow cones find their occluders in columns across the light
// (light_columns.h): every primitive within reach, in the BVH query's order, so that each
// transmittance is the same product as through the BVH, to the bit.
#include "pine/vdbtrace/light_columns.h"
#include "pine/analytic/direction.h"
#include "pine/scenes/scene.h"
#include "pine/vdbtrace/bvh.h"
#include "pine/vdbtrace/multiscale_tracer.h"
#include "pine/vdbtrace/surface_shading.h"
#include "pine/vdbtrace/traced_scene.h"

#include "test_scenes.h"

#include <gtest/gtest.h>
#include <glm/geometric.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <set>

namespace pine::vdbtrace {
namespace {

TEST(Bvh, QueryOrderIsTheOrderAQueryMeetingEveryNodeVisitsIn)
{
    std::mt19937 rng(5);
    std::uniform_real_distribution<double> u(-50.0, 50.0);
    std::vector<Aabb> boxes;
    for (int i = 0; i < 300; ++i) {
        const Vec3 a(u(rng), u(rng), u(rng));
        boxes.push_back(cylinderBounds(a, a + Vec3(u(rng), u(rng), u(rng)) * 0.1, 0.5));
    }
    const Bvh bvh(boxes);
    // A cone so wide that its margin holds every node.
    const ConeRay ray{Vec3(0.0, 0.0, -1000.0), Vec3(0.0, 0.0, 1.0), 10.0};
    std::vector<std::uint32_t> visited;
    bvh.query(ray, 1e9, [&](std::uint32_t i) { visited.push_back(i); });
    EXPECT_EQ(visited, bvh.queryOrder());
    EXPECT_EQ(std::set<std::uint32_t>(visited.begin(), visited.end()).size(), boxes.size());
}

// The distance from the line through x along L to segment a-b, when they are seen along L.
double distanceAcross(const Vec3& x, const Vec3& L, const Vec3& a, const Vec3& b)
{
    const auto flat = [&](const Vec3& p) { return p - glm::dot(p, L) * L; };
    const Vec3 fa = flat(a - x), fb = flat(b - x), d = fb - fa;
    const double length2 = glm::dot(d, d);
    const double f = length2 > 0.0 ? std::clamp(-glm::dot(fa, d) / length2, 0.0, 1.0) : 0.0;
    return glm::length(fa + f * d);
}

TEST(LightColumns, YieldEveryPrimitiveWithinReachOnceInTheBvhsOrder)
{
    // Random sticks (some along the light, some across it), random tubes; the columns must
    // yield each stick within the tube's radius of its line and not beyond the point, and
    // should leave out most of the others.
    std::mt19937 rng(11);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    const Vec3 L = glm::normalize(Vec3(-0.5, -0.6, 0.8));
    std::vector<LightColumns::Primitive> sticks;
    for (int i = 0; i < 2000; ++i) {
        const Vec3 base(60.0 * u(rng), 60.0 * u(rng), 30.0 * u(rng) + 30.0);
        const Vec3 along = i % 10 == 0 ? L : glm::normalize(Vec3(u(rng), u(rng), u(rng)));
        sticks.push_back(
            {base, base + (2.0 + 6.0 * (u(rng) + 1.0)) * along, 0.05 + 1.0 * (u(rng) + 1.0)});
    }
    std::vector<Aabb> boxes;
    for (const auto& s : sticks) boxes.push_back(cylinderBounds(s.base, s.end, s.radius_cm));
    const Bvh bvh(boxes);
    const std::vector<std::uint32_t> order = bvh.queryOrder();
    std::vector<std::size_t> rankOf(sticks.size());
    for (std::size_t r = 0; r < order.size(); ++r) rankOf[order[r]] = r;
    const auto columns = LightColumns::build(
        sticks.size(), [&](std::size_t i) { return sticks[i]; }, order, L, std::size_t(1) << 30);
    ASSERT_TRUE(columns);
    std::size_t yielded = 0, expected = 0;
    for (int q = 0; q < 2000; ++q) {
        const Vec3 x(70.0 * u(rng), 70.0 * u(rng), 40.0 * u(rng) + 30.0);
        const double radius = 0.1 + 4.0 * (u(rng) + 1.0), beyond = 2.0 * (u(rng) + 1.0);
        std::vector<std::uint32_t> got;
        columns->query(x, radius, beyond, [&](std::uint32_t i) {
            got.push_back(i);
            return true;
        });
        for (std::size_t k = 1; k < got.size(); ++k) {
            ASSERT_LT(rankOf[got[k - 1]], rankOf[got[k]]) << "query " << q;
        }
        const std::set<std::uint32_t> found(got.begin(), got.end());
        for (std::size_t i = 0; i < sticks.size(); ++i) {
            const auto& s = sticks[i];
            const double nearest =
                std::min(-glm::dot(s.base, L), -glm::dot(s.end, L)) - s.radius_cm;
            const bool within = distanceAcross(x, L, s.base, s.end) <= s.radius_cm + radius &&
                                nearest <= -glm::dot(x, L) + beyond;
            if (within) {
                ++expected;
                EXPECT_TRUE(found.count(std::uint32_t(i))) << "query " << q << ", stick " << i;
            }
        }
        yielded += got.size();
        // A visit returning false ends the query.
        int calls = 0;
        columns->query(x, radius, beyond, [&](std::uint32_t) { return ++calls < 2; });
        EXPECT_EQ(calls, std::min<int>(2, int(got.size())));
    }
    EXPECT_GT(expected, 1000u);
    EXPECT_LT(double(yielded), 1.5 * double(expected));
    // Too little room: none made.
    EXPECT_FALSE(LightColumns::build(
        sticks.size(), [&](std::size_t i) { return sticks[i]; }, order, L, 1000));
}

TEST(LightColumns, AQueryReadingTheLastOnesCandidatesYieldsWhatTheCellsWould)
{
    // Queries from the same point as the one before, or near it, wider or narrower, deeper or
    // not, on six columns at once (more than a thread keeps neighbourhoods for), on columns
    // made again for another light, and after queries with infinite, huge or negative
    // values: each must yield exactly what its own gather from the cells yields, in order.
    std::mt19937 rng(23);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    std::vector<LightColumns::Primitive> sticks;
    for (int i = 0; i < 3000; ++i) {
        const Vec3 base(30.0 * u(rng), 30.0 * u(rng), 30.0 * u(rng));
        sticks.push_back({base, base + 3.0 * glm::normalize(Vec3(u(rng), u(rng), u(rng))),
                          0.3 + 0.7 * (u(rng) + 1.0)});
    }
    std::vector<std::uint32_t> order(sticks.size());
    for (std::size_t i = 0; i < order.size(); ++i) order[i] = std::uint32_t(order.size() - 1 - i);
    std::vector<Vec3> lights(6);  // of each of the columns below
    const auto make = [&](std::size_t c) {
        const Vec3 towards = lights[c] = glm::normalize(Vec3(0.6 * u(rng), 0.6 * u(rng), 1.0));
        return LightColumns::build(
            sticks.size(), [&](std::size_t i) { return sticks[i]; }, order, towards,
            std::size_t(1) << 30);
    };
    std::vector<std::unique_ptr<LightColumns>> columns;
    for (std::size_t c = 0; c < lights.size(); ++c) {
        columns.push_back(make(c));
        ASSERT_TRUE(columns.back());
    }
    const auto yielded = [](const LightColumns& c, bool cells, const Vec3& x, double radius,
                            double beyond) {
        std::vector<std::uint32_t> got;
        const auto visit = [&](std::uint32_t i) {
            got.push_back(i);
            return true;
        };
        if (cells) {
            c.queryCells(x, radius, beyond, visit);
        } else {
            c.query(x, radius, beyond, visit);
        }
        return got;
    };
    constexpr double kInf = std::numeric_limits<double>::infinity();
    const double nan = std::nan("");
    struct Odd {
        Vec3 x;
        double radius, beyond;
    };
    const std::vector<Odd> odd = {
        {Vec3(0.0, kInf, 0.0), 1.0, 1.0},   {Vec3(0.0, 0.0, -kInf), 1.0, 1.0},
        {Vec3(nan, 0.0, 0.0), 1.0, 1.0},    {Vec3(1.0, 2.0, 3.0), 1e12, 1.0},
        {Vec3(1.0, 2.0, 3.0), kInf, 1.0},   {Vec3(1.0, 2.0, 3.0), -5.0, 1.0},
        {Vec3(1.0, 2.0, 3.0), -1e-12, 1.0}, {Vec3(1.0, 2.0, 3.0), 2.0, nan},
        {Vec3(1.0, 2.0, 3.0), 2.0, -kInf},  {Vec3(1e7, 0.0, 0.0), 2.0, 1.0}};
    std::size_t compared = 0, nonEmpty = 0;
    Vec3 x(1.0, 2.0, 3.0);
    double radius = 1.0, beyond = 1.0;
    for (int q = 0; q < 7000; ++q) {
        const int kind = q % 7;
        if (kind == 0) {  // somewhere else
            x = Vec3(30.0 * u(rng), 30.0 * u(rng), 30.0 * u(rng));
            radius = 0.2 + 1.5 * (u(rng) + 1.0);
            beyond = 1.0 + u(rng);
        } else if (kind == 1) {  // the same point as the first columns below see it, deeper
            x -= 0.75 * (u(rng) + 1.0) * lights[std::size_t(q) % lights.size()];
        } else if (kind == 2) {  // the same point, narrower or wider
            radius *= 1.0 + 0.2 * u(rng);
        } else if (kind == 3) {  // a hair or a millimetre aside
            x += (q % 14 < 7 ? 1e-9 : 0.1) * glm::normalize(Vec3(u(rng), u(rng), 0.0));
        } else if (kind == 4 && q % 70 == 4) {  // made again for another light
            const std::size_t c = std::size_t(q / 70) % columns.size();
            columns[c] = make(c);
        } else if (kind == 5) {  // an odd query, then the same point as before it
            const Odd& o = odd[std::size_t(q / 7) % odd.size()];
            for (const auto& c : columns) {
                const auto got = yielded(*c, false, o.x, o.radius, o.beyond);
                ASSERT_EQ(got, yielded(*c, true, o.x, o.radius, o.beyond))
                    << "odd query " << (q / 7) % odd.size();
                // A reach of more cells than an int counts still reads them all.
                if (o.radius == 1e12) {
                    EXPECT_GT(got.size(), sticks.size() / 4);
                }
            }
        } else if (kind == 6) {  // narrower, from the point before the odd query
            radius *= 0.9;
        }
        for (int c = 0; c < 2; ++c) {
            const LightColumns& cols = *columns[std::size_t(q + c) % columns.size()];
            const auto got = yielded(cols, false, x, radius, beyond);
            ASSERT_EQ(got, yielded(cols, true, x, radius, beyond)) << "query " << q;
            ++compared;
            nonEmpty += !got.empty();
        }
    }
    EXPECT_GT(nonEmpty, compared / 2);
}

TEST(LightColumns, KeepAPrimitiveAtTheEdgeOfReachWhereverItLies)
{
    // Long sticks far from the origin across the light, each exactly `radius` plus its own
    // radius from the line through the origin: the floats their ends are kept in round by
    // more than the origin's own coordinates would allow for.
    std::mt19937 rng(17);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    const Vec3 L = glm::normalize(Vec3(-0.5, -0.6, 0.8));
    const Vec3 e1 = analytic::anyPerpendicular(L), e2 = glm::cross(L, e1);
    int missed = 0;
    for (int n = 0; n < 5000; ++n) {
        const double half = 40.0 + 80.0 * u(rng), r = 0.05 + 2.0 * u(rng);
        const double radius = 0.1 + 5.0 * u(rng);
        // Oblique across the light, so that both of each end's coordinates are large.
        const double theta = 0.2 + 1.2 * u(rng);
        const Vec3 along = std::cos(theta) * e1 + std::sin(theta) * e2;
        const Vec3 normal = -std::sin(theta) * e1 + std::cos(theta) * e2;
        const Vec3 centre = (r + radius) * normal + 30.0 * (u(rng) - 0.5) * L;
        const LightColumns::Primitive stick{centre - half * along, centre + half * along, r};
        const auto columns = LightColumns::build(
            1, [&](std::size_t) { return stick; }, {0u}, L, std::size_t(1) << 20);
        ASSERT_TRUE(columns);
        int found = 0;
        columns->query(Vec3(0.0), radius, 100.0, [&](std::uint32_t) {
            ++found;
            return true;
        });
        missed += found == 0;
    }
    EXPECT_EQ(missed, 0);
}

TEST(LightColumns, ShadowConesReadTheSameThroughColumnsAsThroughTheBvh)
{
    const scenes::Scene scene = scenes::parseScene(
        test::firScene(R"("diffuse", "shadows", "self_shadowing")", 48, 36), "test.json");
    TracedScene traced = buildTracedScene(scene);
    ASSERT_EQ(traced.lights.size(), 2u);
    const std::size_t sun = traced.lights[0].directional ? 0 : 1;
    ASSERT_TRUE(traced.lights[sun].directional);
    EXPECT_NE(traced.columns(sun), nullptr);
    EXPECT_EQ(traced.columns(1 - sun), nullptr);  // a point light's cones fan out

    // Shadow cones from random points among the boughs, each with points spread about it.
    std::mt19937 rng(3);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    std::vector<Vec3> at;
    std::vector<ShadowSamples> samples;
    for (int i = 0; i < 400; ++i) {
        const TracedBough& b =
            traced.boughs[std::size_t((u(rng) + 1.0) * 0.5 * double(traced.boughs.size() - 1))];
        at.push_back(b.base_cm + (u(rng) + 1.0) * (b.tip_cm - b.base_cm) +
                     b.radius_cm * Vec3(u(rng), u(rng), u(rng)));
        ShadowSamples s;
        s.across = glm::normalize(Vec3(u(rng), u(rng), 0.1));
        s.sideways = glm::normalize(glm::cross(traced.lights[sun].towardsLight, s.across));
        for (int k = 0; k < 6; ++k) {
            s.points.push_back({2.0 * u(rng), 1.0 + u(rng), 2.0 * u(rng), 2.0 * u(rng)});
        }
        samples.push_back(s);
    }
    const auto shadows = [&](const TracedScene& s) {
        std::vector<double> T;
        for (std::size_t i = 0; i < at.size(); ++i) {
            const double footprint = 0.2 + 2.0 * (1.0 + std::sin(double(i)));
            T.push_back(
                shadowConeTransmittance(s, at[i], sun, footprint, kNoPrimitive, true, &samples[i]));
            T.push_back(shadowConeTransmittance(s, at[i], sun, footprint, kNoPrimitive, false));
        }
        return T;
    };
    const std::vector<double> through = shadows(traced);
    const RenderResult a = renderMultiscale(traced, {});
    traced.lightColumns.reset();  // every cone walks the BVH
    ASSERT_EQ(traced.columns(sun), nullptr);
    const std::vector<double> walked = shadows(traced);
    EXPECT_EQ(through, walked);
    EXPECT_LT(*std::min_element(walked.begin(), walked.end()), 0.5);  // some are shaded
    const RenderResult b = renderMultiscale(traced, {});
    EXPECT_EQ(a.image.rgba, b.image.rgba);
    // Primitives changed after indexing: no columns of the old ones are read.
    indexPrimitives(traced);
    ASSERT_NE(traced.columns(sun), nullptr);
    traced.boughs.pop_back();
    EXPECT_EQ(traced.columns(sun), nullptr);
    EXPECT_EQ(a.image.aovs, b.image.aovs);
    EXPECT_EQ(a.stats.shadowRays, b.stats.shadowRays);
}

}  // namespace
}  // namespace pine::vdbtrace
