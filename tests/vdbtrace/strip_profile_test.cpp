// A strip profile read over footprints: the constant one is the strip coverage times its
// value, a sampled one integrates exactly, so that footprints tiling the strip sum to its mean.
#include "pine/vdbtrace/strip_profile.h"

#include <gtest/gtest.h>

#include <stdexcept>
#include <vector>

namespace pine::vdbtrace {
namespace {

TEST(StripProfile, AConstantIsTheStripCoverageTimesItsValue)
{
    const StripProfile p = StripProfile::constant(0.4);
    for (const double gap : {-2.0, -0.7, 0.0, 0.3, 1.4}) {
        for (const double w : {0.0, 0.2, 1.0, 5.0}) {
            EXPECT_EQ(p.overFootprint(gap, 1.5, w), stripCoverage(gap, 1.5, w) * 0.4);
        }
    }
    EXPECT_EQ(p.mean(), 0.4);
}

TEST(StripProfile, FootprintsTilingTheStripSumToItsIntegral)
{
    // Cells 0.1, 0.5, 0.9, 0.3 over [-R, R], R = 2: integral 2 R mean = 4 x 0.45 = 1.8.
    const StripProfile p = StripProfile::sampled(std::vector<double>{0.1, 0.5, 0.9, 0.3});
    EXPECT_DOUBLE_EQ(p.mean(), 0.45);
    for (const double w : {0.13, 0.5, 1.7, 6.0}) {
        double sum = 0.0;
        for (double centre = -10.0 + 0.5 * w; centre < 10.0; centre += w) {
            sum += p.overFootprint(centre, 2.0, w) * w;
        }
        EXPECT_NEAR(sum, 1.8, 1e-12) << w;
    }
    // No width reads the cell; a footprint inside one cell reads its value.
    EXPECT_EQ(p.overFootprint(0.5, 2.0, 0.0), 0.9);
    EXPECT_NEAR(p.overFootprint(-1.5, 2.0, 0.4), 0.1, 1e-12);
    EXPECT_EQ(p.overFootprint(2.5, 2.0, 0.4), 0.0);
    EXPECT_THROW(StripProfile::sampled({}), std::invalid_argument);
}

}  // namespace
}  // namespace pine::vdbtrace
