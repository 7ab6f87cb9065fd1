// Ground heights: the plane, and the Gaussian hill of Figure 10's scene.
#include "pine/scenes/scene.h"

#include <gtest/gtest.h>

#include <cmath>

namespace pine::scenes {
namespace {

TEST(Ground, PlaneIsFlatAtItsHeight)
{
    Ground g;
    g.kind = Ground::Kind::Plane;
    g.height_cm = 12.5;
    for (double x : {-1e4, 0.0, 3.0, 7e5}) EXPECT_EQ(g.heightAt(x, -x / 3), 12.5);
    g.kind = Ground::Kind::None;  // trees without ground still stand at its height
    EXPECT_EQ(g.heightAt(4, 5), 12.5);
}

Ground hill()
{
    Ground g;
    g.kind = Ground::Kind::Hill;
    g.height_cm = -20;
    g.hillPeak_cm = 300;
    g.hillRadius_cm = 500;
    g.hillCentre_cm = Vec2(100, -40);
    return g;
}

TEST(Ground, HillPeaksAtItsCentre)
{
    const Ground g = hill();
    EXPECT_DOUBLE_EQ(g.heightAt(100, -40), 280.0);
    // The peak is the maximum: every step away goes down.
    for (double d : {1.0, 50.0, 500.0, 3000.0}) {
        for (double a = 0; a < 6.28; a += 0.5) {
            EXPECT_LT(g.heightAt(100 + d * std::cos(a), -40 + d * std::sin(a)), 280.0);
        }
    }
}

TEST(Ground, HillIsSymmetricAboutItsCentre)
{
    const Ground g = hill();
    for (double d : {10.0, 321.0, 900.0}) {
        const double ref = g.heightAt(100 + d, -40);
        for (double a = 0.1; a < 6.28; a += 0.7) {
            // Rotationally symmetric: the same height at the same distance in any direction.
            EXPECT_NEAR(g.heightAt(100 + d * std::cos(a), -40 + d * std::sin(a)), ref,
                        1e-12 * 300);
        }
    }
}

TEST(Ground, HillFollowsItsGaussian)
{
    const Ground g = hill();
    // One radius out: peak * exp(-1/2); far out: the base height.
    EXPECT_NEAR(g.heightAt(600, -40), -20 + 300 * std::exp(-0.5), 1e-12 * 300);
    EXPECT_NEAR(g.heightAt(1e5, 1e5), -20.0, 1e-12);
}

}  // namespace
}  // namespace pine::scenes
