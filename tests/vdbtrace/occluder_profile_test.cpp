// A bough's opacity from a light along its axis (render.occluder_profile "cones"): it keeps the
// law's mean over the strip for every bough and opacity, and a chain of short boughs end to
// end shades as the long bough they make, where even strips at their means do not.
#include "pine/vdbtrace/occluder_profile.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>
#include <vector>

namespace pine::vdbtrace {
namespace {

// The mean of opacityAt over the strip by the midpoint rule (the profile is smooth but for
// the trapezoid's corners, which land on no sample's interior for long).
double meanOverStrip(const AxialCones& c, double mean)
{
    constexpr int kSamples = 8000;
    double sum = 0.0;
    for (int i = 0; i < kSamples; ++i) {
        sum += c.opacityAt(mean, (i + 0.5) * c.length() / kSamples);
    }
    return sum / kSamples;
}

TEST(OccluderProfile, TheShareIsATrapezoidOfTheConesThatReach)
{
    // A 6 cm bough whose cones reach 3.9 cm: it rises over 3.9 cm, holds to 6, falls to 9.9.
    const AxialCones c{6.0, 3.9};
    EXPECT_DOUBLE_EQ(c.length(), 9.9);
    EXPECT_EQ(c.share(-0.1), 0.0);
    EXPECT_EQ(c.share(10.0), 0.0);
    EXPECT_NEAR(c.share(1.95), 0.5, 1e-12);
    EXPECT_NEAR(c.share(3.9), 1.0, 1e-12);
    EXPECT_NEAR(c.share(5.0), 1.0, 1e-12);
    EXPECT_NEAR(c.share(7.95), 0.5, 1e-12);
    // Shorter than its cones reach (2 cm of apexes): it rises over 2 cm to its largest share,
    // 2 / 3.9 of a long bough's, and holds it to 3.9.
    const AxialCones shortOne{2.0, 3.9};
    EXPECT_NEAR(shortOne.top(), 2.0 / 3.9, 1e-12);
    EXPECT_NEAR(shortOne.share(1.0), 1.0 / 3.9, 1e-12);
    EXPECT_NEAR(shortOne.share(3.0), 2.0 / 3.9, 1e-12);
    EXPECT_NEAR(shortOne.share(4.9), 1.0 / 3.9, 1e-12);
}

TEST(OccluderProfile, KeepsTheLawsMeanOverTheStrip)
{
    // Random boughs from far shorter than their cones reach to 50 times longer, and means from
    // a trace to opaque.
    std::mt19937 rng(11);
    std::uniform_real_distribution<double> apexes(0.3, 200.0), reach(0.5, 8.0), mean(0.0, 1.0);
    double worst = 0.0;
    for (int i = 0; i < 100; ++i) {
        const AxialCones c{i % 4 == 0 ? 0.3 + 3.0 * mean(rng) : apexes(rng), reach(rng)};
        for (const double m : {1e-9, 1e-4, mean(rng), mean(rng), 0.99, 0.9999, 1.0 - 1e-7}) {
            const double kept = meanOverStrip(c, m);
            worst = std::max(worst, std::abs(kept - m) / m);
            ASSERT_NEAR(kept, m, 1e-4 * m)
                << "apexes " << c.apexes_cm << " reach " << c.reach_cm << " mean " << m;
        }
        // An opaque strip stays opaque but for its ends' last hair.
        EXPECT_NEAR(meanOverStrip(c, 1.0), 1.0, 1e-5);
        EXPECT_GT(c.opacityAt(1.0, 0.5 * c.length()), 0.999);
    }
    std::printf("the mean over the strip kept within %.2e of the law's\n", worst);
    EXPECT_EQ(AxialCones({6.0, 3.9}).opacityAt(0.0, 3.0), 0.0);
    EXPECT_EQ(AxialCones({6.0, 3.9}).opacityAt(0.5, 10.0), 0.0);  // beyond the cones' end
}

TEST(OccluderProfile, AChainShadesAsTheLongBoughItMakes)
{
    // Boughs of length L end to end, each with cones reaching c past its last apex: within
    // the chain every point is reached by as many cones as on a long bough. A long bough of
    // optical depth tau gives each its mean (meanOpacity); read back where its cones reach,
    // the chain's transmittance is exp(-tau) all along, as the long bough's. Read even, each
    // at its mean, it is not.
    for (const double L : {1.5, 3.9, 6.0, 12.0}) {
        for (const double tau : {0.05, 0.7, 1.6, 4.0}) {
            const AxialCones bough{L, 3.9};
            const double mean = bough.meanOpacity(tau);
            double worstCones = 0.0, worstEven = 0.0;
            for (int i = 0; i < 500; ++i) {
                const double h = 20.0 + 30.0 * (i + 0.5) / 500;  // well inside 12 boughs' reach
                double cones = 1.0, even = 1.0;
                for (int k = 0; k * L < 60.0; ++k) {
                    const double along = h - k * L;
                    if (along < 0.0 || along > bough.length()) continue;
                    cones *= 1.0 - bough.opacityAt(mean, along);
                    even *= 1.0 - mean;
                }
                worstCones = std::max(worstCones, std::abs(cones / std::exp(-tau) - 1.0));
                worstEven = std::max(worstEven, std::abs(even / std::exp(-tau) - 1.0));
            }
            std::printf(
                "boughs %4.1f cm, tau %.2f: the chain lets through exp(-tau) within "
                "%.1e read by its cones, %.1f%% read even\n",
                L, tau, worstCones, 100.0 * worstEven);
            EXPECT_LT(worstCones, 1e-6) << L << " " << tau;
            if (tau >= 0.7) {
                EXPECT_GT(worstEven, 0.03) << L << " " << tau;
            }
        }
    }
}

}  // namespace
}  // namespace pine::vdbtrace
