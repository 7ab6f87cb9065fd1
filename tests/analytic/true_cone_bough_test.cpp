// The true-cone bough (errata E12): layers counted along chords, and the opacity's relation to
// the paper's asymptote model.
#include "pine/analytic/quadrature.h"
#include "pine/analytic/true_cone_bough.h"
#include "test_support.h"

#include <gtest/gtest.h>

#include <cmath>

namespace pine::analytic {
namespace {

TEST(TrueConeBough, LayersAreTheConesCountedAlongTheChord)
{
    // In the plane P_x (distance x from the branch, the z axis), a ray along -V = -(sin, 0, cos)
    // of phi_V: count the multiples of dh that g = z - rho cot(phi) passes inside rho <= R,
    // averaged over the ray's offset along the branch.
    const BoughGeometry b = paperBough();
    const double R = boughRadius(b.cone), dh = b.coneSpacing_cm, cotPhi = 1 / std::tan(b.cone.aperture_rad);
    test::RandomDirections rnd(51);
    for (int k = 0; k < 40; ++k) {
        const double phiV = rnd.uniform(0.05, kPi - 0.05), u = rnd.uniform(-0.98, 0.98);
        const double x = u * R, half = std::sqrt(R * R - x * x);
        const double s = std::sin(phiV), c = std::cos(phiV);
        double count = 0.0;
        const int offsets = 200, steps = 4000;
        for (int o = 0; o < offsets; ++o) {
            const double z0 = dh * (o + 0.5) / offsets;
            // The chord runs over X in [-half, half]; along the ray z changes by -cot(phi_V) per X.
            const auto g = [&](double X) { return z0 - X * c / s - std::sqrt(X * X + x * x) * cotPhi; };
            double prev = std::floor(g(-half) / dh);
            for (int i = 1; i <= steps; ++i) {
                const double now = std::floor(g(-half + 2 * half * i / steps) / dh);
                count += std::abs(now - prev);
                prev = now;
            }
        }
        EXPECT_NEAR(count / offsets, trueConeLayers(b, c, s, u), 0.01 + 1e-3 * count / offsets)
            << "phiV " << phiV << " u " << u;
    }
}

TEST(TrueConeBough, OrthogonalViewHasAClosedForm)
{
    const BoughGeometry b = paperBough();
    const double R = boughRadius(b.cone), cotPhi = 1 / std::tan(b.cone.aperture_rad);
    for (const double u : {0.0, 0.3, 0.7, 0.99}) {
        EXPECT_NEAR(trueConeLayers(b, 0.0, 1.0, u), 2 * R * (1 - u) * cotPhi / b.coneSpacing_cm, 1e-12);
    }
    const double mu = -std::log1p(-layerOpacity(b.cone)), n0 = 2 * R * cotPhi / b.coneSpacing_cm;
    const double mean = integrateAdaptive([&](double u) { return std::exp(-mu * n0 * (1 - u)); }, 0.0, 1.0);
    EXPECT_NEAR(trueConeOpacity(b, 0.0, 1.0), 1.0 - mean, 1e-9);
}

TEST(TrueConeBough, OpacityMatchesQuadratureAtEveryViewAngle)
{
    const BoughGeometry b = paperBough();
    const double mu = -std::log1p(-layerOpacity(b.cone));
    for (double phiV = 0.05; phiV < kPi; phiV += 0.1) {
        const double c = std::cos(phiV), s = std::sin(phiV);
        // In u (the shader uses u = sin t), split where the stationary point leaves the chord.
        const double ratio = (c / s) * std::tan(b.cone.aperture_rad);
        const double kink = std::abs(ratio) < 1.0 ? std::sqrt(1.0 - ratio * ratio) : 1.0;
        const double mean = integrateAdaptive(
            [&](double u) { return std::exp(-mu * trueConeLayers(b, c, s, u)); }, {0.0, kink, 1.0},
            1e-13, 1e-11);
        EXPECT_NEAR(trueConeOpacity(b, c, s), 1.0 - mean, 1e-6) << phiV;
        EXPECT_GE(trueConeOpacity(b, c, s), 0.0);
        EXPECT_LE(trueConeOpacity(b, c, s), 1.0);
    }
    EXPECT_EQ(trueConeOpacity(b, 1.0, 0.0), 1.0);  // along the branch
}

TEST(TrueConeBough, AsymptotesCountMoreLayersOffTheAxis)
{
    // E12: off the axis the paper's asymptotes count sqrt(1 - u^2) where the cones give
    // 1 - |u| (orthogonal view), so its exact-transmittance opacity is the larger.
    const BoughGeometry b = paperBough();
    const Vec3 axis(0, 0, 1), L(1, 0, 0), V(0, 1, 0);
    const double asymptotes = boughExact(b, boughView(b.cone.aperture_rad, axis, L, V)).total();
    const double cones = trueConeOpacity(b, 0.0, 1.0);
    EXPECT_LT(cones, asymptotes);
    EXPECT_GT(cones, 0.5 * asymptotes);
}

}  // namespace
}  // namespace pine::analytic
