// The layer field against what it stands for: cones counted one by one along a ray, and the
// mean over directions by quadrature on the sphere.
#include "pine/bake/layer_field.h"
#include "pine/bake/extinction_law.h"

#include "test_support.h"

#include <gtest/gtest.h>
#include <glm/geometric.hpp>

#include <cmath>
#include <vector>

namespace pine::bake {
namespace {

const ExtinctionLaw& layerLaw()
{
    return extinctionLaw("layer");
}

constexpr double kPi = 3.14159265358979323846;

Vec3 unit(double x, double y, double z)
{
    return glm::normalize(Vec3(x, y, z));
}

/// Any unit vector orthogonal to unit `a`.
Vec3 perpendicular(const Vec3& a)
{
    const Vec3 other = std::abs(a.x) < 0.9 ? Vec3(1, 0, 0) : Vec3(0, 1, 0);
    return glm::normalize(glm::cross(a, other));
}

TEST(LayerField, MeanOverTheSphereIsHalfTheGradientNorm)
{
    // A spherical Fibonacci lattice, not aligned with G: |d . G| has a kink on the great circle
    // orthogonal to G, which costs the lattice its spectral accuracy; with 2e5 points the
    // error measured is ~1e-6 relative, so 1e-4 leaves room and still catches any factor.
    constexpr int kPoints = 200000;
    const double golden = kPi * (3.0 - std::sqrt(5.0));
    const Vec3 axis = unit(0.3, -0.5, 0.8);
    for (const double phi : {0.2, kPi / 8, 0.7, 1.2, kPi / 2}) {
        BoughSpec b = test::paperBough(Vec3(1.0, 2.0, -3.0), axis, 30.0);
        b.needles.cone.aperture_rad = phi;
        const double R = b.needles.cone.needleLength_cm * std::sin(phi);
        const Vec3 x = b.base_cm + 15.0 * axis + 0.6 * R * perpendicular(axis);
        const auto s = sampleBough(b, x);
        ASSERT_TRUE(s) << "phi " << phi;
        double sum = 0.0;
        for (int i = 0; i < kPoints; ++i) {
            const double z = 1.0 - (2.0 * i + 1.0) / kPoints;
            const double r = std::sqrt(1.0 - z * z);
            const Vec3 d(r * std::cos(golden * i), r * std::sin(golden * i), z);
            sum += layerLaw().extinction(*s, d);
        }
        const double mean = sum / kPoints;
        EXPECT_NEAR(mean / layerLaw().meanExtinction(*s), 1.0, 1e-4) << "phi " << phi;
        // |G| = |axis - cot(phi) radial| / dh = 1 / (dh sin(phi)).
        EXPECT_NEAR(glm::length(s->gradient) * b.needles.coneSpacing_cm * std::sin(phi), 1.0,
                    1e-12);
        const double mu = -std::log(1.0 - s->layerOpacity);
        EXPECT_NEAR(layerLaw().meanExtinction(*s),
                    mu / (2.0 * b.needles.coneSpacing_cm * std::sin(phi)), 1e-12);
    }
}

TEST(LayerField, OnTheAxisTheNeedlesAreAsDenseAsBesideIt)
{
    // On the branch's axis every cone has its apex and no direction across it is singled out,
    // but the needles are there: the field exists, as dense as just beside the axis (|G| =
    // 1 / (dh sin(phi)), coverage 1), its needle phi from the axis. It was once left out, and
    // a bake whose voxel centres lay on a branch's axis lost that whole row of voxels.
    for (const Vec3& axis : {Vec3(1, 0, 0), Vec3(0, 0, -1), unit(0.3, -0.5, 0.8)}) {
        const BoughSpec b = test::paperBough(Vec3(1.0, 2.0, -3.0), axis, 30.0);
        const double phi = b.needles.cone.aperture_rad;
        const Vec3 x = b.base_cm + 12.0 * axis;
        const auto on = sampleBough(b, x);
        const auto beside = sampleBough(b, x + 1e-6 * perpendicular(axis));
        ASSERT_TRUE(on && beside) << axis.x << " " << axis.z;
        EXPECT_NEAR(glm::length(on->gradient) * b.needles.coneSpacing_cm * std::sin(phi), 1.0,
                    1e-12);
        EXPECT_EQ(on->needleCoverage, 1.0);
        EXPECT_NEAR(glm::dot(on->needle, axis), std::cos(phi), 1e-12);
        EXPECT_NEAR(glm::length(on->needle), 1.0, 1e-12);
        for (const char* name : {"layer", "fibre", "poisson"}) {
            const ExtinctionLaw& law = extinctionLaw(name);
            EXPECT_NEAR(law.meanExtinction(*on), law.meanExtinction(*beside),
                        1e-9 * law.meanExtinction(*beside))
                << name;
        }
    }
}

/// Cones crossed between t0 and t1 on x(t) = origin + t d, counted one by one: the changes of
/// floor(g / dh) at steps of `step`, g = h - rho cot(phi) the apex height of the cone through
/// x(t), counted only inside the region. Independent of LayerSample.
int conesCrossed(const BoughSpec& b, const Vec3& origin, const Vec3& d, double t0, double t1,
                 double step)
{
    const Vec3 axis = glm::normalize(b.tip_cm - b.base_cm);
    const double length = glm::length(b.tip_cm - b.base_cm);
    const double R = b.needles.cone.needleLength_cm * std::sin(b.needles.cone.aperture_rad);
    const double cot = 1.0 / std::tan(b.needles.cone.aperture_rad);
    int crossings = 0;
    bool have = false;
    double previous = 0.0;
    for (double t = t0; t <= t1; t += step) {
        const Vec3 v = origin + t * d - b.base_cm;
        const double h = glm::dot(v, axis);
        const double rho = glm::length(v - h * axis);
        const double g = h - rho * cot;
        if (rho > R || g < 0.0 || g > length) {
            have = false;
            continue;
        }
        const double layer = std::floor(g / b.needles.coneSpacing_cm);
        if (have && layer != previous) crossings += int(std::abs(layer - previous));
        previous = layer;
        have = true;
    }
    return crossings;
}

TEST(LayerField, ChordThroughTheAxisCrossesAsManyConesAsItCounts)
{
    // A ray orthogonal to the branch through its axis: the optical depth of the field is
    // mu x (cones crossed), where the crossings are counted directly. A single chord's count is
    // an integer and its ends cut layers, so it may differ by up to one crossing per half; the
    // mean over M offsets spread evenly over one cone spacing has no such end effect beyond
    // 1/M per half.
    const Vec3 axis = unit(0.2, 0.9, -0.4);
    const BoughSpec b = test::paperBough(Vec3(5.0, -1.0, 2.0), axis, 40.0);
    const Vec3 across = perpendicular(axis);
    const double R = b.needles.cone.needleLength_cm * std::sin(b.needles.cone.aperture_rad);
    constexpr int kOffsets = 50;
    constexpr int kSteps = 20000;
    const double dt = 2.0 * (R + 0.5) / kSteps;
    double sumDepth = 0.0, sumCount = 0.0, mu = 0.0;
    for (int m = 0; m < kOffsets; ++m) {
        const double h0 = 20.0 + b.needles.coneSpacing_cm * (m + 0.5) / kOffsets;
        const Vec3 centre = b.base_cm + h0 * axis;
        // Midpoint rule: the integrand is piecewise constant, so only the two cells on the
        // region's edge are in error, by at most dt each.
        double depth = 0.0;
        for (int i = 0; i < kSteps; ++i) {
            const double t = -(R + 0.5) + (i + 0.5) * dt;
            if (const auto s = sampleBough(b, centre + t * across)) {
                depth += layerLaw().extinction(*s, across) * dt;
                mu = s->layerExtinction();
            }
        }
        const int count = conesCrossed(b, centre, across, -(R + 0.5), R + 0.5, 1e-4);
        EXPECT_NEAR(depth / mu, count, 2.0 + 1e-3) << "offset " << m;
        sumDepth += depth;
        sumCount += count;
    }
    ASSERT_GT(mu, 0.0);
    EXPECT_NEAR(sumDepth / mu / kOffsets, sumCount / kOffsets, 2.0 / kOffsets + 1e-3);
    // And both are the exact 2 R cot(phi) / dh (4.36 per half on the paper's bough).
    EXPECT_NEAR(sumCount / kOffsets,
                2.0 * R / std::tan(b.needles.cone.aperture_rad) / b.needles.coneSpacing_cm,
                2.0 / kOffsets);
}

TEST(LayerField, NothingOutsideTheRegion)
{
    const Vec3 axis = unit(0.0, 0.0, 1.0);
    const BoughSpec b = test::paperBough(Vec3(0.0), axis, 10.0);
    const double R = b.needles.cone.needleLength_cm * std::sin(b.needles.cone.aperture_rad);
    const double cot = 1.0 / std::tan(b.needles.cone.aperture_rad);
    const Vec3 e(1.0, 0.0, 0.0);
    // Inside: halfway out, halfway along.
    EXPECT_TRUE(sampleBough(b, 5.0 * axis + 0.5 * R * e));
    // On the axis, where every cone has its apex (OnTheAxisTheNeedlesAreAsDenseAsBesideIt).
    EXPECT_TRUE(sampleBough(b, 5.0 * axis));
    // Beyond the needles' reach.
    EXPECT_FALSE(sampleBough(b, 5.0 * axis + 1.001 * R * e));
    EXPECT_TRUE(sampleBough(b, 5.0 * axis + 0.999 * R * e));
    // Before the first cone (its apex at the base): h < rho cot(phi), though h > 0.
    EXPECT_FALSE(sampleBough(b, 0.9 * 0.5 * R * cot * axis + 0.5 * R * e));
    EXPECT_TRUE(sampleBough(b, 1.1 * 0.5 * R * cot * axis + 0.5 * R * e));
    // Past the last cone (its apex at the tip), though h < length + R cot(phi).
    EXPECT_FALSE(sampleBough(b, (10.0 + 0.5 * R * cot * 1.1) * axis + 0.5 * R * e));
    EXPECT_TRUE(sampleBough(b, (10.0 + 0.5 * R * cot * 0.9) * axis + 0.5 * R * e));
    // Behind the base.
    EXPECT_FALSE(sampleBough(b, -0.1 * axis + 0.5 * R * e));
}

TEST(LayerField, DegenerateBoughsFillNothing)
{
    const Vec3 x(0.5, 0.0, 5.0);
    BoughSpec b = test::paperBough(Vec3(0.0), Vec3(0, 0, 1), 10.0);
    ASSERT_TRUE(sampleBough(b, x));
    BoughSpec zeroLength = b;
    zeroLength.tip_cm = zeroLength.base_cm;
    EXPECT_FALSE(sampleBough(zeroLength, Vec3(0.5, 0.0, 0.5)));
    BoughSpec noNeedles = b;
    noNeedles.needles.cone.needlesPerCone = 0;
    EXPECT_FALSE(sampleBough(noNeedles, x));
    BoughSpec badAperture = b;
    badAperture.needles.cone.aperture_rad = 0.0;
    EXPECT_FALSE(sampleBough(badAperture, x));
    badAperture.needles.cone.aperture_rad = std::nan("");
    EXPECT_FALSE(sampleBough(badAperture, x));
    BoughSpec badSpacing = b;
    badSpacing.needles.coneSpacing_cm = 0.0;
    EXPECT_FALSE(sampleBough(badSpacing, x));
}

TEST(LayerField, NeedleLiesOnItsCone)
{
    // The needle at x lies on the cone g = const through x: orthogonal to G, unit length,
    // at angle phi to the branch, pointing away from it.
    const Vec3 axis = unit(-0.4, 0.1, 0.9);
    const BoughSpec b = test::paperBough(Vec3(3.0), axis, 20.0);
    const Vec3 e = perpendicular(axis);
    const Vec3 x = b.base_cm + 10.0 * axis + 1.0 * glm::normalize(e + 0.3 * glm::cross(axis, e));
    const auto s = sampleBough(b, x);
    ASSERT_TRUE(s);
    EXPECT_NEAR(glm::dot(s->needle, s->gradient), 0.0, 1e-12);
    EXPECT_NEAR(glm::length(s->needle), 1.0, 1e-12);
    EXPECT_NEAR(glm::dot(s->needle, axis), std::cos(b.needles.cone.aperture_rad), 1e-12);
    EXPECT_GT(glm::dot(s->needle, x - (b.base_cm + 10.0 * axis)), 0.0);
    EXPECT_NEAR(s->layerOpacity, 2.0 * 12 * 0.05 / (kPi * 4.25 * std::sin(kPi / 8)), 1e-12);
}

TEST(LayerField, OpaqueLayersStayFinite)
{
    // A = 1 (needles covering the cone) would make mu infinite; the cap keeps it finite.
    BoughSpec b = test::paperBough(Vec3(0.0), Vec3(0, 0, 1), 10.0);
    b.needles.cone.needlesPerCone = 1000;
    const auto s = sampleBough(b, Vec3(0.5, 0.0, 5.0));
    ASSERT_TRUE(s);
    EXPECT_EQ(s->layerOpacity, 1.0);
    EXPECT_EQ(s->layerExtinction(), kMaxLayerExtinction);
    EXPECT_TRUE(std::isfinite(layerLaw().meanExtinction(*s)));
    EXPECT_TRUE(std::isfinite(layerLaw().extinction(*s, glm::normalize(s->needle))));
}

}  // namespace
}  // namespace pine::bake
