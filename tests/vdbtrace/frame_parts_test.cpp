// What crosses between ranks (frame_parts.h) and an animation's files (frame_sequence.h): a
// frame put together from bands is the whole frame's render, bit for bit, in every plane.
#include "pine/vdbtrace/frame_parts.h"
#include "pine/scenes/scene.h"
#include "pine/support/input_error.h"
#include "pine/vdbtrace/frame_sequence.h"
#include "pine/vdbtrace/methods.h"
#include "pine/vdbtrace/traced_scene.h"

#include <gtest/gtest.h>

#include <cstring>
#include <string>

namespace pine::vdbtrace {
namespace {

// Equal bit for bit (a NaN or a -0 would show), every plane.
void expectSameBits(const Image& a, const Image& b, const std::string& what)
{
    ASSERT_EQ(a.width, b.width) << what;
    ASSERT_EQ(a.height, b.height) << what;
    EXPECT_EQ(a.originX, b.originX) << what;
    EXPECT_EQ(a.originY, b.originY) << what;
    EXPECT_EQ(a.frameWidth, b.frameWidth) << what;
    EXPECT_EQ(a.frameHeight, b.frameHeight) << what;
    ASSERT_EQ(a.rgba.size(), b.rgba.size()) << what;
    EXPECT_EQ(std::memcmp(a.rgba.data(), b.rgba.data(), a.rgba.size() * sizeof(float)), 0)
        << what << ": RGBA";
    ASSERT_EQ(a.aovs.size(), b.aovs.size()) << what;
    for (const auto& [name, plane] : a.aovs) {
        const auto other = b.aovs.find(name);
        ASSERT_NE(other, b.aovs.end()) << what << ": " << name;
        EXPECT_EQ(std::memcmp(plane.data(), other->second.data(), plane.size() * sizeof(float)), 0)
            << what << ": " << name;
    }
}

TEST(FrameParts, RowBandsCoverTheWindowInWholeTileRows)
{
    for (const PixelWindow w :
         {PixelWindow{0, 0, 64, 48}, PixelWindow{3, 5, 50, 100}, PixelWindow{0, 0, 7, 3}}) {
        for (int count = 1; count <= 9; ++count) {
            const std::vector<PixelWindow> bands = rowBands(w, count, 16);
            ASSERT_FALSE(bands.empty());
            EXPECT_LE(int(bands.size()), count);
            EXPECT_EQ(bands.front().y0, w.y0);
            EXPECT_EQ(bands.back().y1, w.y1);
            for (std::size_t b = 0; b < bands.size(); ++b) {
                EXPECT_EQ(bands[b].x0, w.x0);
                EXPECT_EQ(bands[b].x1, w.x1);
                EXPECT_GT(bands[b].y1, bands[b].y0);
                EXPECT_EQ((bands[b].y0 - w.y0) % 16, 0) << "band " << b;
                if (b > 0) {
                    EXPECT_EQ(bands[b].y0, bands[b - 1].y1);
                }
            }
            // As many bands as asked wherever the window has that many tile rows.
            if ((w.y1 - w.y0 + 15) / 16 >= count) {
                EXPECT_EQ(int(bands.size()), count);
            }
        }
    }
}

struct ThreeFirs {
    scenes::Scene scene;
    TracedScene traced;
    explicit ThreeFirs(int width, int height)
    {
        scene = scenes::loadScene(std::string(PINE_SOURCE_DIR) + "/scenes/three-firs.json");
        scene.camera.width = width;
        scene.camera.height = height;
        traced = buildTracedScene(scene);
    }
};

// Bands rendered apart, packed as a rank sends them, unpacked and joined: the whole frame's
// render, every pixel of every plane, stats summed, tree sums within rounding.
TEST(FrameParts, AFrameJoinedFromBandsIsTheWholeFramesRender)
{
    const ThreeFirs f(72, 54);
    for (const char* name : {"multiscale", "geometry"}) {
        const RenderMethod& method = renderMethod(name);
        MethodSettings settings;
        settings.geometry.samples = 2;
        const RenderResult whole = method.render(f.traced, settings, {});
        for (const PixelWindow window : {PixelWindow{0, 0, 72, 54}, PixelWindow{5, 3, 70, 50}}) {
            RenderOptions crop;
            crop.window = window;
            const RenderResult cropped = method.render(f.traced, settings, crop);
            const std::vector<PixelWindow> bands = rowBands(window, 3, crop.tileSize);
            ASSERT_EQ(bands.size(), 3u);
            std::vector<RenderResult> parts;
            for (const PixelWindow& band : bands) {
                RenderOptions options;
                options.window = band;
                parts.push_back(
                    unpackRender(packRender(method.render(f.traced, settings, options))));
            }
            const RenderResult joined = joinBands(std::move(parts), bands, window);
            const bool all = window.x1 == 72 && window.y0 == 0;
            const RenderResult& expected = all ? whole : cropped;
            expectSameBits(joined.image, expected.image, std::string(name) + (all ? "" : ", crop"));
            EXPECT_EQ(joined.stats.coneRays, expected.stats.coneRays);
            EXPECT_EQ(joined.stats.shadowRays, expected.stats.shadowRays);
            EXPECT_EQ(joined.stats.pixelsPerLevel[3], expected.stats.pixelsPerLevel[3]);
            ASSERT_EQ(joined.treeFoliage.size(), expected.treeFoliage.size()) << name;
            for (std::size_t t = 0; t < joined.treeFoliage.size(); ++t) {
                EXPECT_EQ(joined.treeFoliage[t].tree, expected.treeFoliage[t].tree);
                EXPECT_NEAR(joined.treeFoliage[t].coverage_px, expected.treeFoliage[t].coverage_px,
                            1e-9 * expected.treeFoliage[t].coverage_px);
                EXPECT_NEAR(joined.treeFoliage[t].luminance, expected.treeFoliage[t].luminance,
                            1e-9 * expected.treeFoliage[t].luminance);
            }
        }
    }
}

TEST(FrameParts, APackedRenderComesBackWholeAndDamageIsRefused)
{
    RenderResult r;
    r.image = Image(3, 2);
    for (std::size_t i = 0; i < r.image.rgba.size(); ++i) r.image.rgba[i] = float(i) * 0.5f;
    r.image.aov("depth")[4] = -0.0f;
    r.image.originX = 7;
    r.image.frameWidth = 40;
    r.stats.coneRays = 12345;
    r.stats.nanosecondsPerLevel[2] = 99;
    r.seconds = 1.25;
    r.treeFoliage = {{3, 1.5, 0.25}, {9, 2.0, 0.5}};
    const Bytes bytes = packRender(r);
    const RenderResult back = unpackRender(bytes);
    expectSameBits(back.image, r.image, "round trip");
    EXPECT_EQ(back.stats.coneRays, 12345u);
    EXPECT_EQ(back.stats.nanosecondsPerLevel[2], 99u);
    EXPECT_EQ(back.seconds, 1.25);
    EXPECT_EQ(back.treeFoliage, r.treeFoliage);
    Bytes cut(bytes.begin(), bytes.end() - 5);
    EXPECT_THROW(unpackRender(cut), std::runtime_error);
    Bytes longer = bytes;
    longer.push_back(0);
    EXPECT_THROW(unpackRender(longer), std::runtime_error);
    Bytes foreign = bytes;
    foreign[0] ^= 0xff;
    EXPECT_THROW(unpackRender(foreign), std::runtime_error);
}

TEST(FrameSequence, RangesAndFileNames)
{
    EXPECT_EQ(parseFrameRange("3-17").first, 3);
    EXPECT_EQ(parseFrameRange("3-17").last, 17);
    EXPECT_EQ(parseFrameRange("5").count(), 1);
    for (const char* bad : {"", "-3", "7-2", "3-", "1-4x", "a", "2-b", "12abc", " 3-5", "3- 5",
                            "1-+2", "99999999999999999999", "3-99999999"}) {
        EXPECT_THROW(parseFrameRange(bad), InputError) << bad;
    }
    EXPECT_EQ(frameFile("out/forest.exr", 12).string(), "out/forest.0012.exr");
    EXPECT_EQ(frameFile("out/forest.exr", 12345).string(), "out/forest.12345.exr");
    EXPECT_EQ(frameFile("stats.json", 3, ".json").string(), "stats.0003.json");
    const std::vector<int> left =
        framesLeft(FrameRange{2, 7}, [](int f) { return f == 3 || f == 6; });
    EXPECT_EQ(left, (std::vector<int>{2, 4, 5, 7}));
}

}  // namespace
}  // namespace pine::vdbtrace
