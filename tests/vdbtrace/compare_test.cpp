// `vdbtrace compare` on a tiny fir with the quick settings: every method and setting has its
// row, image and error map, errors behave (finite, zero for the truth itself, falling with the
// samples), and the dolly's flicker is measured for the three methods.
#include "pine/vdbtrace/compare.h"
#include "pine/vdbtrace/flicker.h"

#include "test_scenes.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

namespace pine::vdbtrace {
namespace {

namespace fs = std::filesystem;

// The tracer tests' fir at 48 x 36, every effect on.
const std::string kFirScene =
    test::firScene(R"("diffuse", "specular", "shadows", "self_shadowing")", 48, 36);

using Table = std::vector<std::map<std::string, std::string>>;

Table readCsv(const fs::path& path)
{
    std::ifstream in(path);
    std::string line;
    std::vector<std::string> header;
    Table rows;
    while (std::getline(in, line)) {
        std::vector<std::string> cells;
        std::istringstream s(line);
        for (std::string cell; std::getline(s, cell, ',');) cells.push_back(cell);
        if (line.back() == ',') cells.emplace_back();
        if (header.empty()) {
            header = cells;
            continue;
        }
        std::map<std::string, std::string> row;
        for (std::size_t i = 0; i < header.size() && i < cells.size(); ++i) {
            row[header[i]] = cells[i];
        }
        rows.push_back(row);
    }
    return rows;
}

class Compare : public ::testing::Test {
protected:
    // One run shared by the tests: it is the slow part.
    static void SetUpTestSuite()
    {
        dir = fs::temp_directory_path() / ("pine-compare-test-" + std::to_string(::getpid()));
        fs::create_directories(dir);
        std::ofstream(dir / "fir.json") << kFirScene;
        CompareOptions options;
        options.sceneFile = dir / "fir.json";
        options.outDir = dir / "out";
        options.settings = CompareSettings::forQuick(true);
        // No plot: the CLI test plots; matplotlib need not be here.
        runCompare(options);
        status = 0;
    }
    static void TearDownTestSuite()
    {
        std::error_code ec;
        fs::remove_all(dir, ec);
    }
    static inline fs::path dir;
    static inline int status = -1;
};

TEST_F(Compare, ReportHasARowPerMethodAndSetting)
{
    ASSERT_EQ(status, 0);
    const Table rows = readCsv(dir / "out" / "report.csv");
    std::vector<std::string> names;
    for (const auto& r : rows) names.push_back(r.at("method") + "_" + r.at("setting"));
    const std::vector<std::string> expected = {
        "truth_16spp",    "geometry_1spp", "geometry_4spp", "reference_1cm",
        "reference_0.5cm", "multiscale_L1", "multiscale_L2", "multiscale_L3", "multiscale_auto"};
    EXPECT_EQ(names, expected);
    for (const std::string& name : expected) {
        EXPECT_TRUE(fs::exists(dir / "out" / (name + ".exr"))) << name;
        EXPECT_TRUE(fs::exists(dir / "out" / (name + ".png"))) << name;
        if (name != "truth_16spp") {
            EXPECT_TRUE(fs::exists(dir / "out" / (name + ".error.png"))) << name;
        }
    }
    EXPECT_TRUE(fs::exists(dir / "out" / "report.md"));
}

TEST_F(Compare, ErrorsAreFiniteZeroForTheTruthAndFallWithSamples)
{
    ASSERT_EQ(status, 0);
    const Table rows = readCsv(dir / "out" / "report.csv");
    ASSERT_FALSE(rows.empty());
    std::map<std::string, double> rmse;
    for (const auto& r : rows) {
        const double e = std::stod(r.at("rmse")), t = std::stod(r.at("seconds"));
        EXPECT_TRUE(std::isfinite(e) && e >= 0.0) << r.at("method") << " " << r.at("setting");
        EXPECT_TRUE(std::isfinite(t) && t > 0.0) << r.at("method") << " " << r.at("setting");
        EXPECT_TRUE(std::isfinite(std::stod(r.at("mean_relative"))));
        rmse[r.at("method") + "_" + r.at("setting")] = e;
        // Only multiscale images carry levels to split the error by.
        if (r.at("method") != "multiscale") {
            EXPECT_EQ(r.at("rmse_bough"), "");
        }
    }
    EXPECT_EQ(rmse.at("truth_16spp"), 0.0);
    EXPECT_LT(rmse.at("geometry_4spp"), rmse.at("geometry_1spp"));
    for (const auto& [name, e] : rmse) {
        if (name != "truth_16spp") {
            EXPECT_GT(e, 0.0) << name;
        }
    }
}

TEST_F(Compare, FlickerIsMeasuredForTheThreeMethods)
{
    ASSERT_EQ(status, 0);
    const Table rows = readCsv(dir / "out" / "flicker.csv");
    ASSERT_EQ(rows.size(), 3u);
    for (const auto& r : rows) {
        const double f = std::stod(r.at("flicker"));
        EXPECT_TRUE(std::isfinite(f) && f >= 0.0) << r.at("method");
    }
}

TEST(CompareRun, UnwritableFolderFailsBeforeWork)
{
    CompareOptions options;
    options.sceneFile = "/no/such/scene.json";  // never read: the folder is checked first
    options.outDir = "/proc/pine-cannot-write-here";
    try {
        runCompare(options);
        ADD_FAILURE() << "no InputError";
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("/proc/pine-cannot-write-here"), std::string::npos)
            << e.what();
    }
}

TEST(CompareRun, ParsesResolution)
{
    int w = 0, h = 0;
    EXPECT_TRUE(parseResolution("64x48", w, h));
    EXPECT_EQ(w, 64);
    EXPECT_EQ(h, 48);
    EXPECT_FALSE(parseResolution("64x", w, h));
    EXPECT_FALSE(parseResolution("0x48", w, h));
    EXPECT_FALSE(parseResolution("64x48x2", w, h));
}

Image constantFrame(float value)
{
    Image image(2, 1);
    for (float& v : image.rgba) v = value;
    return image;
}

TEST(Flicker, SteadyAndLinearSequencesScoreZeroAlternatingScoresItsAmplitude)
{
    std::vector<Image> steady, linear, alternating;
    for (int t = 0; t < 8; ++t) {
        steady.push_back(constantFrame(0.5f));
        linear.push_back(constantFrame(0.1f + 0.05f * float(t)));
        alternating.push_back(constantFrame(t % 2 ? 0.6f : 0.4f));
    }
    EXPECT_NEAR(temporalFlicker(steady), 0.0, 1e-7);
    EXPECT_NEAR(temporalFlicker(linear), 0.0, 1e-6);
    // +-0.1 about 0.5, less the small slope an even count of alternations fits.
    EXPECT_NEAR(temporalFlicker(alternating), 0.1, 0.01);
    EXPECT_THROW(temporalFlicker({steady[0], steady[1]}), ImageError);
}

}  // namespace
}  // namespace pine::vdbtrace
