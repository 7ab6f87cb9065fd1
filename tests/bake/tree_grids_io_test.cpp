// Writing and reading baked grids: round trip, what third-party tools see (vdb_print,
// vdb_render, OpenVDB's own reader), and files we must refuse before OpenVDB parses them.
#include "pine/bake/extinction_law.h"
#include "pine/bake/tree_grids.h"
#include "pine/support/atomic_file.h"

#include "test_support.h"

#include <gtest/gtest.h>
#include <openvdb/io/Stream.h>

#include <algorithm>
#include <iostream>
#include <random>
#include <cstdlib>
#include <iterator>
#include <fstream>
#include <iterator>
#include <sstream>

namespace pine::bake {
namespace {

namespace fs = std::filesystem;

/// Two boughs crossing near the origin, along x and y, at the paper's parameters.
TreeGrids twoBoughs(double voxelSize_cm = 0.4, int levels = 3)
{
    BoughSpec a = test::paperBough(Vec3(-8.0, 0.0, 0.0), Vec3(1, 0, 0), 16.0);
    BoughSpec b = test::paperBough(Vec3(0.0, -8.0, 2.0), Vec3(0, 1, 0.2), 14.0);
    b.needles.cone.needlesPerCone = 20;
    b.needleAlbedo = Vec3(0.2, 0.4, 0.1);
    return bakeBoughs({a, b}, BakeSettings{voxelSize_cm, levels});
}

const BakeProvenance kProvenance{"scenes/test.json", 7, 4200432988u};

std::string readFile(const fs::path& file)
{
    std::ifstream in(file, std::ios::binary);
    return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

void writeFile(const fs::path& file, const std::string& bytes)
{
    std::ofstream(file, std::ios::binary) << bytes;
}

bool onPath(const char* tool)
{
    return std::system(("command -v " + std::string(tool) + " >/dev/null 2>&1").c_str()) == 0;
}

std::string quoted(const fs::path& p) { return "'" + p.string() + "'"; }

template <class GridT>
void expectSameGrid(const GridT& expected, const GridT& actual)
{
    EXPECT_EQ(expected.getName(), actual.getName());
    EXPECT_EQ(expected.transform(), actual.transform()) << expected.getName();
    EXPECT_EQ(expected.activeVoxelCount(), actual.activeVoxelCount()) << expected.getName();
    auto acc = actual.getConstAccessor();
    for (auto it = expected.cbeginValueOn(); it; ++it) {
        ASSERT_TRUE(acc.isValueOn(it.getCoord())) << expected.getName() << it.getCoord();
        ASSERT_EQ(*it, acc.getValue(it.getCoord())) << expected.getName() << it.getCoord();
    }
}

TEST(TreeGridsIo, RoundTripKeepsValuesAndScale)
{
    const test::TempDir dir;
    const TreeGrids g = twoBoughs();
    const fs::path file = dir.path() / "tree.vdb";
    writeTreeGrids(g, file, kProvenance);
    const TreeGrids r = readTreeGrids(file);
    expectSameGrid(*g.density, *r.density);
    expectSameGrid(*g.layerGradient, *r.layerGradient);
    expectSameGrid(*g.layerOpacity, *r.layerOpacity);
    expectSameGrid(*g.needleDirection, *r.needleDirection);
    expectSameGrid(*g.needleAlbedo, *r.needleAlbedo);
    ASSERT_EQ(g.densityPyramid.size(), 2u);
    ASSERT_EQ(r.densityPyramid.size(), 2u);
    for (std::size_t i = 0; i < 2; ++i) expectSameGrid(*g.densityPyramid[i], *r.densityPyramid[i]);
    EXPECT_EQ(r.densityScale_per_cm, g.densityScale_per_cm);
    EXPECT_EQ(r.voxelSize_cm, 0.4);
    // Writing adds metadata to what it writes, not to the caller's grids.
    EXPECT_FALSE(g.density->getMetadata<openvdb::DoubleMetadata>("pine:density_scale_per_cm"));
    // Only the file and its manifest: no temporary left behind.
    EXPECT_EQ(std::distance(fs::directory_iterator(dir.path()), fs::directory_iterator()), 2);
}

TEST(TreeGridsIo, OpenVdbSeesAFogVolumeFirstWithItsProvenance)
{
    // Read back with OpenVDB's own file reader, as a third-party tool would.
    const test::TempDir dir;
    const TreeGrids g = twoBoughs();
    const fs::path file = dir.path() / "tree.vdb";
    writeTreeGrids(g, file, kProvenance);
    openvdb::io::File in(file.string());
    in.open();
    const openvdb::GridPtrVecPtr grids = in.getGrids();
    const openvdb::MetaMap::Ptr meta = in.getMetadata();
    in.close();
    // io::File lists grids by name; density comes first there too.
    ASSERT_EQ(grids->size(), std::size(kFields) + g.densityPyramid.size());
    EXPECT_EQ((*grids)[0]->getName(), "density");
    // In the file itself (io::Stream reads it in order) density is written first.
    const std::vector<std::string> names = {"density", "layer_gradient", "layer_opacity",
                                            "needle_direction", "needle_coverage", "needle_albedo",
                                            "density_lod1",
                                            "density_lod2"};
    {
        std::ifstream raw(file, std::ios::binary);
        openvdb::io::Stream stream(raw, /*delayLoad=*/false);
        const openvdb::GridPtrVecPtr inOrder = stream.getGrids();
        ASSERT_EQ(inOrder->size(), names.size());
        for (std::size_t i = 0; i < names.size(); ++i) {
            EXPECT_EQ((*inOrder)[i]->getName(), names[i]);
        }
    }

    const auto density = openvdb::gridPtrCast<openvdb::FloatGrid>((*grids)[0]);
    ASSERT_TRUE(density);
    EXPECT_EQ(density->getGridClass(), openvdb::GRID_FOG_VOLUME);
    float lo = 2.0f, hi = -1.0f;
    for (auto it = density->cbeginValueOn(); it; ++it) {
        lo = std::min(lo, *it);
        hi = std::max(hi, *it);
    }
    EXPECT_GT(lo, 0.0f);
    EXPECT_NEAR(hi, 1.0f, 2e-7f);  // the densest voxel, normalized: 1 within float rounding
    EXPECT_LE(hi, 1.0f);
    const auto scale = density->getMetadata<openvdb::DoubleMetadata>("pine:density_scale_per_cm");
    ASSERT_TRUE(scale);
    EXPECT_EQ(scale->value(), g.densityScale_per_cm);

    ASSERT_TRUE(meta);
    EXPECT_EQ(meta->metaValue<std::string>("pine:units"), "cm");
    EXPECT_EQ(meta->metaValue<openvdb::Int32>("pine:format_version"), kFormatVersion);
    EXPECT_EQ(meta->metaValue<std::string>("pine:extinction_law"), "fibre");
    EXPECT_EQ(meta->metaValue<std::string>("pine:extinction"), extinctionLaw("fibre").formula());
    EXPECT_EQ(meta->metaValue<double>("pine:voxel_size_cm"), 0.4);
    EXPECT_EQ(meta->metaValue<std::string>("pine:scene"), "scenes/test.json");
    EXPECT_EQ(meta->metaValue<openvdb::Int32>("pine:tree"), 7);
    EXPECT_EQ(meta->metaValue<openvdb::Int64>("pine:seed"), 4200432988);
    EXPECT_FALSE(meta->metaValue<std::string>("pine:tool_version").empty());
    // The full-resolution grids share one transform: voxel centres at ijk h.
    for (const auto& grid : *grids) {
        if (grid->getName().find("_lod") != std::string::npos) continue;
        EXPECT_EQ(grid->transform(), density->transform()) << grid->getName();
    }
    EXPECT_EQ(density->indexToWorld(openvdb::Coord(3, -2, 5)),
              openvdb::Vec3d(3 * 0.4, -2 * 0.4, 5 * 0.4));
}

TEST(TreeGridsIo, VdbPrintListsEveryGrid)
{
    if (!onPath("vdb_print")) GTEST_SKIP() << "vdb_print is not on PATH";
    const test::TempDir dir;
    const fs::path file = dir.path() / "tree.vdb", listing = dir.path() / "listing.txt";
    writeTreeGrids(twoBoughs(), file, kProvenance);
    ASSERT_EQ(std::system(("vdb_print " + quoted(file) + " > " + quoted(listing)).c_str()), 0);
    const std::string text = readFile(listing);
    for (const char* name : {"density ", "layer_gradient", "layer_opacity", "needle_direction",
                             "needle_albedo", "density_lod1", "density_lod2"}) {
        EXPECT_NE(text.find(name), std::string::npos) << name << " not in:\n" << text;
    }
}

TEST(TreeGridsIo, VdbRenderDrawsTheDensity)
{
    // vdb_render takes the first float grid (density) and measures extinction per voxel; no
    // faked multiple scattering (-gain 0) and no cutoff of thin media (-cutoff 0) (DESIGN.md).
    if (!onPath("vdb_render")) GTEST_SKIP() << "vdb_render is not on PATH";
    const test::TempDir dir;
    const fs::path file = dir.path() / "tree.vdb", image = dir.path() / "tree.ppm";
    writeTreeGrids(twoBoughs(), file, kProvenance);
    const std::string command = "vdb_render " + quoted(file) + " " + quoted(image) +
                                " -gain 0 -cutoff 0 -res 64x64 -translate 0,0,40"
                                " -lookat 0,0,0 -cpus 1 > /dev/null 2>&1";
    ASSERT_EQ(std::system(command.c_str()), 0) << command;
    // Binary PPM: "P6\n64 64\n255\n" then 64 x 64 RGB bytes; the background is black.
    const std::string ppm = readFile(image);
    const std::string header = "P6\n64 64\n255\n";
    ASSERT_EQ(ppm.size(), header.size() + 64 * 64 * 3);
    ASSERT_EQ(ppm.substr(0, header.size()), header);
    int lit = 0;
    for (std::size_t i = header.size(); i < ppm.size(); i += 3) {
        lit += (ppm[i] != 0 || ppm[i + 1] != 0 || ppm[i + 2] != 0);
    }
    // Two 16 cm boughs 3.3 cm thick seen from 40 cm with a 44.8 degree field: a cross over
    // roughly a tenth of the frame.
    EXPECT_GT(lit, 200);
    EXPECT_LT(lit, 64 * 64 / 2);
}

std::string readBytes(const fs::path& p)
{
    std::ifstream in(p, std::ios::binary);
    return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

/// Writes grids to a fresh file and returns its path.
fs::path written(const test::TempDir& dir)
{
    const fs::path file = dir.path() / "tree.vdb";
    writeTreeGrids(twoBoughs(0.8, 1), file, kProvenance);
    return file;
}

void expectRefused(const fs::path& file, const std::string& fragment)
{
    try {
        readTreeGrids(file);
        ADD_FAILURE() << "readTreeGrids accepted " << file;
    } catch (const BakeError& e) {
        const std::string message = e.what();
        EXPECT_NE(message.find(file.string()), std::string::npos) << message;
        EXPECT_NE(message.find(fragment), std::string::npos) << message;
    }
}

TEST(TreeGridsIo, DamagedFilesAreRefusedBeforeOpenVdbReadsThem)
{
    const test::TempDir dir;
    const fs::path file = written(dir);
    const std::string good = readFile(file);
    ASSERT_GT(good.size(), 1000u);
    const std::string mismatch = "does not match its manifest (written by bake?)";

    // One byte flipped, anywhere: header, metadata, descriptors, compressed data.
    for (const double where : {0.001, 0.1, 0.5, 0.9, 0.999}) {
        std::string bad = good;
        bad[std::size_t(where * double(bad.size()))] ^= 0x5a;
        writeFile(file, bad);
        expectRefused(file, mismatch);
    }
    // Truncated, and lengthened.
    writeFile(file, good.substr(0, good.size() / 2));
    expectRefused(file, mismatch);
    writeFile(file, good + "x");
    expectRefused(file, mismatch);
    // Back to the original: accepted again.
    writeFile(file, good);
    EXPECT_NO_THROW(readTreeGrids(file));
}

TEST(TreeGridsIo, AMissingOrForeignManifestIsRefused)
{
    const test::TempDir dir;
    const fs::path file = written(dir);
    const fs::path manifest = file.string() + ".json";
    const std::string good = readFile(manifest);

    fs::remove(manifest);
    expectRefused(file, "no manifest");
    writeFile(manifest, "{\"file\": \"tree.vdb\"");
    expectRefused(file, "unreadable manifest");
    writeFile(manifest, "{\"file\": \"tree.vdb\", \"bytes\": \"many\", \"fnv1a64\": \"0\"}");
    expectRefused(file, "unreadable manifest");
    // The manifest of another bake beside this file.
    const fs::path other = dir.path() / "other.vdb";
    writeTreeGrids(twoBoughs(0.7, 1), other, kProvenance);
    fs::copy_file(other.string() + ".json", manifest, fs::copy_options::overwrite_existing);
    expectRefused(file, "does not match its manifest");
    // A file renamed with its manifest is the same file.
    writeFile(manifest, good);
    fs::rename(file, dir.path() / "renamed.vdb");
    fs::rename(manifest, dir.path() / "renamed.vdb.json");
    EXPECT_NO_THROW(readTreeGrids(dir.path() / "renamed.vdb"));
}

// A manifest beside `file` that matches its bytes, as a file edited elsewhere would have.
void writeMatchingManifest(const fs::path& file)
{
    const std::string text = readFile(file);
    std::uint64_t hash = 14695981039346656037ull;
    for (const char c : text) {
        hash ^= std::uint64_t(static_cast<unsigned char>(c));
        hash *= 1099511628211ull;
    }
    char hex[17];
    std::snprintf(hex, sizeof hex, "%016llx", static_cast<unsigned long long>(hash));
    std::ostringstream manifest;
    manifest << R"({"file": ")" << file.filename().string() << R"(", "bytes": )" << text.size()
             << R"(, "fnv1a64": ")" << hex << "\"}";
    writeFile(file.string() + ".json", manifest.str());
}

TEST(TreeGridsIo, WhatOpenVdbCannotReadIsABakeError)
{
    // A manifest that matches a file that is not a VDB: OpenVDB refuses it, and we say so as
    // BakeError rather than letting its exception through.
    const test::TempDir dir;
    const fs::path file = dir.path() / "fake.vdb";
    writeFile(file, "this is not a vdb file, though its manifest says it is fine\n");
    writeMatchingManifest(file);
    expectRefused(file, "cannot read");
}

TEST(TreeGridsIo, DamagedBytesWithAMatchingManifestAreRefusedNeverFatal)
{
    // A file edited elsewhere comes with a manifest that matches its bytes. OpenVDB 10.0.1
    // crashes on some such damage (SIGSEGV on a flipped byte, SIGBUS on a zeroed block, an abort
    // on a corrupted heap) or allocates gigabytes: whatever the damage, the read returns or
    // throws BakeError, and this process survives it (it did not before reads were isolated).
    const test::TempDir dir;
    const fs::path good = written(dir);
    const std::string bytes = readFile(good);
    const fs::path file = dir.path() / "damaged.vdb";
    std::mt19937_64 rng(3);  // its trial 21 aborts OpenVDB 10.0.1 (malloc: heap corrupted)
    int refused = 0, read = 0, fatal = 0;  // fatal: crashed or ran out of memory in the child
    std::string lastWhy;
    for (int trial = 0; trial < 40; ++trial) {
        std::string damaged = bytes;
        // Half of the damage in the first 2 KiB: the header, metadata and first topology.
        const std::size_t at = rng() % (trial % 8 < 4 ? std::min<std::size_t>(2048, damaged.size())
                                                      : damaged.size());
        switch (trial % 4) {
        case 0: damaged[at] = char(damaged[at] ^ (1 << (rng() % 8))); break;
        case 1: damaged.replace(at, std::min<std::size_t>(4096, damaged.size() - at),
                                std::min<std::size_t>(4096, damaged.size() - at), '\0'); break;
        case 2: damaged.resize(at); break;
        case 3:  // a size or count field made huge
            for (int i = 0; i < 4 && at + i < damaged.size(); ++i) damaged[at + i] = char(0x7f);
            break;
        }
        writeFile(file, damaged);
        writeMatchingManifest(file);
        try {
            (void)readTreeGrids(file, 512.0 * 1024 * 1024);
            ++read;
        } catch (const BakeError& e) {
            ++refused;
            lastWhy = e.what();
            if (lastWhy.find("OpenVDB") != std::string::npos) ++fatal;
            EXPECT_NE(lastWhy.find("damaged.vdb"), std::string::npos) << lastWhy;
            EXPECT_EQ(lastWhy.find('\n'), std::string::npos) << lastWhy;
        }
    }
    EXPECT_EQ(read + refused, 40);
    EXPECT_GT(refused, 20) << "most damage must be seen";
    std::cout << read << " damaged files read, " << refused << " refused (" << fatal
              << " that would have crashed this process or exhausted its memory)\n";
}

TEST(TreeGridsIo, AnotherFormatVersionOrAnUnknownLawIsRefused)
{
    // The same grids written again by OpenVDB with one piece of file metadata changed, and a
    // manifest that matches: what the file says of itself decides.
    const test::TempDir dir;
    const fs::path file = written(dir);
    openvdb::GridPtrVecPtr grids;
    openvdb::MetaMap::Ptr meta;
    {
        openvdb::io::File in(file.string());
        in.open();
        grids = in.getGrids();
        meta = in.getMetadata();
    }
    const auto rewrite = [&](const openvdb::MetaMap& m, const openvdb::GridPtrVec* with = nullptr) {
        openvdb::io::File out(file.string());
        out.write(with ? *with : *grids, m);
        out.close();
        writeMatchingManifest(file);
    };
    openvdb::MetaMap old = *meta;
    old.removeMeta("pine:format_version");
    rewrite(old);
    expectRefused(file, "no pine:format_version");
    openvdb::MetaMap future = *meta;
    future.insertMeta("pine:format_version", openvdb::Int32Metadata(kFormatVersion + 1));
    rewrite(future);
    expectRefused(file, "format version " + std::to_string(kFormatVersion + 1));
    openvdb::MetaMap unknown = *meta;
    unknown.insertMeta("pine:extinction_law", openvdb::StringMetadata("dust"));
    rewrite(unknown);
    expectRefused(file, "unknown extinction law 'dust'");
    // A pyramid level of another type is refused, not taken as the pyramid's end.
    openvdb::GridPtrVec wrongLod = *grids;
    wrongLod.push_back(openvdb::Vec3SGrid::create());
    wrongLod.back()->setName("density_lod1");
    rewrite(*meta, &wrongLod);
    expectRefused(file, "grid 'density_lod1' has type Tree_vec3s");
    rewrite(*meta);
    EXPECT_EQ(readTreeGrids(file).extinctionLaw, BakeSettings{}.extinctionLaw);
}

TEST(TreeGridsIo, UnwritableOutputIsABakeErrorAndLeavesNothing)
{
    const test::TempDir dir;
    const TreeGrids g = twoBoughs(0.8, 1);
    EXPECT_THROW(writeTreeGrids(g, dir.path() / "no" / "such" / "tree.vdb", kProvenance),
                 BakeError);
    EXPECT_THROW(io::checkWritable(dir.path() / "no" / "tree.vdb"), InputError);
    fs::create_directory(dir.path() / "folder.vdb");
    EXPECT_THROW(writeTreeGrids(g, dir.path() / "folder.vdb", kProvenance), BakeError);
    TreeGrids incomplete = g;
    incomplete.layerGradient = nullptr;
    EXPECT_THROW(writeTreeGrids(incomplete, dir.path() / "tree.vdb", kProvenance), BakeError);
    // Only the folder made above: no file, no temporary.
    std::vector<fs::path> left;
    for (const auto& entry : fs::recursive_directory_iterator(dir.path())) {
        left.push_back(entry.path());
    }
    ASSERT_EQ(left.size(), 1u);
    EXPECT_EQ(left[0], dir.path() / "folder.vdb");
}

TEST(TreeGridsIo, RewritingReplacesTheFileAndItsManifest)
{
    const test::TempDir dir;
    const fs::path file = dir.path() / "tree.vdb";
    writeTreeGrids(twoBoughs(0.8, 1), file, kProvenance);
    const TreeGrids finer = twoBoughs(0.5, 2);
    writeTreeGrids(finer, file, kProvenance);
    const TreeGrids r = readTreeGrids(file);
    EXPECT_EQ(r.voxelSize_cm, 0.5);
    EXPECT_EQ(r.densityPyramid.size(), 1u);
    EXPECT_EQ(r.density->activeVoxelCount(), finer.density->activeVoxelCount());
    EXPECT_EQ(std::distance(fs::directory_iterator(dir.path()), fs::directory_iterator()), 2);
}

TEST(TreeGridsIo, AFailedManifestLeavesThePreviousPairAndAKilledBakesTemporariesGo)
{
    const test::TempDir dir;
    const fs::path file = dir.path() / "tree.vdb";
    writeTreeGrids(twoBoughs(0.8, 1), file, kProvenance);
    const std::string before = readBytes(file), manifest = readBytes(file.string() + ".json");
    // What a bake killed mid-write leaves: temporaries of the grid and of the manifest.
    for (const char* stale :
         {".tree.vdb.tmp-0123456789abcdef", ".tree.vdb.json.tmp-fedcba9876543210"}) {
        std::ofstream(dir.path() / stale) << "half";
    }
    // The manifest cannot be put in place (its name is made a folder): the new grid must not
    // replace the old one.
    fs::remove(file.string() + ".json");
    fs::create_directory(file.string() + ".json");
    EXPECT_THROW(writeTreeGrids(twoBoughs(0.5, 2), file, kProvenance), BakeError);
    EXPECT_EQ(readBytes(file), before);
    fs::remove(file.string() + ".json");
    std::ofstream(file.string() + ".json", std::ios::binary) << manifest;
    EXPECT_EQ(readTreeGrids(file).voxelSize_cm, 0.8);
    // The stale temporaries were removed by that write; nothing of its own is left.
    std::vector<std::string> names;
    for (const auto& e : fs::directory_iterator(dir.path())) {
        names.push_back(e.path().filename().string());
    }
    std::sort(names.begin(), names.end());
    EXPECT_EQ(names, (std::vector<std::string>{"tree.vdb", "tree.vdb.json"}));
    // And the next bake replaces both.
    writeTreeGrids(twoBoughs(0.5, 2), file, kProvenance);
    EXPECT_EQ(readTreeGrids(file).voxelSize_cm, 0.5);
}

}  // namespace
}  // namespace pine::bake
