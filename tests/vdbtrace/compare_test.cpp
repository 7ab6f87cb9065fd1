// `vdbtrace compare` on a tiny fir with the quick settings: every method and setting has its
// row, image and error map, errors behave (finite, zero for the truth itself, falling with the
// samples), the report's errors at every scale and per-tree biases are what the EXRs it wrote
// give, and the dolly's flicker is measured for the three methods.
#include "pine/vdbtrace/compare.h"
#include "pine/vdbtrace/compare_report.h"
#include "pine/vdbtrace/dolly.h"
#include "pine/vdbtrace/error_budget.h"
#include "pine/vdbtrace/flicker.h"
#include "pine/vdbtrace/image.h"
#include "pine/vdbtrace/integer_list.h"
#include "pine/vdbtrace/methods.h"
#include "pine/vdbtrace/traced_scene.h"

#include <nlohmann/json.hpp>

#include "test_scenes.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>
#include <tuple>
#include <utility>
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
        EXPECT_EQ(cells.size(), header.size()) << path << ": " << line;
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
        options.settings.repeat = 3;  // the median of three runs and its spread are reported
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
    for (const auto& r : rows) {
        // The error budget's rows: TheErrorBudgetHasEachSwitchsRender.
        if (r.at("method").rfind("budget:", 0) != 0) {
            names.push_back(r.at("method") + "_" + r.at("setting"));
        }
    }
    std::vector<std::string> expected = {"truth_16spp",   "geometry_1spp",   "geometry_4spp",
                                         "reference_1cm", "reference_0.5cm", "multiscale_L1",
                                         "multiscale_L2", "multiscale_L3",   "multiscale_auto"};
    // Last, the truth against 4 times its samples: a number, not an image.
    expected.push_back("truth_check_64spp");
    EXPECT_EQ(names, expected);
    expected.pop_back();
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
        if (r.at("method") == "truth_check") continue;  // checked below
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

TEST(Dolly, FramesKeepTheScenesShape)
{
    // 16 x 12 halved is 8 x 6: its short side raised to 8 keeps the shape (11 x 8), where the
    // frames were made 8 x 8 and saw a wider view than the scene's.
    CompareSettings settings = CompareSettings::forQuick(true);
    settings.frames = 3;  // the fewest flicker is measured over
    for (const auto& [w, h, fw, fh] : {std::tuple{16, 12, 11, 8},
                                       {48, 36, 24, 18},
                                       {49, 37, 24, 18},
                                       {8, 6, 8, 6},
                                       {1, 1, 1, 1}}) {
        const scenes::Scene scene =
            scenes::parseScene(test::firScene(R"("diffuse")", w, h), "fir.json");
        const DollyFlicker d = measureDollyFlicker(scene, settings, {});
        EXPECT_EQ(d.width, fw) << w << "x" << h;
        EXPECT_EQ(d.height, fh) << w << "x" << h;
        EXPECT_EQ(d.rows.size(), 3u);
    }
}

// Independent of compareImages: both images' RGB box-downsampled first, luminance after.
struct BlockErrors {
    double rmse = 0.0, mae = 0.0;
};
BlockErrors downsampledErrors(const Image& a, const Image& b, int k)
{
    const int bw = a.width / k, bh = a.height / k;
    double sq = 0.0, abs = 0.0;
    for (int by = 0; by < bh; ++by) {
        for (int bx = 0; bx < bw; ++bx) {
            double d = 0.0;
            for (int y = by * k; y < by * k + k; ++y) {
                for (int x = bx * k; x < bx * k + k; ++x) {
                    const double w[3] = {0.2126, 0.7152, 0.0722};
                    for (int c = 0; c < 3; ++c) d += w[c] * (a.pixel(x, y)[c] - b.pixel(x, y)[c]);
                }
            }
            d /= double(k * k);
            sq += d * d;
            abs += std::abs(d);
        }
    }
    return {std::sqrt(sq / (bw * bh)), abs / (bw * bh)};
}

// [tree, coverage_px, luminance] per tree, as the EXR header carries them, read here as JSON.
std::map<int, std::pair<double, double>> treeSums(const Metadata& header)
{
    std::map<int, std::pair<double, double>> out;
    for (const auto& [key, value] : header) {
        if (key != "pine:tree_foliage") continue;
        for (const auto& t : nlohmann::json::parse(std::get<std::string>(value))) {
            out[t[0].get<int>()] = {t[1].get<double>(), t[2].get<double>()};
        }
    }
    return out;
}

TEST_F(Compare, ReportNumbersAreWhatTheWrittenImagesGive)
{
    ASSERT_EQ(status, 0);
    const fs::path out = dir / "out";
    const Table rows = readCsv(out / "report.csv");
    Metadata truthHeader;
    const Image truth = readExr(out / "truth_16spp.exr", &truthHeader);
    const auto truthTrees = treeSums(truthHeader);
    ASSERT_FALSE(truthTrees.empty()) << "the truth's EXR carries no tree sums";
    const auto close = [](double got, double want) {
        return std::abs(got - want) <= 1e-6 * std::abs(want) + 1e-12;
    };
    int checkedTrees = 0;
    bool sawCheck = false;
    for (const auto& r : rows) {
        const std::string name = r.at("method") + "_" + r.at("setting");
        if (r.at("method") == "truth_check") {
            sawCheck = true;
            EXPECT_GT(std::stod(r.at("rmse_k1")), 0.0);
            continue;
        }
        if (r.at("method") == "truth" || r.at("method").rfind("budget:", 0) == 0) continue;
        EXPECT_LE(std::stod(r.at("seconds_min")), std::stod(r.at("seconds"))) << name;
        EXPECT_LE(std::stod(r.at("seconds")), std::stod(r.at("seconds_max"))) << name;
        Metadata header;
        const Image image = readExr(out / (name + ".exr"), &header);
        for (const int k : {1, 2, 4, 8, 16}) {
            const std::string rmse = r.at("rmse_k" + std::to_string(k));
            if (image.width / k < 1 || image.height / k < 1) {
                EXPECT_EQ(rmse, "") << name << " k " << k;
                continue;
            }
            const BlockErrors e = downsampledErrors(image, truth, k);
            EXPECT_TRUE(close(std::stod(rmse), e.rmse))
                << name << " k " << k << ": " << rmse << " against " << e.rmse;
            EXPECT_TRUE(close(std::stod(r.at("mae_k" + std::to_string(k))), e.mae))
                << name << " k " << k;
        }
        EXPECT_TRUE(close(std::stod(r.at("rmse")), downsampledErrors(image, truth, 1).rmse));
        // Per tree: coverage and mean luminance against the truth's, trees of >= 20 pixels.
        const auto trees = treeSums(header);
        ASSERT_FALSE(trees.empty()) << name << ": every method's image carries its trees' sums";
        std::vector<double> luminance, coverage;
        double cov = 0, lum = 0, covTruth = 0, lumTruth = 0;
        for (const auto& [tree, sums] : truthTrees) {
            covTruth += sums.first;
            lumTruth += sums.second;
            if (sums.first < 20.0) continue;
            const auto it = trees.find(tree);
            const double c = it == trees.end() ? 0.0 : it->second.first;
            const double l = it == trees.end() || c <= 0.0 ? 0.0 : it->second.second / c;
            coverage.push_back(c / sums.first - 1.0);
            luminance.push_back(l / (sums.second / sums.first) - 1.0);
        }
        for (const auto& [tree, sums] : trees) {
            cov += sums.first;
            lum += sums.second;
        }
        const auto median = [](std::vector<double> v) {
            std::sort(v.begin(), v.end());
            const std::size_t n = v.size();
            return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
        };
        ASSERT_FALSE(luminance.empty()) << name;
        EXPECT_EQ(std::stoul(r.at("trees")), luminance.size()) << name;
        for (const auto& [which, biases] :
             {std::pair{"luminance", luminance}, std::pair{"coverage", coverage}}) {
            const double worst =
                *std::max_element(biases.begin(), biases.end(),
                                  [](double x, double y) { return std::abs(x) < std::abs(y); });
            const long beyond = std::count_if(biases.begin(), biases.end(),
                                              [](double b) { return std::abs(b) > 0.03; });
            EXPECT_TRUE(close(std::stod(r.at(std::string("tree_") + which + "_worst")), worst))
                << name << " " << which;
            EXPECT_EQ(std::stol(r.at(std::string("trees_") + which + "_beyond_3pct")), beyond)
                << name << " " << which;
        }
        EXPECT_TRUE(close(std::stod(r.at("tree_luminance_median")), median(luminance))) << name;
        EXPECT_TRUE(close(std::stod(r.at("tree_coverage_median")), median(coverage))) << name;
        EXPECT_TRUE(close(std::stod(r.at("foliage_coverage_bias")), cov / covTruth - 1.0)) << name;
        EXPECT_TRUE(close(std::stod(r.at("foliage_luminance_bias")),
                          (lum / cov) / (lumTruth / covTruth) - 1.0))
            << name;
        ++checkedTrees;
    }
    EXPECT_TRUE(sawCheck) << "no truth_check row";
    EXPECT_GE(checkedTrees, 8) << "geometry, multiscale and reference rows all carry their trees";
}

TEST_F(Compare, TheErrorBudgetHasEachSwitchsRender)
{
    ASSERT_EQ(status, 0);
    const fs::path out = dir / "out";
    const Table rows = readCsv(out / "report.csv");
    std::vector<std::string> budget;
    std::map<std::string, double> rmse;
    for (const auto& r : rows) {
        if (r.at("method").rfind("budget:", 0) != 0) continue;
        budget.push_back(r.at("method") + " " + r.at("setting"));
        rmse[r.at("setting")] = std::stod(r.at("rmse"));
    }
    scenes::Scene scene = scenes::parseScene(kFirScene, "fir.json");
    std::vector<std::string> expected;
    for (const BudgetSwitch& s : errorBudgetSwitches(scene.render.model)) {
        expected.push_back("budget:" + s.method + " " + s.label);
    }
    EXPECT_EQ(budget, expected);
    // One switch rendered here on its own (bark "line" at every level, as compare's
    // multiscale auto), measured against the truth compare wrote.
    scene.render.model.bark = "line";
    const TracedScene traced = buildTracedScene(scene);
    const RenderResult r = renderMethod("multiscale").render(traced, MethodSettings{}, {});
    const Image truth = readExr(out / "truth_16spp.exr");
    const double want = downsampledErrors(r.image, truth, 1).rmse;
    EXPECT_NEAR(rmse.at("bark=line"), want, 1e-6 * want);
    EXPECT_GT(std::abs(rmse.at("bark=line") - rmse.at("bough_law=linear")), 1e-6)
        << "two switches rendered the same image";
}

TEST(ErrorBudget, EachSwitchMovesOneChoiceAndThePresetMovesAll)
{
    using scenes::ModelChoices;
    const ModelChoices faithful = ModelChoices::faithful(), paper = ModelChoices::paper();
    const auto differences = [](const ModelChoices& a, const ModelChoices& b) {
        return int(a.boughLaw != b.boughLaw) + int(a.layerModel != b.layerModel) +
               int(a.extinctionLaw != b.extinctionLaw) + int(a.shadowOrigin != b.shadowOrigin) +
               int(a.levelBlend != b.levelBlend) + int(a.bark != b.bark) +
               int(a.coneLevelMax != b.coneLevelMax) +
               int(a.layerCorrelation != b.layerCorrelation) + int(a.pixelSplitQ != b.pixelSplitQ) +
               int(a.occluderProfile != b.occluderProfile);
    };
    const std::vector<BudgetSwitch> switches = errorBudgetSwitches(faithful);
    ASSERT_FALSE(switches.empty());
    int paperOnes = 0;
    for (const BudgetSwitch& s : switches) {
        if (s.label == "preset=paper") {
            // Every multiscale choice the paper's; the reference's law left as the scene's.
            ModelChoices expected = paper;
            expected.extinctionLaw = faithful.extinctionLaw;
            EXPECT_EQ(differences(s.model, expected), 0);
            continue;
        }
        EXPECT_EQ(differences(s.model, faithful), 1) << s.label;
        EXPECT_EQ(s.method, s.label.rfind("extinction_law", 0) == 0 ? "reference" : "multiscale")
            << s.label;
        // The paper's mark is right: the switched choice equals the paper's.
        EXPECT_EQ(s.paper, differences(s.model, paper) == differences(faithful, paper) - 1)
            << s.label;
        paperOnes += s.paper;
    }
    // Every choice where the presets differ has its paper's switch (cone_level_max does not
    // differ); the alternatives beyond the paper's too (bough_law corrected, shadow_origin bough,
    // extinction_law poisson).
    EXPECT_EQ(paperOnes, differences(faithful, paper));
    EXPECT_EQ(switches.back().label, "preset=paper");
    for (const char* other :
         {"bough_law=corrected", "shadow_origin=bough", "extinction_law=poisson"}) {
        EXPECT_TRUE(std::any_of(switches.begin(), switches.end(), [&](const BudgetSwitch& s) {
            return s.label == other;
        })) << other;
    }
    // From the paper's choices: the faithful ones are the alternatives, no preset row.
    for (const BudgetSwitch& s : errorBudgetSwitches(paper)) {
        EXPECT_NE(s.label, "preset=paper");
        EXPECT_FALSE(s.paper) << s.label;
        EXPECT_EQ(differences(s.model, paper), 1) << s.label;
    }
}

TEST(CompareRun, EffectsTheMethodsCannotShareAreRefused)
{
    scenes::Effects effects;
    effects.shadows = true;
    try {
        checkEffects(effects);
        ADD_FAILURE() << "shadows without self_shadowing were accepted";
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("self_shadowing"), std::string::npos) << e.what();
    }
    effects.shadows = false;
    effects.selfShadowing = true;
    EXPECT_THROW(checkEffects(effects), InputError);
    effects.shadows = true;
    EXPECT_NO_THROW(checkEffects(effects));
    effects.shadows = effects.selfShadowing = false;
    EXPECT_NO_THROW(checkEffects(effects));
}

// A comparison of a few settings, each run once, against a 4 spp truth with no check of it,
// no budget and no reference.
CompareSettings fewSettings(std::vector<int> geometrySamples, std::vector<int> levels)
{
    CompareSettings st;
    st.truthSamples = 4;
    st.truthCheckFactor = 0;
    st.repeat = 1;
    st.budget = false;
    st.geometrySamples = std::move(geometrySamples);
    st.voxelSizes_cm = {};
    st.levels = std::move(levels);
    return st;
}

// A setting's runs are spread over the comparison: round by round, every setting once a round,
// in the report's order, the truth once first. Back to back, each setting would be timed in
// one stretch of a shared machine whose speed drifts, and their ratios would drift with it.
TEST(CompareRun, EverySettingRunsOnceARoundInTheReportsOrder)
{
    const scenes::Scene scene = scenes::parseScene(kFirScene, "fir.json");
    CompareSettings st = fewSettings({1, 2}, {2, 0});
    st.repeat = 3;
    std::vector<std::string> runs, rows;
    const CompareRun run = runComparison(scene, st, [&](const std::string& line) {
        if (line.find(" CPU-s") == std::string::npos) return;  // the scene's build, say
        (line.rfind("run ", 0) == 0 ? runs : rows).push_back(line.substr(0, line.find(':')));
    });
    const std::vector<std::string> settings = {"geometry 1spp", "geometry 2spp", "multiscale L2",
                                               "multiscale auto"};
    std::vector<std::string> expected;
    for (int round = 1; round <= 3; ++round) {
        for (const std::string& setting : settings) {
            expected.push_back("run " + std::to_string(round) + "/3 " + setting);
        }
    }
    EXPECT_EQ(runs, expected);
    // Each row once, after every run, with the median of its three.
    std::vector<std::string> expectedRows = {"truth 4spp"};
    expectedRows.insert(expectedRows.end(), settings.begin(), settings.end());
    EXPECT_EQ(rows, expectedRows);
    ASSERT_EQ(run.rows.size(), expectedRows.size());
    EXPECT_EQ(run.rows.front().runs, 1);
    for (std::size_t i = 1; i < run.rows.size(); ++i) {
        const CompareRow& r = run.rows[i];
        EXPECT_EQ(r.runs, 3) << r.stem();
        EXPECT_LE(r.secondsMin, r.seconds) << r.stem();
        EXPECT_LE(r.seconds, r.secondsMax) << r.stem();
        EXPECT_EQ(r.image.width, 48) << r.stem();  // the first run's image, kept
    }
}

TEST(CompareRun, ABlackTruthHasNoLuminanceBiasInAnyReport)
{
    // A fir whose needles and bark reflect nothing: its luminance biases are undefined, so
    // the reports leave them out ('-', empty cells) where they read 0% or nan, while its
    // coverage biases stand.
    std::string black = kFirScene;
    for (const std::string key :
         {"\"bark_albedo\": 0.25", "\"needle_albedo\": 0.3", "\"needle_specular\": 0.2"}) {
        const std::size_t at = black.find(key);
        ASSERT_NE(at, std::string::npos) << key;
        black.replace(at, key.size(), key.substr(0, key.find(':')) + ": 0");
    }
    const scenes::Scene scene = scenes::parseScene(black, "fir.json");
    const CompareSettings st = fewSettings({1}, {0});
    const CompareRun run = runComparison(scene, st, {});
    // "nan" as a number prints it, not inside a word ("luminance").
    const auto printsNan = [](const std::string& text) {
        for (std::size_t at = text.find("nan"); at != std::string::npos;
             at = text.find("nan", at + 1)) {
            if (at == 0 || !std::isalpha(static_cast<unsigned char>(text[at - 1]))) return true;
        }
        return false;
    };
    const CompareRow& ms = run.rows.back();
    ASSERT_EQ(ms.method, "multiscale");
    ASSERT_GT(ms.trees.trees, 0u);
    EXPECT_EQ(ms.trees.luminance.defined, 0u);
    EXPECT_EQ(ms.trees.coverage.defined, ms.trees.trees);
    EXPECT_TRUE(ms.foliageCoverageBias.has_value());
    EXPECT_FALSE(ms.foliageLuminanceBias.has_value());
    for (const std::string& text : {reportCsv(run), treesCsv(run)}) {
        EXPECT_FALSE(printsNan(text)) << text;
        EXPECT_EQ(text.find(",-1,"), std::string::npos) << "no worst tree: " << text;
    }
    const std::string md = reportMd(run, scene, ReportInfo{});
    EXPECT_FALSE(printsNan(md)) << md;
    EXPECT_EQ(md.find("(knows no trees)"), std::string::npos) << md;
    EXPECT_NE(md.find("luminance undefined (black in the truth)"), std::string::npos) << md;
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
    // Past an int, each side: sscanf's %d read these as 32 x 24 (modulo 2^32).
    for (const char* wrapped : {"4294967328x24", "-4294967264x24", "32x4294967320"}) {
        EXPECT_FALSE(parseResolution(wrapped, w, h)) << wrapped;
    }
    EXPECT_FALSE(parseResolution(" 64x48", w, h));
    EXPECT_FALSE(parseResolution("64x+48", w, h));
    EXPECT_EQ(w, 64);  // untouched by what was refused
    int crop[4] = {};
    EXPECT_TRUE(parseIntegers("0,-1,16384,2147483647", ',', crop));
    EXPECT_EQ(crop[1], -1);
    EXPECT_EQ(crop[3], 2147483647);
    EXPECT_FALSE(parseIntegers("0,0,4294967300,24", ',', crop));
    EXPECT_FALSE(parseIntegers("0,0,2147483648,24", ',', crop));
    EXPECT_FALSE(parseIntegers("0,0,4,4,", ',', crop));
    EXPECT_FALSE(parseIntegers("0,0,4", ',', crop));
    EXPECT_FALSE(parseIntegers("0,,4,4", ',', crop));
    EXPECT_FALSE(parseIntegers("0,-1,4,4", ',', crop, /*negative=*/false));
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
