// The "tree" AOV and the per-tree foliage measures (tree_foliage.h): each method names the tree
// its foliage comes from, checked against each tree rendered alone; regions and sums checked
// against direct computation on small images; the sums fragment by fragment
// (tree_foliage_tally.h) against the AOVs, alone and together, and through an EXR header.
#include "pine/vdbtrace/tree_foliage.h"
#include "pine/scenes/scene.h"
#include "pine/vdbtrace/fragment.h"
#include "pine/vdbtrace/geometry_tracer.h"
#include "pine/vdbtrace/methods.h"
#include "pine/vdbtrace/multiscale_tracer.h"
#include "pine/vdbtrace/traced_scene.h"

#include <gtest/gtest.h>
#include <tbb/task_arena.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <numeric>
#include <random>
#include <string>
#include <vector>

namespace pine::vdbtrace {
namespace {

Image withPlanes(int w, int h, const std::vector<float>& tree, const std::vector<float>& foliage)
{
    Image image(w, h);
    image.aov("tree") = tree;
    image.aov("foliage") = foliage;
    return image;
}

TEST(TreeFoliage, RegionsTakeTheNearestNamedPixel)
{
    // 6 x 1: tree 3 at x = 0, tree 1 at x = 4; x = 2 is as near to both: the earlier pixel's.
    const Image row = withPlanes(6, 1, {3, -1, -1, -1, 1, -1}, std::vector<float>(6, 0.0f));
    EXPECT_EQ(treeRegions(row), (std::vector<int>{3, 3, 3, 1, 1, 1}));
    // Nothing named: nothing assigned.
    const Image none = withPlanes(2, 2, {-1, -1, -1, -1}, std::vector<float>(4, 0.0f));
    EXPECT_EQ(treeRegions(none), (std::vector<int>(4, -1)));
    EXPECT_THROW(treeRegions(Image(2, 2)), ImageError);
}

TEST(TreeFoliage, SumsOverEachRegion)
{
    // 3 x 2, regions {0 0 1 / 0 1 1}; luminance of grey g is g.
    Image image = withPlanes(3, 2, {0, 0, 1, 0, 1, 1}, {0.5f, 1.0f, 0.25f, 0.0f, 0.75f, 1.0f});
    const float grey[6] = {0.2f, 0.4f, 0.8f, 0.9f, 0.1f, 0.3f};
    for (int i = 0; i < 6; ++i) {
        for (int c = 0; c < 3; ++c) image.rgba[4 * i + c] = grey[i];
    }
    const std::vector<TreeFoliage> t =
        foliageByTree(image, treeRegions(image), FoliageLuminance::Pixels);
    ASSERT_EQ(t.size(), 2u);
    EXPECT_EQ(t[0].tree, 0);
    EXPECT_EQ(t[0].pixels, 3u);
    EXPECT_NEAR(t[0].coverage, 1.5, 1e-6);
    EXPECT_NEAR(t[0].luminance, (0.2 * 0.5 + 0.4 * 1.0) / 1.5, 1e-6);
    EXPECT_EQ(t[1].pixels, 3u);
    EXPECT_NEAR(t[1].coverage, 2.0, 1e-6);
    EXPECT_NEAR(t[1].luminance, (0.8 * 0.25 + 0.1 * 0.75 + 0.3 * 1.0) / 2.0, 1e-6);
    // Against itself: no bias; one tree darker by half: -50% luminance, same coverage.
    Image darker = image;
    for (int i : {2, 4, 5}) {
        for (int c = 0; c < 3; ++c) darker.rgba[4 * i + c] *= 0.5f;
    }
    const std::vector<TreeBias> b = treeBiases(darker, image, 0.0);
    ASSERT_EQ(b.size(), 2u);
    EXPECT_NEAR(b[0].luminanceBias, 0.0, 1e-9);
    EXPECT_NEAR(b[1].luminanceBias, -0.5, 1e-6);
    EXPECT_NEAR(b[1].coverageBias, 0.0, 1e-9);

    // The foliage's own luminance: its AOV summed over the region, over the coverage summed.
    Image own = image;
    own.aov("foliage_luminance") = {0.1f, 0.3f, 0.05f, 0.0f, 0.2f, 0.4f};
    EXPECT_TRUE(hasOwnFoliageLuminance(own));
    const std::vector<TreeFoliage> o = foliageByTree(own, treeRegions(own));
    EXPECT_NEAR(o[0].luminance, (0.1 + 0.3 + 0.0) / 1.5, 1e-6);
    EXPECT_NEAR(o[1].luminance, (0.05 + 0.2 + 0.4) / 2.0, 1e-6);
    // Measured the pixels' way unless both images have it.
    EXPECT_NEAR(treeBiases(own, image, 0.0)[0].luminanceBias, 0.0, 1e-9);
    EXPECT_THROW(foliageByTree(image, treeRegions(image)), ImageError);
}

// The three firs at low resolution, all of them or only tree `only`: the others moved behind
// the camera, so that every tree keeps its index and its needles. `overlapping`: the middle
// fir moved behind the near one's edge, so that some pixels show both.
scenes::Scene threeFirs(int only = -1, bool overlapping = false)
{
    scenes::Scene s = scenes::loadScene(std::string(PINE_SOURCE_DIR) + "/scenes/three-firs.json");
    s.camera.width = 128;
    s.camera.height = 96;
    if (overlapping) s.trees[1].base_cm.x = -80.0;
    for (std::size_t i = 0; i < s.trees.size(); ++i) {
        if (only >= 0 && int(i) != only) s.trees[i].base_cm.y -= 1e5;
    }
    return s;
}

// Renders `s` with the method `name` (registered), explicit needles at `samples` a pixel, the
// reference's own bake at 1 cm.
RenderResult renderWith(const std::string& name, const scenes::Scene& s, int samples)
{
    const RenderMethod& method = renderMethod(name);
    MethodSettings settings;
    settings.geometry.samples = samples;
    settings.voxelSize_cm = 1.0;
    return method.render(buildTracedScene(s, method.parts), settings, {});
}

TEST(TreeFoliage, EveryMethodNamesTheTreeItsFoliageComesFrom)
{
    // Where only tree i's own render has foliage, the whole scene's "tree" AOV must say i; a
    // pixel no tree covers says -1. Rendered with the multiscale method (every level appears
    // on this scene), explicit needles and the reference's voxels.
    for (const char* name : {"multiscale", "geometry", "reference"}) {
        const auto render = [&](const scenes::Scene& s) { return renderWith(name, s, 1); };
        const scenes::Scene all = threeFirs();
        const RenderResult whole = render(all);
        std::vector<std::vector<float>> alone;
        for (int i = 0; i < 3; ++i) alone.push_back(render(threeFirs(i)).image.aovs.at("foliage"));
        const std::vector<float>& tree = whole.image.aovs.at("tree");
        int checked = 0, empty = 0;
        for (std::size_t p = 0; p < tree.size(); ++p) {
            int only = -1, covering = 0;
            for (int i = 0; i < 3; ++i) {
                if (alone[std::size_t(i)][p] > 0.0f) {
                    only = i;
                    ++covering;
                }
            }
            if (covering == 0) {
                EXPECT_EQ(tree[p], -1.0f) << "pixel " << p;
                ++empty;
            } else if (covering == 1 && whole.image.aovs.at("foliage")[p] > 0.0f) {
                EXPECT_EQ(tree[p], float(only)) << "pixel " << p << ' ' << name;
                ++checked;
            }
        }
        EXPECT_GT(checked, 1000);
        EXPECT_GT(empty, 1000);
    }
}

TEST(TreeFoliage, TheFoliagesOwnLuminanceIsWhatFoliageFragmentsGive)
{
    // A branch half covering the footprint, then a needle fragment, then the ground: the
    // foliage gave what the needles reflect through the branch's gap, nothing of the others.
    FrontToBack c;
    c.add(Fragment{1.0, 0.5, Vec3(0.2), Vec3(0.0), 0, false, -1});
    c.add(Fragment{2.0, 0.4, Vec3(0.1, 0.2, 0.3), Vec3(0.04), 3, true, 0});
    c.add(Fragment{3.0, 1.0, Vec3(0.7), Vec3(0.0), 0, false, -1});
    const SampleValue v = c.value();
    EXPECT_NEAR(v.foliage, 0.5 * 0.4, 1e-12);
    EXPECT_NEAR(v.foliageLuminance, 0.5 * luminance(Vec3(0.14, 0.24, 0.34)), 1e-12);
}

TEST(TreeFoliage, TheFoliagesOwnLuminanceDoesNotSeeWhatLiesBehind)
{
    // The three firs with a white sky and ground, then black: each tree's own luminance is
    // unchanged (to float rounding), for explicit needles and the multiscale method alike,
    // where the pixels' measure moves with the backdrop wherever foliage covers a pixel in
    // part.
    for (const bool geometry : {false, true}) {
        std::vector<TreeFoliage> own[2], pixels[2];
        for (int dark = 0; dark < 2; ++dark) {
            scenes::Scene s = threeFirs();
            s.render.background = Vec3(dark ? 0.0 : 1.0);
            s.ground.albedo = Vec3(dark ? 0.0 : 1.0);
            const TracedScene t = buildTracedScene(s);
            GeometryOptions g;
            g.samples = 4;
            const Image image = geometry ? renderGeometry(t, g).image : renderMultiscale(t).image;
            const std::vector<int> regions = treeRegions(image);
            own[dark] = foliageByTree(image, regions, FoliageLuminance::Own);
            pixels[dark] = foliageByTree(image, regions, FoliageLuminance::Pixels);
        }
        ASSERT_EQ(own[0].size(), 3u);
        for (std::size_t k = 0; k < 3; ++k) {
            std::printf("%s tree %zu: own luminance %.5f / %.5f, the pixels' %.5f / %.5f (white "
                        "/ black backdrop)\n",
                        geometry ? "geometry" : "multiscale", k, own[0][k].luminance,
                        own[1][k].luminance, pixels[0][k].luminance, pixels[1][k].luminance);
            EXPECT_NEAR(own[0][k].luminance / own[1][k].luminance, 1.0, 1e-5);
            EXPECT_GT(pixels[0][k].luminance / pixels[1][k].luminance, 1.02);
        }
    }
}

TEST(TreeFoliage, ATreesSumsAreItsFragmentsWhereverItsPixelsLie)
{
    // Rendered alone, a tree's sums are the foliage AOVs' sums over the image (every foliage
    // fragment is its). Among the others (two overlapping in the image), the pixels only its
    // own render covers are wholly its (a lower bound of its coverage) and those its own render
    // covers hold all of it (an upper bound); the trees' sums add up to the AOVs' whatever tree
    // a pixel names; and a tree of black needles has no luminance, in the pixels it shares too.
    for (const char* name : {"multiscale", "geometry", "reference"}) {
        const auto render = [&](const scenes::Scene& s) { return renderWith(name, s, 4); };
        const auto sum = [](const std::vector<float>& v) {
            return std::accumulate(v.begin(), v.end(), 0.0);
        };
        const RenderResult whole = render(threeFirs(-1, true));
        const std::vector<float>& foliage = whole.image.aovs.at("foliage");
        ASSERT_EQ(whole.treeFoliage.size(), 3u) << name;
        double coverage = 0.0, luminance = 0.0;
        for (const TreeFoliageSum& t : whole.treeFoliage) {
            coverage += t.coverage_px;
            luminance += t.luminance;
        }
        EXPECT_NEAR(coverage / sum(foliage), 1.0, 1e-5) << name;
        EXPECT_NEAR(luminance / sum(whole.image.aovs.at("foliage_luminance")), 1.0, 1e-5) << name;
        std::vector<std::vector<float>> alone;
        for (int i = 0; i < 3; ++i) {
            const RenderResult r = render(threeFirs(i, true));
            ASSERT_EQ(r.treeFoliage.size(), 1u) << name;
            EXPECT_EQ(r.treeFoliage[0].tree, i);
            EXPECT_NEAR(r.treeFoliage[0].coverage_px / sum(r.image.aovs.at("foliage")), 1.0, 1e-5);
            EXPECT_NEAR(r.treeFoliage[0].luminance / sum(r.image.aovs.at("foliage_luminance")),
                        1.0, 1e-5);
            alone.push_back(r.image.aovs.at("foliage"));
        }
        for (int i = 0; i < 3; ++i) {
            double only = 0.0, within = 0.0;
            for (std::size_t p = 0; p < foliage.size(); ++p) {
                int covering = 0;
                for (const std::vector<float>& a : alone) covering += a[p] > 0.0f;
                if (alone[std::size_t(i)][p] > 0.0f) {
                    within += foliage[p];
                    if (covering == 1) only += foliage[p];
                }
            }
            const double own = whole.treeFoliage[std::size_t(i)].coverage_px;
            std::printf("%s tree %d: %.2f px of foliage; its pixels alone %.2f, all it covers "
                        "%.2f\n", name, i, own, only, within);
            EXPECT_GE(own, only * (1.0 - 1e-5)) << name << " tree " << i;
            EXPECT_LE(own, within * (1.0 + 1e-5)) << name << " tree " << i;
        }
        // The bounds must differ where the firs overlap, or they test nothing.
        double shared = 0.0;
        for (std::size_t p = 0; p < foliage.size(); ++p) {
            shared += alone[0][p] > 0.0f && alone[1][p] > 0.0f ? foliage[p] : 0.0f;
        }
        EXPECT_GT(shared, 10.0) << name << ": the firs barely overlap";

        // The middle fir's needles black: all the luminance, shared pixels too, is the near
        // fir's and the far one's, none of it the middle one's.
        scenes::Scene dark = threeFirs(-1, true);
        dark.species["dark"] = dark.species.at(dark.trees[1].species);
        dark.species["dark"].needleAlbedo = dark.species["dark"].needleSpecular = 0.0;
        dark.trees[1].species = "dark";
        const RenderResult d = render(dark);
        ASSERT_EQ(d.treeFoliage.size(), 3u);
        EXPECT_EQ(d.treeFoliage[1].luminance, 0.0) << name;
        EXPECT_NEAR((d.treeFoliage[0].luminance + d.treeFoliage[2].luminance) /
                        sum(d.image.aovs.at("foliage_luminance")),
                    1.0, 1e-5)
            << name;
    }
}

TEST(TreeFoliage, ATreesSumsDoNotDependOnThreads)
{
    const TracedScene t = buildTracedScene(threeFirs());
    std::vector<TreeFoliageSum> sums[2];
    for (const int threads : {1, 2}) {
        tbb::task_arena arena(threads);
        arena.execute([&] { sums[threads - 1] = renderMultiscale(t).treeFoliage; });
    }
    ASSERT_EQ(sums[0].size(), 3u);
    EXPECT_EQ(sums[0], sums[1]);
}

TEST(TreeFoliage, BiasesFromTheSumsOfTwoRenders)
{
    // Tree 0: 10% more coverage at half the luminance; tree 1: under the truth's 20 pixels,
    // left out; tree 2: not in the image; tree 3: only in the image, not judged.
    const std::vector<TreeFoliageSum> image{{0, 110.0, 27.5}, {3, 40.0, 4.0}};
    const std::vector<TreeFoliageSum> truth{{0, 100.0, 50.0}, {1, 19.0, 5.0}, {2, 50.0, 10.0}};
    const std::vector<TreeBias> b = treeBiases(image, truth);
    ASSERT_EQ(b.size(), 2u);
    EXPECT_EQ(b[0].truth.tree, 0);
    EXPECT_NEAR(b[0].coverageBias, 0.1, 1e-12);
    EXPECT_NEAR(b[0].luminanceBias, 27.5 / 110.0 / 0.5 - 1.0, 1e-12);
    EXPECT_NEAR(b[0].image.luminance, 0.25, 1e-12);
    EXPECT_EQ(b[1].truth.tree, 2);
    EXPECT_EQ(b[1].coverageBias, -1.0);
    EXPECT_EQ(b[1].luminanceBias, -1.0);
    EXPECT_EQ(treeBiases(image, truth, 0.0).size(), 3u);
}

TEST(TreeFoliage, ABlackTreeInTheTruthHasNoLuminanceBias)
{
    // Tree 0 is black in the truth (in deep shadow, no sky): any luminance of the image's is
    // no ratio of it, so the bias is undefined, not 0%. Its coverage bias still stands, and
    // the summary's luminance spread is over the trees where it is defined.
    const std::vector<TreeFoliageSum> image{{0, 100.0, 30.0}, {1, 100.0, 45.0}};
    const std::vector<TreeFoliageSum> truth{{0, 100.0, 0.0}, {1, 100.0, 50.0}};
    const std::vector<TreeBias> b = treeBiases(image, truth);
    ASSERT_EQ(b.size(), 2u);
    EXPECT_TRUE(std::isnan(b[0].luminanceBias));
    EXPECT_EQ(b[0].coverageBias, 0.0);
    EXPECT_NEAR(b[1].luminanceBias, -0.1, 1e-12);
    const TreeBiasSummary s = summarizeTreeBiases(b);
    EXPECT_EQ(s.trees, 2u);
    EXPECT_EQ(s.luminance.defined, 1u);
    EXPECT_NEAR(s.luminance.median, -0.1, 1e-12);
    EXPECT_NEAR(s.luminance.worst, -0.1, 1e-12);
    EXPECT_EQ(s.luminance.worstTree, 1);
    EXPECT_EQ(s.luminance.beyond, 1u);
    EXPECT_EQ(s.coverage.defined, 2u);
    // Only black trees: no median or worst to state.
    const TreeBiasSummary none = summarizeTreeBiases({b[0]});
    EXPECT_EQ(none.luminance.defined, 0u);
    EXPECT_TRUE(std::isnan(none.luminance.median));
    EXPECT_TRUE(std::isnan(none.luminance.worst));
    EXPECT_EQ(none.luminance.worstTree, -1);
}

TEST(TreeFoliage, SumsRoundTripThroughAnExrHeader)
{
    // Ten thousand trees (a landscape's), random sums: back bit for bit.
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> u(0.0, 1e4);
    std::vector<TreeFoliageSum> sums;
    for (int i = 0; i < 10000; ++i) sums.push_back({3 * i + 1, u(rng), u(rng) * 1e-3});
    const std::filesystem::path path = std::filesystem::temp_directory_path() /
                                       ("pine-tree-foliage-" +
                                        std::to_string(std::random_device{}()) + ".exr");
    writeExr(Image(2, 2), path, {{kTreeFoliageAttribute, treeFoliageText(sums)}});
    Metadata header;
    readExr(path, &header);
    std::filesystem::remove(path);
    const auto back = treeFoliageOf(header, path.string());
    ASSERT_TRUE(back.has_value());
    EXPECT_EQ(*back, sums);
    EXPECT_FALSE(treeFoliageOf(Metadata{{"pine:method", std::string("multiscale")}}, "x"));

    for (const char* bad : {"{", "{}", "[[1, 2]]", "[[-1, 2, 3]]", "[[2, 1, 1], [1, 1, 1]]",
                            "[[1, -2, 3]]", "[[1.5, 2, 3]]", "[[1, \"a\", 3]]",
                            "[[4294967297, 1, 1]]"}) {
        EXPECT_THROW(parseTreeFoliage(bad, "image.exr"), ImageError) << bad;
    }
    EXPECT_THROW(treeFoliageOf(Metadata{{kTreeFoliageAttribute, 3}}, "x"), ImageError);
}

TEST(TreeFoliage, SumsAreReadInThePixelsOfTheImageThatCarriesThem)
{
    // Summed at 1280 x 960, the image box-filtered to 320 x 240 (as scripts/forest_levels.sh
    // does): a pixel of it holds 16 of the frame's.
    const std::vector<TreeFoliageSum> sums{{0, 1600.0, 480.0}, {3, 32.0, 8.0}};
    const Metadata header{{kTreeFoliageAttribute, treeFoliageText(sums)},
                          {kTreeFoliageFrameAttribute, frameText(1280, 960)}};
    const Image small(320, 240);
    const auto scaled = treeFoliageOf(header, "fine.exr", &small);
    ASSERT_TRUE(scaled.has_value());
    ASSERT_EQ(scaled->size(), sums.size());
    for (std::size_t i = 0; i < sums.size(); ++i) {
        EXPECT_EQ((*scaled)[i].tree, sums[i].tree);
        EXPECT_DOUBLE_EQ((*scaled)[i].coverage_px, sums[i].coverage_px / 16.0);
        // The mean luminance, what a tree's bias compares, is unchanged.
        EXPECT_DOUBLE_EQ((*scaled)[i].luminance / (*scaled)[i].coverage_px,
                         sums[i].luminance / sums[i].coverage_px);
    }
    // The frame it was rendered in, a crop of it, or no image: as summed.
    Image crop(100, 50);
    crop.frameWidth = 1280;
    crop.frameHeight = 960;
    EXPECT_EQ(*treeFoliageOf(header, "crop.exr", &crop), sums);
    const Image whole(1280, 960);
    EXPECT_EQ(*treeFoliageOf(header, "fine.exr", &whole), sums);
    EXPECT_EQ(*treeFoliageOf(header, "fine.exr"), sums);
    // Without the frame (files written before it): as summed.
    EXPECT_EQ(*treeFoliageOf(Metadata{header[0]}, "old.exr", &small), sums);
    for (const char* bad :
         {"1280", "1280x", "x960", "0x960", "1280x960x", "1280 x 960", "-1x5", "01280x960"}) {
        const Metadata damaged{header[0], {kTreeFoliageFrameAttribute, std::string(bad)}};
        try {
            treeFoliageOf(damaged, "bad.exr", &small);
            ADD_FAILURE() << bad << " was read as a frame";
        } catch (const ImageError& e) {
            EXPECT_NE(std::string(e.what()).find("bad.exr"), std::string::npos) << e.what();
            EXPECT_NE(std::string(e.what()).find(kTreeFoliageFrameAttribute), std::string::npos);
        }
    }
    EXPECT_THROW(treeFoliageOf(Metadata{header[0], {kTreeFoliageFrameAttribute, 3}}, "x", &small),
                 ImageError);
}

TEST(TreeFoliage, ASummaryHasTheMedianTheWorstWithItsSignAndTheTreesBeyond)
{
    const auto bias = [](int tree, double luminance, double coverage) {
        TreeBias b;
        b.truth.tree = tree;
        b.luminanceBias = luminance;
        b.coverageBias = coverage;
        return b;
    };
    // Luminance: sorted -0.12, -0.02, 0.01, 0.05: median -0.005, worst tree 7's -0.12, two
    // beyond 3%. Coverage: sorted -0.04, 0, 0.02, 0.08: median 0.01, worst tree 4's +0.08.
    std::vector<TreeBias> biases = {bias(4, 0.05, 0.08), bias(7, -0.12, 0.0),
                                    bias(9, 0.01, -0.04), bias(2, -0.02, 0.02)};
    TreeBiasSummary s = summarizeTreeBiases(biases);
    EXPECT_EQ(s.trees, 4u);
    EXPECT_DOUBLE_EQ(s.luminance.median, -0.005);
    EXPECT_DOUBLE_EQ(s.luminance.worst, -0.12);
    EXPECT_EQ(s.luminance.worstTree, 7);
    EXPECT_EQ(s.luminance.beyond, 2u);
    EXPECT_DOUBLE_EQ(s.coverage.median, 0.01);
    EXPECT_DOUBLE_EQ(s.coverage.worst, 0.08);
    EXPECT_EQ(s.coverage.worstTree, 4);
    EXPECT_EQ(s.coverage.beyond, 2u);
    // An odd count: the middle one; a threshold of 10%: one tree beyond.
    biases.pop_back();
    s = summarizeTreeBiases(biases, 0.1);
    EXPECT_DOUBLE_EQ(s.luminance.median, 0.01);
    EXPECT_EQ(s.luminance.beyond, 1u);
    s = summarizeTreeBiases({});
    EXPECT_EQ(s.trees, 0u);
    EXPECT_EQ(s.luminance.worstTree, -1);
}

}  // namespace
}  // namespace pine::vdbtrace
