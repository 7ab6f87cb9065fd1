// Level 1 (section 4) against quadrature of its defining integrals over the cylinder's normals.
#include "pine/analytic/needle_shader.h"
#include "pine/analytic/reference_integrals.h"
#include "test_support.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

namespace pine::analytic {
namespace {

TEST(NeedleShader, DiffuseMatchesQuadrature)
{
    // Eq. (1) is exact: only the reference's own tolerance (1e-11 relative) remains.
    test::RandomDirections rnd(11);
    for (int i = 0; i < 2000; ++i) {
        const Vec3 axis = rnd.direction(), L = rnd.direction(), V = rnd.direction();
        EXPECT_NEAR(needleDiffuse(axis, L, V), reference::needleDiffuse(axis, L, V), 1e-9);
    }
}

TEST(NeedleShader, DiffuseIsReciprocalInProjectedArea)
{
    // The numerator int (N.L)+ (N.V)+ is symmetric in L and V; the denominator is 2 s_v.
    test::RandomDirections rnd(12);
    for (int i = 0; i < 10000; ++i) {
        const Vec3 axis = rnd.direction(), L = rnd.direction(), V = rnd.direction();
        const double sl = projectOnAxis(axis, L).s, sv = projectOnAxis(axis, V).s;
        EXPECT_NEAR(sv * needleDiffuse(axis, L, V), sl * needleDiffuse(axis, V, L), 1e-12);
    }
}

TEST(NeedleShader, DiffuseKnownValues)
{
    const Vec3 axis(0, 0, 1);
    EXPECT_NEAR(needleDiffuse(axis, {1, 0, 0}, {1, 0, 0}), kPi / 4, 1e-15);  // lit where seen
    EXPECT_NEAR(needleDiffuse(axis, {-1, 0, 0}, {1, 0, 0}), 0.0, 1e-15);     // lit from behind
    EXPECT_NEAR(needleDiffuse(axis, {0, 0, 1}, {1, 0, 0}), 0.0, 1e-15);      // light on the axis
}

TEST(NeedleShader, SpecularMatchesQuadratureToOrderOneOverN)
{
    // Eq. (2) freezes cos(alpha - alpha_V) at the lobe's peak and widens cos^n to a Gaussian
    // over the whole line. Inside the visible half both cost O(1/n) relative (second-order
    // Taylor terms, the Gaussian's 1/(4n) excess); at the edge of the visible half the lobe
    // is cut, an error of order s_h^n / n against the scale s_h^n sqrt(2 pi / n) / 2, i.e.
    // O(1/sqrt(n)) of the scale. Bounds: relative 1/n inside (cos > 3/sqrt(n)), and
    // (1/n + 0.5/sqrt(n)) of the scale everywhere.
    test::RandomDirections rnd(13);
    for (const double n : {10.0, 30.0, 100.0, 1000.0, 10000.0}) {
        for (int i = 0; i < 300; ++i) {
            const Vec3 axis = rnd.direction(), L = rnd.direction(), V = rnd.direction();
            const auto H = safeNormalize(L + V);
            ASSERT_TRUE(H);
            const AxisProjection h = projectOnAxis(axis, *H), v = projectOnAxis(axis, V);
            const double scale = 0.5 * std::pow(h.s, n) * std::sqrt(2.0 * kPi / n);
            const double ours = needleSpecular(axis, L, V, n);
            const double ref = reference::needleSpecular(axis, L, V, n);
            EXPECT_LE(std::abs(ours - ref), scale * (1.0 / n + 0.5 / std::sqrt(n)) + 1e-300)
                << "n=" << n;
            const double cosHV = glm::dot(h.perp, v.perp) / (h.s * v.s);
            if (cosHV > 3.0 / std::sqrt(n)) {
                EXPECT_LE(std::abs(ours - ref), ref / n) << "n=" << n << " cos=" << cosHV;
            }
        }
    }
}

TEST(NeedleShader, SpecularStaysBoundedAsTheExponentVanishes)
{
    // sqrt(2 pi / n) diverges as n -> 0 (an exponent of 5e-324 gave NaN) where the lobe's
    // integral over the half-circle tends to pi: capped there, so R_s <= pi / 2 for every
    // n > 0, continuous at n = 2 / pi and the printed form above it.
    test::RandomDirections rnd(29);
    for (int i = 0; i < 500; ++i) {
        const Vec3 axis = rnd.direction(), L = rnd.direction(), V = rnd.direction();
        for (const double n : {5e-324, 1e-300, 1e-10, 0.01, 0.5}) {
            const double r = needleSpecular(axis, L, V, n);
            ASSERT_TRUE(std::isfinite(r)) << "n=" << n;
            EXPECT_GE(r, 0.0);
            EXPECT_LE(r, 0.5 * kPi);
        }
        const double at = 2.0 / kPi;
        EXPECT_NEAR(needleSpecular(axis, L, V, at), needleSpecular(axis, L, V, at * (1 - 1e-9)),
                    1e-8);
        const auto H = safeNormalize(L + V);
        if (!H) continue;
        const AxisProjection h = projectOnAxis(axis, *H), v = projectOnAxis(axis, V);
        if (!(h.s * v.s > 0.0)) continue;
        const double cosHV = std::clamp(glm::dot(h.perp, v.perp) / (h.s * v.s), 0.0, 1.0);
        for (const double n : {0.7, 5.0, 100.0}) {
            EXPECT_EQ(needleSpecular(axis, L, V, n),
                      0.5 * std::pow(h.s, n) * cosHV * std::sqrt(2.0 * kPi / n));
        }
    }
}

TEST(NeedleShader, SpecularErrorShrinksAsOneOverN)
{
    const Vec3 axis(0, 0, 1), L = glm::normalize(Vec3(1, 0.2, 0.3)), V = glm::normalize(Vec3(1, -0.3, 0.1));
    const auto error = [&](double n) {
        const double ref = reference::needleSpecular(axis, L, V, n);
        return std::abs(needleSpecular(axis, L, V, n) - ref) / ref;
    };
    const double ratio = error(100.0) / error(1000.0);
    EXPECT_GT(ratio, 5.0);  // order 1: ratio 10
    EXPECT_LT(ratio, 20.0);
}

TEST(NeedleShader, SpecularPrintedFormWouldGoNegative)
{
    // Erratum: eq. (2) as printed has cos(alpha_H - alpha_V), negative when H_p leans away from
    // V_p by more than 90 degrees (L_p . V_p < -s_v^2); the defining integral cannot be.
    const Vec3 axis(0, 0, 1);
    const Vec3 V = glm::normalize(Vec3(0.3, 0, 1)), L = glm::normalize(Vec3(-1, 0.3, 0));
    const AxisProjection h = projectOnAxis(axis, glm::normalize(L + V)), v = projectOnAxis(axis, V);
    EXPECT_LT(glm::dot(h.perp, v.perp), 0.0);  // the printed form is negative here
    EXPECT_GE(reference::needleSpecular(axis, L, V, 100.0), 0.0);
    EXPECT_GE(needleSpecular(axis, L, V, 100.0), 0.0);
}

TEST(NeedleShader, ProjectedAreaMatchesQuadrature)
{
    // Eq. (3)'s numerator, printed "2 R_s": the projected area int (N.V)+ dS = 2 r l s_v.
    test::RandomDirections rnd(14);
    for (int i = 0; i < 500; ++i) {
        const Vec3 axis = rnd.direction(), V = rnd.direction();
        const double r = rnd.uniform(0.01, 0.2), l = rnd.uniform(0.5, 10.0);
        EXPECT_NEAR(needleProjectedArea(axis, V, r, l), reference::needleProjectedArea(axis, V, r, l),
                    1e-10 * r * l);
    }
}

TEST(NeedleShader, OpacityIsCoverageOfTheFootprint)
{
    EXPECT_DOUBLE_EQ(needleOpacity(0.5, 2.0), 0.25);
    EXPECT_DOUBLE_EQ(needleOpacity(3.0, 2.0), 1.0);  // needle larger than the footprint
    EXPECT_DOUBLE_EQ(needleOpacity(0.0, 0.0), 0.0);
    EXPECT_DOUBLE_EQ(needleOpacity(1.0, 0.0), 1.0);
}

}  // namespace
}  // namespace pine::analytic
