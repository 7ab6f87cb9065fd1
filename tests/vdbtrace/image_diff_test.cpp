// compareImages' errors at every scale (issue: a fair comparison): after box-downsampling by k
// a pixel's noise averages away and a bias stays, which is what the scales are for.
#include "pine/vdbtrace/image_diff.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

namespace pine::vdbtrace {
namespace {

void fill(Image& image, int x, int y, double grey)
{
    for (int c = 0; c < 3; ++c) image.pixel(x, y)[c] = float(grey);
    image.pixel(x, y)[3] = 1.0f;
}

TEST(ImageDiff, RefusesWhatNoErrorCanBeMeasuredOf)
{
    // A NaN or an infinite colour in either image (a damaged or overflowed render) is refused,
    // naming the file: it crashed the error map's colour ramp. Two crops of different windows
    // of one frame are not the same pixels, though the same size.
    const auto message = [](const Image& a, const Image& b) -> std::string {
        try {
            (void)compareImages(a, b, "a.exr", "b.exr");
        } catch (const ImageError& e) {
            return e.what();
        }
        return "";
    };
    Image plain(4, 3);
    for (int y = 0; y < 3; ++y) {
        for (int x = 0; x < 4; ++x) fill(plain, x, y, 0.5);
    }
    for (const float bad : {std::nanf(""), std::numeric_limits<float>::infinity()}) {
        Image damaged = plain;
        damaged.pixel(2, 1)[1] = bad;
        EXPECT_EQ(message(damaged, plain), "a.exr: 1 colour value is not finite (NaN or infinity)");
        EXPECT_EQ(message(plain, damaged), "b.exr: 1 colour value is not finite (NaN or infinity)");
    }
    Image left = plain, right = plain;
    left.frameWidth = right.frameWidth = 8;
    left.frameHeight = right.frameHeight = 3;
    right.originX = 4;
    EXPECT_EQ(message(left, right),
              "images show different windows of the frame: [0, 4) x [0, 3) "
              "of 8x3 against [4, 8) x [0, 3) of 8x3");
    EXPECT_EQ(message(left, plain),
              "images show different windows of the frame: [0, 4) x [0, 3) "
              "of 8x3 against the whole frame");
    EXPECT_EQ(message(left, left), "");
}

TEST(ImageDiffScales, NoiseAveragesAwayAndABiasStays)
{
    // A checkerboard of +-a about the reference (noise whose every 2 x 2 block sums to 0) on
    // top of a bias b: per pixel sqrt(a^2 + b^2), from k = 2 on b alone.
    const double a = 0.125, b = 0.0625;
    Image image(32, 16), reference(32, 16);
    for (int y = 0; y < 16; ++y) {
        for (int x = 0; x < 32; ++x) {
            fill(reference, x, y, 0.5);
            fill(image, x, y, 0.5 + b + ((x + y) % 2 ? a : -a));
        }
    }
    const ImageErrors e = compareImages(image, reference);
    ASSERT_EQ(e.byScale.size(), 5u);
    EXPECT_NEAR(e.atScale(1)->rmse, std::sqrt(a * a + b * b), 1e-7);
    EXPECT_NEAR(e.atScale(1)->rmse, e.rmse, 1e-12);
    for (const int k : {2, 4, 8, 16}) {
        ASSERT_NE(e.atScale(k), nullptr) << k;
        EXPECT_NEAR(e.atScale(k)->rmse, b, 1e-7) << k;
        EXPECT_NEAR(e.atScale(k)->mae, b, 1e-7) << k;
        EXPECT_EQ(e.atScale(k)->blocks, std::size_t(32 / k) * std::size_t(16 / k)) << k;
    }
}

TEST(ImageDiffScales, PartialBlocksAndScalesWithoutABlockAreLeftOut)
{
    // 5 x 3: at k = 2 two whole blocks (the last column and row are partial); no whole block
    // at k = 4 or beyond. An error in the partial column counts at k = 1 only.
    Image image(5, 3), reference(5, 3);
    for (int y = 0; y < 3; ++y) {
        for (int x = 0; x < 5; ++x) {
            fill(reference, x, y, 0.25);
            fill(image, x, y, x == 4 || y == 2 ? 0.75 : 0.25);
        }
    }
    const ImageErrors e = compareImages(image, reference);
    ASSERT_EQ(e.byScale.size(), 2u);
    EXPECT_EQ(e.byScale[0].k, 1);
    EXPECT_EQ(e.byScale[1].k, 2);
    EXPECT_EQ(e.byScale[1].blocks, 2u);
    EXPECT_GT(e.byScale[0].rmse, 0.2);
    EXPECT_EQ(e.byScale[1].rmse, 0.0);
    EXPECT_EQ(e.atScale(4), nullptr);
}

// An independent computation: each image's RGB box-downsampled first, luminance after.
double downsampledRmse(const Image& a, const Image& b, int k)
{
    const int bw = a.width / k, bh = a.height / k;
    double sq = 0.0;
    for (int by = 0; by < bh; ++by) {
        for (int bx = 0; bx < bw; ++bx) {
            double mean[2][3] = {};
            for (int y = by * k; y < by * k + k; ++y) {
                for (int x = bx * k; x < bx * k + k; ++x) {
                    for (int c = 0; c < 3; ++c) {
                        mean[0][c] += a.pixel(x, y)[c];
                        mean[1][c] += b.pixel(x, y)[c];
                    }
                }
            }
            const double w[3] = {0.2126, 0.7152, 0.0722};
            double d = 0.0;
            for (int c = 0; c < 3; ++c) d += w[c] * (mean[0][c] - mean[1][c]) / (k * k);
            sq += d * d;
        }
    }
    return std::sqrt(sq / (bw * bh));
}

TEST(ImageDiffScales, MatchesDownsamplingTheImagesFirst)
{
    std::mt19937 rng(7);
    std::uniform_real_distribution<float> u(0.0f, 1.0f);
    for (int trial = 0; trial < 20; ++trial) {
        const int w = 1 + int(rng() % 70), h = 1 + int(rng() % 50);
        Image a(w, h), b(w, h);
        for (float& v : a.rgba) v = u(rng);
        for (float& v : b.rgba) v = u(rng) * (trial % 3 ? 1.0f : 1e-3f);  // some near black
        const ImageErrors e = compareImages(a, b);
        std::size_t expected = 0;
        for (const int k : kErrorScales) expected += w / k >= 1 && h / k >= 1;
        ASSERT_EQ(e.byScale.size(), expected) << w << "x" << h;
        for (const ImageErrors::AtScale& s : e.byScale) {
            EXPECT_NEAR(s.rmse, downsampledRmse(a, b, s.k), 1e-9 * (1.0 + s.rmse))
                << w << "x" << h << " k " << s.k;
            EXPECT_LE(s.mae, s.rmse + 1e-12);
        }
    }
}

// Foliage seen on both images, at a pixel and over blocks: black where the image's own
// foliage luminance is under a quarter of the reference's, counted only where the reference's
// foliage is lit (a quarter of its mean or more) and both cover half the block or more.
TEST(ImageDiff, CountsFoliageBlackWhereTheReferencesIsLit)
{
    constexpr int kSide = 8;
    Image image(kSide, kSide), reference(kSide, kSide);
    // The foliage AOVs: its coverage, and its own luminance times it.
    const auto foliage = [](Image& i, int x, int y, double coverage, double own) {
        const std::size_t at = std::size_t(y) * kSide + x;
        i.aov("foliage")[at] = float(coverage);
        i.aov("foliage_luminance")[at] = float(coverage * own);
    };
    for (int y = 0; y < kSide; ++y) {
        for (int x = 0; x < kSide; ++x) {
            const bool unlit = x < 2 && y < 2;  // in the reference's shadow: black in both
            const bool black = x >= 4 && x < 6 && y >= 4 && y < 6;  // the image's alone
            foliage(reference, x, y, 1.0, unlit ? 0.01 : 0.1);
            foliage(image, x, y, 1.0, unlit ? 0.0 : black ? 0.02 : 0.1);
        }
    }
    foliage(image, 6, 1, 1.0, 0.03);  // darker, not black: over a quarter of 0.1
    foliage(image, 7, 7, 0.3, 0.0);   // black, but too little of it at one pixel
    const ImageErrors e = compareImages(image, reference);
    ASSERT_EQ(e.blackFoliage.size(), 4u);
    const std::size_t blocks[4] = {59, 15, 4, 1}, black[4] = {4, 1, 0, 0};
    for (int s = 0; s < 4; ++s) {
        const ImageErrors::BlackFoliage& b = e.blackFoliage[s];
        EXPECT_EQ(b.k, kErrorScales[s]);
        EXPECT_EQ(b.blocks, blocks[s]) << "k = " << b.k;
        EXPECT_EQ(b.black, black[s]) << "k = " << b.k;
    }
    const nlohmann::json j = e.toJson();
    EXPECT_EQ(j["black_foliage"][0]["black"], 4);
    EXPECT_NEAR(j["black_foliage"][0]["fraction"].get<double>(), 4.0 / 59.0, 1e-12);
    // The reference unlit everywhere: nothing to count; either image without the AOVs: none.
    Image dark = reference;
    for (float& v : dark.aov("foliage_luminance")) v = 0.0f;
    EXPECT_EQ(compareImages(image, dark).blackFoliage[0].blocks, 0u);
    EXPECT_TRUE(compareImages(image, Image(kSide, kSide)).blackFoliage.empty());
    EXPECT_TRUE(compareImages(Image(kSide, kSide), reference).blackFoliage.empty());
}

}  // namespace
}  // namespace pine::vdbtrace
