// Frames on disk: EXR round trips bit-exactly with its AOV layers and metadata, PNG previews
// carry sRGB values, the level map follows Figure 12's colours, and no write ever leaves a
// half-written file or a temporary behind. Each test works in a fresh temporary folder.
#include "pine/vdbtrace/image.h"

#include <OpenImageIO/imageio.h>

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <bit>
#include <cstdint>
#include <cstdlib>
#include <fstream>
#include <iterator>
#include <limits>
#include <random>
#include <sstream>
#include <set>
#include <string>
#include <thread>
#include <vector>

namespace {

namespace fs = std::filesystem;
using pine::vdbtrace::Image;
using pine::vdbtrace::ImageError;
using pine::vdbtrace::Metadata;

class ImageIo : public ::testing::Test {
protected:
    void SetUp() override
    {
        dir = fs::temp_directory_path() /
              ("pine-image-io-" + std::to_string(std::random_device{}()) + "-" +
               ::testing::UnitTest::GetInstance()->current_test_info()->name());
        fs::create_directories(dir);
    }
    void TearDown() override
    {
        std::error_code ignored;
        fs::remove_all(dir, ignored);
    }

    /// Names of everything in the test folder, sorted: shows any leftover temporary.
    std::vector<std::string> listing() const
    {
        std::vector<std::string> names;
        for (const auto& entry : fs::directory_iterator(dir)) {
            names.push_back(entry.path().filename().string());
        }
        std::sort(names.begin(), names.end());
        return names;
    }

    fs::path dir;
};

std::string slurp(const fs::path& path)
{
    std::ifstream in(path, std::ios::binary);
    return std::string(std::istreambuf_iterator<char>(in), {});
}

/// 8-bit RGB of a PNG, as OIIO reads it back.
struct Bytes {
    int width = 0, height = 0, channels = 0;
    std::vector<std::uint8_t> values;
    std::array<int, 3> at(int x, int y) const
    {
        const std::size_t i = (std::size_t(y) * width + x) * channels;
        return {values[i], values[i + 1], values[i + 2]};
    }
};

Bytes readPng(const fs::path& path)
{
    auto in = OIIO::ImageInput::open(path.string());
    if (!in) throw std::runtime_error(OIIO::geterror());
    Bytes bytes;
    bytes.width = in->spec().width;
    bytes.height = in->spec().height;
    bytes.channels = in->spec().nchannels;
    bytes.values.resize(std::size_t(bytes.width) * bytes.height * bytes.channels);
    if (!in->read_image(0, 0, 0, bytes.channels, OIIO::TypeDesc::UINT8, bytes.values.data())) {
        throw std::runtime_error(in->geterror());
    }
    EXPECT_EQ(std::string(in->format_name()), "png");
    return bytes;
}

/// A 5 x 3 frame whose every value differs, with awkward floats (tiny, negative, huge).
Image sampleImage()
{
    Image image(5, 3);
    for (std::size_t i = 0; i < image.rgba.size(); ++i) {
        image.rgba[i] = float(i) * 0.0371f - 0.2f;
    }
    image.rgba[0] = 1e-30f;
    image.rgba[5] = -3.5e7f;
    image.rgba[6] = std::numeric_limits<float>::denorm_min();
    auto& level = image.aov("level");
    auto& depth = image.aov("Z");
    for (std::size_t i = 0; i < level.size(); ++i) {
        level[i] = 1.0f + float(i) / 7.0f;
        depth[i] = float(i) * 123.456f;
    }
    depth[3] = std::numeric_limits<float>::infinity();  // nothing hit
    return image;
}

void expectBitExact(const std::vector<float>& expected, const std::vector<float>& actual,
                    const std::string& what)
{
    ASSERT_EQ(expected.size(), actual.size()) << what;
    for (std::size_t i = 0; i < expected.size(); ++i) {
        EXPECT_EQ(std::bit_cast<std::uint32_t>(expected[i]),
                  std::bit_cast<std::uint32_t>(actual[i]))
            << what << "[" << i << "]: " << expected[i] << " vs " << actual[i];
    }
}

TEST_F(ImageIo, ExrRoundTripIsBitExact)
{
    const Image image = sampleImage();
    pine::vdbtrace::Matrix44 camera;
    for (int i = 0; i < 4; ++i) {
        for (int j = 0; j < 4; ++j) camera.m[i][j] = float(i * 4 + j) * 0.5f - 3.0f;
    }
    const Metadata metadata = {{"scene", "paper-fig12.json"},
                               {"method", "multiscale"},
                               {"renderTimeSeconds", 12.5f},
                               {"samplesPerPixel", 16},
                               {"worldToCamera", camera},
                               {"pine:grid_to_world", camera},
                               {"settings", std::string(300, 'x') + " with spaces, ümlauts"}};
    const fs::path path = dir / "frame.exr";
    pine::vdbtrace::writeExr(image, path, metadata);

    Metadata back;
    const Image read = pine::vdbtrace::readExr(path, &back);
    EXPECT_EQ(read.width, 5);
    EXPECT_EQ(read.height, 3);
    expectBitExact(image.rgba, read.rgba, "rgba");
    ASSERT_EQ(read.aovs.size(), 2u);
    ASSERT_TRUE(read.aovs.count("level") && read.aovs.count("Z"));
    expectBitExact(image.aovs.at("level"), read.aovs.at("level"), "level");
    expectBitExact(image.aovs.at("Z"), read.aovs.at("Z"), "Z");

    // Each value comes back with its type.
    Metadata expected = metadata;
    std::sort(expected.begin(), expected.end(),
              [](const auto& a, const auto& b) { return a.first < b.first; });
    ASSERT_EQ(back.size(), expected.size());
    for (std::size_t i = 0; i < back.size(); ++i) {
        EXPECT_EQ(back[i].first, expected[i].first);
        EXPECT_TRUE(back[i].second == expected[i].second) << back[i].first;
    }
    EXPECT_EQ(listing(), std::vector<std::string>{"frame.exr"});
}

TEST_F(ImageIo, ExrIsFloatZipWithAovLayers)
{
    const fs::path path = dir / "frame.exr";
    pine::vdbtrace::writeExr(sampleImage(), path, {});
    auto in = OIIO::ImageInput::open(path.string());
    ASSERT_TRUE(in) << OIIO::geterror();
    const OIIO::ImageSpec& spec = in->spec();
    EXPECT_EQ(std::string(in->format_name()), "openexr");
    EXPECT_EQ(spec.format, OIIO::TypeDesc::FLOAT);
    EXPECT_EQ(spec.get_string_attribute("compression"), "zip");
    std::vector<std::string> names = spec.channelnames;
    ASSERT_EQ(names.size(), 6u);
    EXPECT_EQ(std::vector<std::string>(names.begin(), names.begin() + 4),
              (std::vector<std::string>{"R", "G", "B", "A"}));
    std::sort(names.begin() + 4, names.end());
    EXPECT_EQ(names[4], "Z");  // OpenEXR's depth channel, under its own name
    EXPECT_EQ(names[5], "level.Y");
}

TEST_F(ImageIo, OiiotoolListsAovChannelsAndMetadata)
{
    if (std::system("command -v oiiotool > /dev/null 2>&1") != 0) {
        GTEST_SKIP() << "oiiotool is not on PATH (Debian package openimageio-tools)";
    }
    const fs::path exr = dir / "frame.exr";
    const fs::path info = dir / "info.txt";
    pine::vdbtrace::writeExr(sampleImage(), exr, {{"method", "reference"}});
    const std::string command =
        "oiiotool --info -v '" + exr.string() + "' > '" + info.string() + "' 2>&1";
    ASSERT_EQ(std::system(command.c_str()), 0) << slurp(info);
    const std::string text = slurp(info);
    EXPECT_NE(text.find("level.Y"), std::string::npos) << text;
    EXPECT_NE(text.find("channel list: R, G, B, A, Z, level.Y"), std::string::npos) << text;
    EXPECT_NE(text.find("method: \"reference\""), std::string::npos) << text;
}

TEST_F(ImageIo, PngIsSrgbEncodedAndClamped)
{
    Image image(4, 3);
    float* p = image.pixel(1, 2);
    p[0] = 0.5f;  // sRGB(0.5) = 0.7354 -> 188
    p[1] = 0.0f;
    p[2] = 1.0f;
    p[3] = 1.0f;
    float* q = image.pixel(3, 0);
    q[0] = 7.0f;  // clamped
    q[1] = -2.0f;
    q[2] = std::numeric_limits<float>::quiet_NaN();
    q[3] = 0.5f;
    float* r = image.pixel(0, 1);
    r[0] = 0.001f;  // linear segment: 12.92 * 0.001 * 255 = 3.29 -> 3
    r[1] = 0.2140f;  // 0.5 in sRGB -> 127.5: 127 or 128
    r[2] = 0.25f;    // premultiplied: alpha does not scale it again
    r[3] = 0.25f;
    const fs::path path = dir / "preview.png";
    pine::vdbtrace::writePng(image, path);

    const Bytes png = readPng(path);
    EXPECT_EQ(png.width, 4);
    EXPECT_EQ(png.height, 3);
    EXPECT_EQ(png.channels, 3);
    EXPECT_EQ(png.at(1, 2), (std::array<int, 3>{188, 0, 255}));
    EXPECT_EQ(png.at(3, 0), (std::array<int, 3>{255, 0, 0}));
    EXPECT_EQ(png.at(0, 1)[0], 3);
    EXPECT_NEAR(png.at(0, 1)[1], 127.5, 0.6);
    EXPECT_EQ(png.at(0, 1)[2], 137);  // sRGB(0.25) = 0.5371 -> 136.96
    EXPECT_EQ(png.at(0, 0), (std::array<int, 3>{0, 0, 0}));
    EXPECT_EQ(listing(), std::vector<std::string>{"preview.png"});
}

TEST_F(ImageIo, LevelPngFollowsFigure12Colours)
{
    const float levels[] = {1.0f, 2.0f, 3.0f, 1.5f, 0.0f, 2.5f, 2.0f};
    const float alphas[] = {1.0f, 1.0f, 1.0f, 1.0f, 1.0f, 1.0f, 0.5f};
    Image image(7, 1);
    auto& level = image.aov("level");
    for (int x = 0; x < 7; ++x) {
        level[x] = levels[x];
        image.pixel(x, 0)[3] = alphas[x];
    }
    const fs::path path = dir / "levels.png";
    pine::vdbtrace::writeLevelPng(image, path);

    const Bytes png = readPng(path);
    ASSERT_EQ(png.width, 7);
    ASSERT_EQ(png.height, 1);
    ASSERT_EQ(png.channels, 3);
    using Rgb = std::array<int, 3>;
    EXPECT_EQ(png.at(0, 0), (Rgb{255, 0, 0})) << "level 1: needle, red";
    EXPECT_EQ(png.at(1, 0), (Rgb{0, 255, 0})) << "level 2: cone, green";
    EXPECT_EQ(png.at(2, 0), (Rgb{0, 0, 255})) << "level 3: bough, blue";
    EXPECT_EQ(png.at(3, 0), (Rgb{128, 128, 0})) << "level 1.5: half red, half green";
    EXPECT_EQ(png.at(4, 0), (Rgb{0, 0, 0})) << "level 0: nothing hit, black";
    EXPECT_EQ(png.at(5, 0), (Rgb{0, 128, 128})) << "level 2.5: half green, half blue";
    EXPECT_EQ(png.at(6, 0), (Rgb{0, 128, 0})) << "half coverage halves the colour";
}

TEST_F(ImageIo, LevelPngWithoutLevelAovThrowsAndWritesNothing)
{
    const fs::path path = dir / "levels.png";
    EXPECT_THROW(pine::vdbtrace::writeLevelPng(Image(2, 2), path), ImageError);
    EXPECT_TRUE(listing().empty());
}

TEST_F(ImageIo, WriteIntoMissingFolderThrowsNamingThePath)
{
    const fs::path path = dir / "missing" / "frame.exr";
    const Image image = sampleImage();
    auto expectFailure = [&](auto&& write, const fs::path& target) {
        try {
            write(target);
            ADD_FAILURE() << "no ImageError for " << target;
        } catch (const ImageError& error) {
            const std::string message = error.what();
            EXPECT_NE(message.find(target.string()), std::string::npos) << message;
            EXPECT_EQ(message.find('\n'), std::string::npos) << "one line: " << message;
        }
    };
    expectFailure([&](const fs::path& t) { pine::vdbtrace::writeExr(image, t, {}); }, path);
    expectFailure([&](const fs::path& t) { pine::vdbtrace::writePng(image, t); },
                  path.parent_path() / "preview.png");
    expectFailure([&](const fs::path& t) { pine::vdbtrace::writeLevelPng(image, t); },
                  path.parent_path() / "levels.png");
    EXPECT_TRUE(listing().empty()) << "nothing created, not even the folder";
}

TEST_F(ImageIo, UnwritablePathThrowsAndLeavesNoTemporary)
{
    // Permission bits do not stop root, so make the path unwritable by its shape: under a
    // regular file, and onto an existing folder (the temporary is written, the rename fails).
    std::ofstream(dir / "plain.txt") << "not a folder";
    const fs::path underFile = dir / "plain.txt" / "frame.exr";
    EXPECT_THROW(pine::vdbtrace::writeExr(sampleImage(), underFile, {}), ImageError);

    fs::create_directory(dir / "taken.exr");
    std::ofstream(dir / "taken.exr" / "inside.txt") << "keep me";
    try {
        pine::vdbtrace::writeExr(sampleImage(), dir / "taken.exr", {});
        ADD_FAILURE() << "no ImageError when the path is a folder";
    } catch (const ImageError& error) {
        EXPECT_NE(std::string(error.what()).find((dir / "taken.exr").string()),
                  std::string::npos)
            << error.what();
    }
    EXPECT_THROW(pine::vdbtrace::writePng(sampleImage(), dir / "taken.exr"), ImageError);
    EXPECT_EQ(listing(), (std::vector<std::string>{"plain.txt", "taken.exr"}));
    EXPECT_EQ(slurp(dir / "taken.exr" / "inside.txt"), "keep me");
}

TEST_F(ImageIo, FailedWriteKeepsTheExistingFile)
{
    const fs::path exr = dir / "frame.exr";
    const fs::path png = dir / "levels.png";
    pine::vdbtrace::writeExr(sampleImage(), exr, {{"method", "geometry"}});
    Image withLevel = sampleImage();
    pine::vdbtrace::writeLevelPng(withLevel, png);
    const std::string exrBefore = slurp(exr), pngBefore = slurp(png);
    ASSERT_FALSE(exrBefore.empty());

    Image badAov = sampleImage();
    badAov.aov("level").pop_back();
    EXPECT_THROW(pine::vdbtrace::writeExr(badAov, exr, {}), ImageError);
    EXPECT_THROW(pine::vdbtrace::writeExr(sampleImage(), exr, {{"compression", "none"}}),
                 ImageError);
    EXPECT_THROW(pine::vdbtrace::writeExr(sampleImage(), exr, {{"a", "1"}, {"a", "2"}}),
                 ImageError);
    // A camera matrix only as a matrix.
    EXPECT_THROW(pine::vdbtrace::writeExr(sampleImage(), exr, {{"worldToCamera", "identity"}}),
                 ImageError);
    EXPECT_THROW(pine::vdbtrace::writeLevelPng(Image(5, 3), png), ImageError);

    EXPECT_EQ(slurp(exr), exrBefore);
    EXPECT_EQ(slurp(png), pngBefore);
    EXPECT_EQ(listing(), (std::vector<std::string>{"frame.exr", "levels.png"}));
    Metadata back;
    pine::vdbtrace::readExr(exr, &back);
    EXPECT_EQ(back, (Metadata{{"method", "geometry"}}));
}

TEST_F(ImageIo, ReaderNeverSeesAHalfWrittenFile)
{
    // A second thread watches the final name while a large frame replaces a small one: it
    // may see the old file or the new one, never a size in between. (Writing in place shows
    // the file growing while OpenEXR compresses its chunks.)
    const fs::path path = dir / "frame.exr";
    pine::vdbtrace::writeExr(Image(2, 2), path, {});
    const std::uintmax_t before = fs::file_size(path);

    Image large(1024, 768);
    std::mt19937 noise(7);  // fixed seed: incompressible values make the write take a while
    std::uniform_real_distribution<float> uniform(0.0f, 1.0f);
    for (float& v : large.rgba) v = uniform(noise);
    for (float& v : large.aov("depth")) v = uniform(noise);

    std::atomic<bool> done{false};
    std::set<std::uintmax_t> seen;
    std::thread watcher([&] {
        while (!done.load()) {
            std::error_code error;
            const std::uintmax_t size = fs::file_size(path, error);
            if (!error) seen.insert(size);
        }
    });
    pine::vdbtrace::writeExr(large, path, {});
    done = true;
    watcher.join();

    const std::uintmax_t after = fs::file_size(path);
    for (std::uintmax_t size : seen) {
        EXPECT_TRUE(size == before || size == after)
            << "saw " << size << " bytes; old " << before << ", new " << after;
    }
    EXPECT_EQ(listing(), std::vector<std::string>{"frame.exr"});
}

TEST_F(ImageIo, InconsistentImageIsRejected)
{
    Image empty;
    EXPECT_THROW(pine::vdbtrace::writeExr(empty, dir / "a.exr", {}), ImageError);
    Image shortRgba(3, 2);
    shortRgba.rgba.pop_back();
    EXPECT_THROW(pine::vdbtrace::writePng(shortRgba, dir / "a.png"), ImageError);
    Image unnamed(3, 2);
    unnamed.aov("");
    EXPECT_THROW(pine::vdbtrace::writeExr(unnamed, dir / "a.exr", {}), ImageError);
    EXPECT_TRUE(listing().empty());
}

TEST_F(ImageIo, ReadExrRejectsMissingAndNonExrFiles)
{
    EXPECT_THROW(pine::vdbtrace::readExr(dir / "none.exr"), ImageError);
    const fs::path png = dir / "preview.png";
    pine::vdbtrace::writePng(sampleImage(), png);
    try {
        pine::vdbtrace::readExr(png);
        ADD_FAILURE() << "a PNG read as EXR";
    } catch (const ImageError& error) {
        EXPECT_NE(std::string(error.what()).find(png.string()), std::string::npos);
    }
    std::ofstream(dir / "broken.exr") << "not an image";
    EXPECT_THROW(pine::vdbtrace::readExr(dir / "broken.exr"), ImageError);
}

}  // namespace
