// Level 2 (section 5) against quadrature over the needle azimuth of the level-1 expressions,
// which are the defining integrals of eqs. (4)-(6).
#include "pine/analytic/cone_shader.h"
#include "pine/analytic/needle_shader.h"
#include "pine/analytic/quadrature.h"
#include "pine/analytic/reference_integrals.h"
#include "test_support.h"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

namespace pine::analytic {
namespace {

struct RandomCone {
    double phi, n;
    Vec3 axis, L, V;
};

RandomCone randomCone(test::RandomDirections& rnd)
{
    return {rnd.uniform(2.0, 88.0) * kPi / 180.0, rnd.logUniform(10.0, 1e4), rnd.direction(),
            rnd.direction(), rnd.direction()};
}

// 2000 random cones with both our integrals and the reference's, computed once for the three
// tests below.
struct ConeComparison {
    RandomCone cone;
    ConeIntegrals ours, ref;
};

const std::vector<ConeComparison>& comparisons()
{
    static const std::vector<ConeComparison> table = [] {
        test::RandomDirections rnd(21);
        std::vector<ConeComparison> t(2000);
        for (ConeComparison& x : t) {
            const RandomCone c = randomCone(rnd);
            x = {c, coneIntegrals(c.phi, c.axis, c.L, c.V, c.n),
                 reference::coneIntegrals(c.phi, c.axis, c.L, c.V, c.n)};
        }
        return t;
    }();
    return table;
}

TEST(ConeShader, OpacityIntegralMatchesQuadrature)
{
    // J = int s_v over each face: 8-point Gauss on each quarter, kinks on its ends. The
    // integrand is analytic inside, so the error is spectrally small; 1e-4 relative bounds the
    // worst case, a view just off the aperture angle (s_v ~ sqrt(d^2 + t^2) near t = 0).
    for (const ConeComparison& c : comparisons()) {
        EXPECT_NEAR(c.ours.front.J, c.ref.front.J, 1e-4 * c.ref.front.J);
        EXPECT_NEAR(c.ours.rear.J, c.ref.rear.J, 1e-4 * c.ref.rear.J);
    }
}

TEST(ConeShader, DiffuseIntegralMatchesQuadrature)
{
    // G: the degree-2 trigonometric part (pi/2) int Q is exact; the rest s_l s_v h(da), h in
    // [1, pi/2], by 8-point Gauss per half face. Where a needle lies along L the rest has a
    // kink (s_l ~ |t - t_L|) inside a panel: O(h^2) there. Measured worst over the sweep's
    // 2000 cases: 0.0097; bound 0.02 absolute, against G up to pi^2.
    for (const ConeComparison& c : comparisons()) {
        EXPECT_NEAR(c.ours.front.G, c.ref.front.G, 0.02);
        EXPECT_NEAR(c.ours.rear.G, c.ref.rear.G, 0.02);
    }
}

TEST(ConeShader, SpecularIntegralMatchesQuadrature)
{
    // S: Gauss on windows around the lobe's peaks. Measured worst 0.0045 of one peak's
    // natural scale sqrt(2 pi / (n - 1)) (kinks of (H_p.V_p)+ and the faces' edges inside a
    // window); bound 0.01 of it.
    for (const ConeComparison& c : comparisons()) {
        const double tol = 0.01 * std::sqrt(2.0 * kPi / (c.cone.n - 1.0));
        EXPECT_NEAR(c.ours.front.S, c.ref.front.S, tol) << "n=" << c.cone.n;
        EXPECT_NEAR(c.ours.rear.S, c.ref.rear.S, tol) << "n=" << c.cone.n;
    }
}

TEST(ConeShader, SpecularCoversEachEpsilonCase)
{
    // Eq. (5)'s eps: 0 (no needle orthogonal to H), 1 (one such azimuth on the face) or 2 (both
    // on the same face). Draw cases until each count has been seen on the front face at least
    // 20 times, and check each against quadrature (tolerance as in SpecularIntegralMatchesQuadrature).
    test::RandomDirections rnd(28);
    int seen[3] = {0, 0, 0};
    for (int i = 0; i < 20000 && (seen[0] < 20 || seen[1] < 20 || seen[2] < 20); ++i) {
        const RandomCone c = randomCone(rnd);
        const double printed = coneSpecularPrinted(c.phi, c.axis, c.L, c.V, c.n, true);
        const double peak = std::sqrt(2.0 * kPi / c.n) * std::max(0.0, glm::dot(c.V, glm::normalize(c.L + c.V)));
        const int eps = peak > 0.0 ? int(std::lround(printed / peak)) : 0;
        if (seen[eps] >= 20) continue;
        ++seen[eps];
        const double ours = coneIntegrals(c.phi, c.axis, c.L, c.V, c.n).front.S;
        const double ref = reference::coneIntegrals(c.phi, c.axis, c.L, c.V, c.n).front.S;
        EXPECT_NEAR(ours, ref, 0.01 * std::sqrt(2.0 * kPi / (c.n - 1.0))) << "eps=" << eps;
    }
    EXPECT_EQ(seen[0], 20);
    EXPECT_EQ(seen[1], 20);
    EXPECT_EQ(seen[2], 20);
}

TEST(ConeShader, PrintedEq5MissesTheLaplaceJacobian)
{
    // Erratum: Laplace's method over theta gives each peak the width sqrt(2 pi / n) / |dc_h/dt|;
    // eq. (5) drops 1 / |dc_h/dt| = 1 / sqrt(w^2 - u^2), u = cos(phi) c_h, w = sin(phi) s_h.
    const double phi = 0.5, n = 5000.0;
    const Vec3 axis(0, 0, 1), L = glm::normalize(Vec3(1, 0.4, 0.3)), V = glm::normalize(Vec3(-0.2, 1, 0.1));
    const Vec3 H = glm::normalize(L + V);
    const AxisProjection h = projectOnAxis(axis, H);
    const double u = std::cos(phi) * h.c, w = std::sin(phi) * h.s;
    ASSERT_LT(std::abs(u), 0.5 * w);  // two well separated peaks
    const ConeIntegrals ref = reference::coneIntegrals(phi, axis, L, V, n);
    const double printed = coneSpecularPrinted(phi, axis, L, V, n, true) +
                           coneSpecularPrinted(phi, axis, L, V, n, false);
    const double jacobian = 1.0 / std::sqrt(w * w - u * u);
    EXPECT_GT(jacobian, 1.5);  // a visible error, not a rounding
    EXPECT_NEAR((ref.front.S + ref.rear.S) / printed, jacobian, 0.02 * jacobian);
}

TEST(ConeShader, LambdaFitIsExactWhenLightAndViewRunAlongTheBranch)
{
    // With L and V along the branch both angles are constant (B_L = B_V = 0): the fit has
    // nothing to approximate. Elsewhere its error is measured by `analytic sweep`.
    const double phi = 0.4;
    const Vec3 axis(0, 0, 1);
    for (const bool front : {true, false}) {
        EXPECT_NEAR(coneDiffuseLambdaFit(phi, axis, axis, axis, front),
                    reference::coneLambdaFitIntegral(phi, axis, axis, axis, front), 1e-9);
    }
}

TEST(ConeShader, LambdaFitAngleModelDoesNotFoldAtPi)
{
    // Erratum: the angle model AV ~ A_V + B_V cos, A_V = max(phi_V, phi), B_V = min(phi_V, phi),
    // holds while phi_V + phi <= pi. For V against the branch the angle is pi - phi for every
    // needle, yet the model swings from pi - phi to pi + phi: the fit is wrong where the
    // integrand is constant.
    const double phi = 0.4;
    const Vec3 axis(0, 0, 1), V(0, 0, -1);
    const double fit = coneDiffuseLambdaFit(phi, axis, axis, V, true);
    const double ref = reference::coneLambdaFitIntegral(phi, axis, axis, V, true);
    EXPECT_GT(std::abs(fit - ref), 0.1);
}

TEST(ConeShader, FFitMatchesEq1AtItsAnchors)
{
    // The F fit shares value and slope with g at 0, pi/2 and pi (section 5).
    for (const double da : {0.0, kPi / 2, kPi}) {
        EXPECT_NEAR(diffuseFFit(da), diffuseG(da), 1e-12);
        const double h = 1e-6;
        const double slope = (diffuseFFit(da + h) - diffuseFFit(da - h)) / (2 * h);
        const double slopeG = (diffuseG(da + h) - diffuseG(da - h)) / (2 * h);
        if (da > 0.0 && da < kPi) {
            EXPECT_NEAR(slope, slopeG, 1e-6);
        }
    }
}

TEST(ConeShader, IntegralsAreInvariantUnderRotation)
{
    test::RandomDirections rnd(24);
    for (int i = 0; i < 500; ++i) {
        const RandomCone c = randomCone(rnd);
        const Vec3 spin = rnd.direction();
        const double angle = rnd.uniform(0.0, 2.0 * kPi);
        const auto r = [&](const Vec3& v) { return test::rotate(v, spin, angle); };
        const ConeIntegrals a = coneIntegrals(c.phi, c.axis, c.L, c.V, c.n);
        const ConeIntegrals b = coneIntegrals(c.phi, r(c.axis), r(c.L), r(c.V), c.n);
        for (const auto& [x, y] : {std::pair{a.front, b.front}, std::pair{a.rear, b.rear}}) {
            EXPECT_NEAR(x.J, y.J, 1e-9);
            EXPECT_NEAR(x.G, y.G, 1e-9);
            EXPECT_NEAR(x.S, y.S, 1e-9);
        }
    }
}

TEST(ConeShader, LayerOpacityIsTheNeedlesMeanCoverageOfTheCone)
{
    // A = 2 N r / (pi R): at distance s from the apex N needles of width 2r cover
    // N 2r / (2 pi s sin(phi)) of the circle; averaged over the cone's area (weight s).
    const ConeGeometry cone{0.45, 4.0, 0.04, 14};
    const double sinPhi = std::sin(cone.aperture_rad), l = cone.needleLength_cm;
    const double covered = integrateAdaptive(
        [&](double s) {
            const double circle = 2 * kPi * s * sinPhi;
            return cone.needlesPerCone * 2 * cone.needleRadius_cm / circle * circle;
        },
        0.0, l);
    const double area = integrateAdaptive([&](double s) { return 2 * kPi * s * sinPhi; }, 0.0, l);
    EXPECT_NEAR(layerOpacity(cone), covered / area, 1e-12);
}

TEST(ConeShader, SumsMatchExplicitNeedles)
{
    // The normalisation of the sums (section 5's l A / 4 drops R / 2): N explicit needles at
    // azimuths 2 pi i / N + offset, each contributing 2 r l s_v and that times eq. (1)/(2),
    // averaged over the offset, must give the continuous sums. A smooth lobe (n = 20) keeps
    // the discrete sum converged at N = 360.
    const ConeGeometry cone{0.5, 4.0, 0.05, 360};
    const double n = 20.0;
    test::RandomDirections rnd(27);
    for (int k = 0; k < 20; ++k) {
        const Vec3 axis = rnd.direction(), L = rnd.direction(), V = rnd.direction();
        const ConeFrame f = coneFrame(cone.aperture_rad, axis, L, V);
        ConeFaceSums front, rear;
        const int offsets = 16;
        for (int o = 0; o < offsets; ++o) {
            for (int i = 0; i < int(cone.needlesPerCone); ++i) {
                const double t = 2 * kPi * (i + (o + 0.5) / offsets) / cone.needlesPerCone;
                const Vec3 a = f.needle(t);
                const double area = needleProjectedArea(a, V, cone.needleRadius_cm, cone.needleLength_cm) / offsets;
                ConeFaceSums& face = std::cos(t) >= 0.0 ? front : rear;
                face.area += area;
                face.diffuse += area * needleDiffuse(a, L, V);
                face.specular += area * needleSpecular(a, L, V, n);
            }
        }
        const ConeSums sums = coneSums(cone, coneIntegrals(cone.aperture_rad, axis, L, V, n), n);
        EXPECT_NEAR(sums.front.area, front.area, 1e-3 * front.area);
        EXPECT_NEAR(sums.rear.area, rear.area, 1e-3 * rear.area);
        EXPECT_NEAR(sums.front.diffuse, front.diffuse, 2e-3 * (front.diffuse + rear.diffuse) + 1e-9);
        EXPECT_NEAR(sums.rear.diffuse, rear.diffuse, 2e-3 * (front.diffuse + rear.diffuse) + 1e-9);
        EXPECT_NEAR(sums.front.specular, front.specular, 1e-2 * (front.specular + rear.specular) + 1e-9);
        EXPECT_NEAR(sums.rear.specular, rear.specular, 1e-2 * (front.specular + rear.specular) + 1e-9);
    }
}

TEST(ConeShader, ShadingIsBoundedByItsCoverage)
{
    test::RandomDirections rnd(25);
    for (int i = 0; i < 5000; ++i) {
        const RandomCone c = randomCone(rnd);
        const ConeGeometry cone{c.phi, rnd.uniform(0.5, 8.0), rnd.uniform(0.01, 0.2),
                                rnd.uniform(1.0, 40.0)};
        const ConeSums sums = coneSums(cone, coneIntegrals(c.phi, c.axis, c.L, c.V, c.n), c.n);
        const ConeShading s = shadeCone(sums, rnd.logUniform(0.01, 100.0));
        for (const double alpha : {s.alphaFront, s.alphaRear}) {
            EXPECT_GE(alpha, 0.0);
            EXPECT_LE(alpha, 1.0);
        }
        // Mean reflectances are bounded by a needle's: diffuse pi/4, specular sqrt(2 pi / n)/2.
        EXPECT_LE(s.diffuseFront, s.alphaFront * kPi / 4 + 1e-12);
        EXPECT_LE(s.diffuseRear, s.alphaRear * kPi / 4 + 1e-12);
        const double maxSpecular = 0.5 * std::sqrt(2 * kPi / c.n) * 1.01;  // S's quadrature error
        EXPECT_LE(s.specularFront, s.alphaFront * maxSpecular + 1e-12);
        EXPECT_LE(s.specularRear, s.alphaRear * maxSpecular + 1e-12);
    }
}

}  // namespace
}  // namespace pine::analytic
