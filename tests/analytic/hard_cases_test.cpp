// DESIGN.md's hard cases: every output finite and physically bounded, over 10^5 random
// direction triples per shader and a named degenerate set, with extreme parameters.
#include "pine/analytic/bough_shader.h"
#include "pine/analytic/cone_shader.h"
#include "pine/analytic/needle_shader.h"
#include "test_support.h"

#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

namespace pine::analytic {
namespace {

struct Triple {
    std::string name;
    Vec3 axis, L, V;
};

Vec3 tilted(const Vec3& axis, double angle)  // a unit vector at `angle` from the z axis
{
    const Vec3 side = anyPerpendicular(axis);
    return std::cos(angle) * axis + std::sin(angle) * side;
}

std::vector<Triple> degenerateTriples(double phi)
{
    const Vec3 z(0, 0, 1), x(1, 0, 0), y(0, 1, 0);
    const Vec3 some = glm::normalize(Vec3(0.3, -0.5, 0.8));
    const Vec3 other = glm::normalize(Vec3(-0.7, 0.2, 0.1));
    return {
        {"L equals V", z, some, some},
        {"L opposite V", z, some, -some},
        {"L along the axis", z, z, other},
        {"L against the axis", z, -z, other},
        {"V along the axis", z, other, z},
        {"V against the axis", z, other, -z},
        {"L and V along the axis", z, z, z},
        {"V inside the aperture", z, other, tilted(z, 0.5 * phi)},
        {"V at the aperture angle", z, other, tilted(z, phi)},
        {"V at pi minus the aperture", z, other, tilted(z, kPi - phi)},
        {"L at the aperture angle", z, tilted(z, phi), other},
        {"V a hair off the axis", z, other, glm::normalize(Vec3(1e-12, 0, 1))},
        {"sin(l_v) = 0, same side", z, glm::normalize(Vec3(1, 0, 0.4)), glm::normalize(Vec3(1, 0, -0.3))},
        {"sin(l_v) = 0, opposite sides", z, glm::normalize(Vec3(-1, 0, 0.4)), glm::normalize(Vec3(1, 0, 0.2))},
        {"grazing: V orthogonal to the axis", z, other, x},
        {"H along the axis", z, glm::normalize(Vec3(1, 0, 1)), glm::normalize(Vec3(-1, 0, 1))},
        {"H orthogonal to all needles' band edge", z, y, tilted(z, kPi / 2 - phi)},
    };
}

// A bough geometry for the hard cases: the paper's, and ones that break the law.
std::vector<std::pair<std::string, BoughGeometry>> hardBoughs()
{
    BoughGeometry paper;
    paper.cone = {kPi / 8, 4.25, 0.05, 12};
    paper.coneSpacing_cm = 0.9;
    auto dense = paper;
    dense.coneSpacing_cm = 1e-4;  // n A ~ 2e4
    auto zeroLength = paper;
    zeroLength.cone.needleLength_cm = 0.0;
    auto zeroAperture = paper;
    zeroAperture.cone.aperture_rad = 0.0;
    auto noNeedles = paper;
    noNeedles.cone.needlesPerCone = 0.0;
    auto opaqueLayers = paper;
    opaqueLayers.cone.needlesPerCone = 1e6;  // A clamps to 1
    auto huge = paper;
    huge.cone.needleLength_cm = 1e5;
    auto flat = paper;
    flat.cone.aperture_rad = kPi / 2;
    return {{"paper", paper},         {"dense", dense},       {"zero length", zeroLength},
            {"zero aperture", zeroAperture}, {"no needles", noNeedles},
            {"opaque layers", opaqueLayers}, {"huge", huge},  {"flat cones", flat}};
}

void expectUnit(double x, const std::string& what)
{
    EXPECT_TRUE(std::isfinite(x)) << what;
    EXPECT_GE(x, 0.0) << what;
    EXPECT_LE(x, 1.0 + 1e-12) << what;
}

void checkNeedle(const Vec3& axis, const Vec3& L, const Vec3& V, double n, const std::string& what)
{
    const double d = needleDiffuse(axis, L, V), s = needleSpecular(axis, L, V, n);
    EXPECT_TRUE(std::isfinite(d) && std::isfinite(s)) << what;
    EXPECT_GE(d, 0.0) << what;
    EXPECT_LE(d, kPi / 4 + 1e-12) << what;
    EXPECT_GE(s, 0.0) << what;
    EXPECT_LE(s, 0.5 * std::sqrt(2 * kPi / n) + 1e-12) << what;
    // The cylinder has no preferred end.
    EXPECT_NEAR(d, needleDiffuse(-axis, L, V), 1e-12) << what;
    EXPECT_NEAR(s, needleSpecular(-axis, L, V, n), 1e-12) << what;
}

void checkCone(const ConeGeometry& cone, const Vec3& axis, const Vec3& L, const Vec3& V, double n,
               double footprint, const std::string& what)
{
    const ConeIntegrals in = coneIntegrals(cone.aperture_rad, axis, L, V, n);
    for (const double x : {in.front.J, in.rear.J, in.front.G, in.rear.G, in.front.S, in.rear.S}) {
        EXPECT_TRUE(std::isfinite(x)) << what;
        EXPECT_GE(x, 0.0) << what;
    }
    const ConeShading s = shadeCone(coneSums(cone, in, n), footprint);
    expectUnit(s.alphaFront, what + " alphaFront");
    expectUnit(s.alphaRear, what + " alphaRear");
    EXPECT_LE(s.diffuseFront, s.alphaFront * kPi / 4 + 1e-12) << what;
    EXPECT_LE(s.diffuseRear, s.alphaRear * kPi / 4 + 1e-12) << what;
    const double maxSpecular = 0.5 * std::sqrt(2 * kPi / n) * 1.01;
    for (const double x : {s.diffuseFront, s.diffuseRear, s.specularFront, s.specularRear}) {
        EXPECT_TRUE(std::isfinite(x)) << what;
        EXPECT_GE(x, 0.0) << what;
    }
    EXPECT_LE(s.specularFront, s.alphaFront * maxSpecular + 1e-12) << what;
    EXPECT_LE(s.specularRear, s.alphaRear * maxSpecular + 1e-12) << what;
}

void checkBough(const BoughGeometry& b, const Vec3& axis, const Vec3& L, const Vec3& V,
                const std::string& what)
{
    const BoughView view = boughView(b.cone.aperture_rad, axis, L, V);
    EXPECT_FALSE(std::isnan(view.kV) || std::isnan(view.kVbar) || std::isnan(view.kL) ||
                 std::isnan(view.kLbar) || std::isnan(view.cosLV))
        << what;
    const BoughLinearLaw law = boughLinearLaw(b, view);
    expectUnit(law.alphaView.front, what + " linear alpha front");
    expectUnit(law.alphaView.rear, what + " linear alpha rear");
    expectUnit(law.alphaView.front + law.alphaView.rear, what + " linear alpha");
    expectUnit(law.transfer.front, what + " linear transfer front");
    expectUnit(law.transfer.rear, what + " linear transfer rear");
    EXPECT_LE(law.transfer.front, law.alphaView.front + 1e-12) << what;
    EXPECT_LE(law.transfer.rear, law.alphaView.rear + 1e-12) << what;
    const BoughExact exact = boughExact(b, view);
    expectUnit(exact.alpha.front, what + " exact alpha front");
    expectUnit(exact.alpha.rear, what + " exact alpha rear");
    expectUnit(exact.total(), what + " exact alpha");
    expectUnit(exact.transfer.front, what + " exact transfer front");
    expectUnit(exact.transfer.rear, what + " exact transfer rear");
    EXPECT_LE(exact.transfer.front, exact.alpha.front + 1e-9) << what;  // shadows only remove
    EXPECT_LE(exact.transfer.rear, exact.alpha.rear + 1e-9) << what;
}

TEST(HardCases, DegenerateDirectionsStayFiniteAndBounded)
{
    for (const auto& [boughName, bough] : hardBoughs()) {
        const double phi = bough.cone.aperture_rad;
        for (const Triple& t : degenerateTriples(phi > 0 ? phi : kPi / 8)) {
            for (const double n : {1.5, 100.0, 1e4, 1e6}) {
                const std::string what = t.name + ", " + boughName + ", n=" + std::to_string(n);
                checkNeedle(t.axis, t.L, t.V, n, what);
                checkCone(bough.cone, t.axis, t.L, t.V, n, 1.0, what);
            }
            checkBough(bough, t.axis, t.L, t.V, t.name + ", " + boughName);
        }
    }
}

TEST(HardCases, NeedleOverRandomTriples)
{
    test::RandomDirections rnd(41);
    for (int i = 0; i < 100000; ++i) {
        checkNeedle(rnd.direction(), rnd.direction(), rnd.direction(), rnd.logUniform(1.5, 1e6),
                    "needle #" + std::to_string(i));
        if (HasFailure()) return;
    }
}

TEST(HardCases, ConeOverRandomTriples)
{
    test::RandomDirections rnd(42);
    for (int i = 0; i < 100000; ++i) {
        const ConeGeometry cone{rnd.uniform(0.0, kPi / 2), rnd.uniform(0.0, 10.0),
                                rnd.uniform(0.0, 0.3), rnd.uniform(0.0, 50.0)};
        checkCone(cone, rnd.direction(), rnd.direction(), rnd.direction(), rnd.logUniform(1.5, 1e6),
                  rnd.logUniform(1e-3, 1e3), "cone #" + std::to_string(i));
        if (HasFailure()) return;
    }
}

TEST(HardCases, BoughOverRandomTriples)
{
    test::RandomDirections rnd(43);
    for (int i = 0; i < 100000; ++i) {
        BoughGeometry b;
        b.cone = {rnd.uniform(0.0, kPi / 2), rnd.uniform(0.0, 10.0), rnd.uniform(0.0, 0.3),
                  rnd.uniform(0.0, 50.0)};
        b.coneSpacing_cm = rnd.logUniform(1e-4, 10.0);
        checkBough(b, rnd.direction(), rnd.direction(), rnd.direction(),
                   "bough #" + std::to_string(i));
        if (HasFailure()) return;
    }
}

}  // namespace
}  // namespace pine::analytic
