// Flicker taken apart (flicker.h): by level band and frame by frame, and along a path measured
// against each frame's neighbours, checked against sequences whose jitter is known.
#include "pine/vdbtrace/flicker.h"
#include "pine/scenes/scene.h"
#include "pine/vdbtrace/animation_flicker.h"
#include "pine/vdbtrace/methods.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

namespace pine::vdbtrace {
namespace {

// `count` frames of w x h grey pixels, pixel i at frame t: value(i, t).
template <class Value>
std::vector<Image> sequence(int w, int h, int count, Value value)
{
    std::vector<Image> frames;
    for (int t = 0; t < count; ++t) {
        Image im(w, h);
        for (int i = 0; i < w * h; ++i) {
            const float v = float(value(i, t));
            for (int c = 0; c < 3; ++c) im.rgba[4 * std::size_t(i) + c] = v;
            im.rgba[4 * std::size_t(i) + 3] = 1.0f;
        }
        frames.push_back(std::move(im));
    }
    return frames;
}

// The whole-sequence measure is temporalFlicker's, and both windows see a steady ramp as 0.
TEST(FlickerBreakdown, TheWholeLineIsTemporalFlickerAndARampIsSteady)
{
    std::mt19937 rng(3);
    std::normal_distribution<double> noise(0.0, 0.05);
    const auto noisy =
        sequence(16, 8, 9, [&](int i, int) { return 0.3 + 0.01 * i + noise(rng); });
    // Each pixel's residual about its own least-squares line, computed here with the slope
    // and intercept solved as a 2 x 2 system (not the centred form flicker.cpp uses).
    double expected = 0.0;
    for (int i = 0; i < 16 * 8; ++i) {
        double n = 0, st = 0, stt = 0, sy = 0, sty = 0;
        for (int t = 0; t < 9; ++t) {
            const double y = noisy[std::size_t(t)].rgba[4 * std::size_t(i)];
            n += 1;
            st += t;
            stt += double(t) * t;
            sy += y;
            sty += t * y;
        }
        const double slope = (n * sty - st * sy) / (n * stt - st * st);
        const double intercept = (sy - slope * st) / n;
        double squares = 0.0;
        for (int t = 0; t < 9; ++t) {
            const double r = noisy[std::size_t(t)].rgba[4 * std::size_t(i)] - intercept - slope * t;
            squares += r * r;
        }
        expected += std::sqrt(squares / 9.0);
    }
    EXPECT_NEAR(flickerBreakdown(noisy).flicker, expected / (16 * 8), 1e-6);
    const auto ramp = sequence(16, 8, 9, [](int i, int t) { return 0.1 + 0.002 * i * t; });
    EXPECT_NEAR(flickerBreakdown(ramp, {}, 1, 0).flicker, 0.0, 1e-6);
    EXPECT_NEAR(flickerBreakdown(ramp, {}, 1, 3).flicker, 0.0, 1e-6);
}

// Along a curve (a pixel brightening then darkening, as an edge sweeps over it) the whole
// line counts the curve as flicker; the neighbours' line does not, and still finds the
// jitter added to it: its standard deviation, in every band.
TEST(FlickerBreakdown, TheNeighboursLineSeesJitterNotTheCurve)
{
    std::mt19937 rng(11);
    std::normal_distribution<double> unit(0.0, 1.0);
    const int w = 64, h = 64, count = 40;
    const double sigma[2] = {0.01, 0.04};  // band 0: the left half of the image, band 1 the right
    std::vector<std::uint8_t> band(std::size_t(w) * h);
    for (int i = 0; i < w * h; ++i) band[std::size_t(i)] = std::uint8_t((i % w) >= w / 2);
    const auto curve = [](int t) { return 0.5 + 0.3 * std::sin(double(t) / 40.0 * 3.14159); };
    const auto frames = sequence(
        w, h, count, [&](int i, int t) { return curve(t) + sigma[(i % w) >= w / 2] * unit(rng); });
    const FlickerBreakdown local = flickerBreakdown(frames, band, 2, 3);
    // Each pixel's estimate is a root mean square of 38 departures: slightly below sigma
    // on average (Jensen), and the curve adds its second difference (0.3 (pi/40)^2 / 2).
    EXPECT_NEAR(local.perBand[0], sigma[0], 0.08 * sigma[0]);
    EXPECT_NEAR(local.perBand[1], sigma[1], 0.05 * sigma[1]);
    EXPECT_EQ(local.bandPixels[0], std::size_t(w * h / 2));
    EXPECT_NEAR(local.flicker, 0.5 * (local.perBand[0] + local.perBand[1]), 1e-12);
    const auto smooth = sequence(w, h, count, [&](int, int t) { return curve(t); });
    EXPECT_GT(flickerBreakdown(smooth, {}, 1, 0).flicker, 0.02);
    EXPECT_LT(flickerBreakdown(smooth, {}, 1, 3).flicker, 0.001);
    EXPECT_THROW(flickerBreakdown(frames, band, 2, 5), ImageError);
    EXPECT_THROW(flickerBreakdown(frames, {1, 0}, 2, 3), ImageError);
}

// A frame that pops (every pixel brighter once) is a spike over the frames: its departure
// is the jump, its neighbours' half of it, the others' none.
TEST(FlickerBreakdown, AFrameThatPopsIsASpike)
{
    const auto frames =
        sequence(8, 8, 10, [](int, int t) { return 0.2 + 0.01 * t + (t == 6 ? 0.1 : 0.0); });
    const FlickerBreakdown f = flickerBreakdown(frames, {}, 1, 3);
    EXPECT_NEAR(f.residualPerFrame[6], 0.1, 1e-6);
    EXPECT_NEAR(f.residualPerFrame[5], 0.05, 1e-6);
    EXPECT_NEAR(f.residualPerFrame[7], 0.05, 1e-6);
    EXPECT_NEAR(f.residualPerFrame[3], 0.0, 1e-6);
    EXPECT_TRUE(std::isnan(f.residualPerFrame[0]));
    EXPECT_TRUE(std::isnan(f.residualPerFrame[9]));
    EXPECT_NEAR(f.luminancePerFrame[6], 0.36, 1e-6);
}

TEST(LevelBands, EachPixelTakesItsMeanLevelWhereItHasFoliage)
{
    std::vector<Image> frames(3, Image(4, 1));
    const float levels[3][4] = {{0, 1.2f, 2.6f, 0}, {0, 1.4f, 0, 2.0f}, {0, 1.9f, 3.0f, 2.4f}};
    for (int t = 0; t < 3; ++t) {
        auto& plane = frames[std::size_t(t)].aov("level");
        for (int i = 0; i < 4; ++i) plane[std::size_t(i)] = levels[t][i];
    }
    // Pixel 1: mean 1.5 -> 2; pixel 2: (2.6 + 3.0) / 2 = 2.8 -> 3 (its empty frame not counted).
    EXPECT_EQ(levelBands(frames), (std::vector<std::uint8_t>{0, 2, 3, 2}));
    frames[1].aovs.clear();
    EXPECT_THROW(levelBands(frames), ImageError);
}

// The methods along three-firs' path, with a truth: each sequence's flicker, and each method's
// error flicker against the truth, are what the frames rendered one by one give under an
// independent computation (second differences summed here); the frames kept are those renders.
TEST(AnimationFlicker, EachSequenceIsItsFramesRenderedAlone)
{
    scenes::Scene scene =
        scenes::loadScene(std::string(PINE_SOURCE_DIR) + "/scenes/three-firs.json");
    scene.camera.width = 40;
    scene.camera.height = 30;
    std::vector<scenes::Camera> cameras;
    for (int f = 1; f <= 5; ++f) cameras.push_back(scene.cameraPath.at(f, scene.camera));
    const AnimationFlicker a = measureAnimationFlicker(scene, cameras, {0, 3}, 3, 4, {});
    ASSERT_EQ(a.rows.size(), std::size(kAnimationSequences) + 1);
    ASSERT_TRUE(a.rows.back().truth);
    EXPECT_FALSE(a.rows.back().errorFlicker);
    // Mean over pixels of sqrt(mean over inner frames of the second difference^2 / 1.5).
    const auto localFlicker = [](const std::vector<std::vector<double>>& lum) {
        double sum = 0.0;
        for (std::size_t i = 0; i < lum[0].size(); ++i) {
            double squares = 0.0;
            for (std::size_t t = 1; t + 1 < lum.size(); ++t) {
                const double d = lum[t][i] - 0.5 * (lum[t - 1][i] + lum[t + 1][i]);
                squares += d * d;
            }
            sum += std::sqrt(squares / double(lum.size() - 2) / 1.5);
        }
        return sum / double(lum[0].size());
    };
    std::vector<std::vector<std::vector<double>>> lums;  // [sequence][frame][pixel]
    for (std::size_t m = 0; m < a.rows.size(); ++m) {
        const bool truth = m == std::size(kAnimationSequences);
        const char* method = truth ? "geometry" : kAnimationSequences[m].method;
        std::vector<std::vector<double>> lum;
        for (std::size_t f = 0; f < cameras.size(); ++f) {
            scenes::Scene at = scene;
            at.camera = cameras[f];
            const TracedScene traced = buildTracedScene(at);
            MethodSettings settings;
            settings.geometry.samples = truth ? 4 : std::max(1, kAnimationSequences[m].samples);
            settings.geometry.sampleSeed = truth ? 1 : 0;
            const RenderResult r = renderMethod(method).render(traced, settings, {});
            std::vector<double> l;
            for (std::size_t i = 0; i + 3 < r.image.rgba.size(); i += 4) {
                l.push_back(0.2126 * r.image.rgba[i] + 0.7152 * r.image.rgba[i + 1] +
                            0.0722 * r.image.rgba[i + 2]);
            }
            lum.push_back(l);
            if (f == 0 || f == 3) {
                const Image& kept = a.rows[m].kept[f == 0 ? 0 : 1];
                EXPECT_EQ(kept.rgba, r.image.rgba) << a.rows[m].method << ", frame " << f;
            }
        }
        EXPECT_NEAR(a.rows[m].flicker.flicker, localFlicker(lum), 1e-9) << a.rows[m].method;
        EXPECT_GT(a.rows[m].flicker.flicker, 0.0) << a.rows[m].method;
        EXPECT_GT(a.rows[m].cpuSecondsPerFrame, 0.0) << a.rows[m].method;
        lums.push_back(std::move(lum));
    }
    for (std::size_t m = 0; m < std::size(kAnimationSequences); ++m) {
        std::vector<std::vector<double>> error = lums[m];
        for (std::size_t f = 0; f < error.size(); ++f) {
            for (std::size_t i = 0; i < error[f].size(); ++i) error[f][i] -= lums.back()[f][i];
        }
        ASSERT_TRUE(a.rows[m].errorFlicker) << a.rows[m].method;
        // Float frames subtracted before the luminance here, after it there: equal to rounding.
        EXPECT_NEAR(a.rows[m].errorFlicker->flicker, localFlicker(error), 1e-6) << a.rows[m].method;
    }
}

}  // namespace
}  // namespace pine::vdbtrace
