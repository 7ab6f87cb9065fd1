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

const BakeProvenance kProvenance{"scenes/test.json", 7, 4200432988u, "0123456789abcdef"};

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

double magnitude(float v) { return std::abs(double(v)); }
double magnitude(const openvdb::Vec3s& v) { return double(v.length()); }

/// Expects `actual` to hold `expected`'s voxels, each value within `tolerance` (relative; 0:
/// the same values).
template <class GridT>
void expectNearGrid(const GridT& expected, const GridT& actual, double tolerance)
{
    EXPECT_EQ(expected.getName(), actual.getName());
    EXPECT_EQ(expected.transform(), actual.transform()) << expected.getName();
    EXPECT_EQ(expected.activeVoxelCount(), actual.activeVoxelCount()) << expected.getName();
    auto acc = actual.getConstAccessor();
    for (auto it = expected.cbeginValueOn(); it; ++it) {
        ASSERT_TRUE(acc.isValueOn(it.getCoord())) << expected.getName() << it.getCoord();
        const auto e = *it, a = acc.getValue(it.getCoord());
        if (tolerance == 0.0) {
            ASSERT_EQ(e, a) << expected.getName() << it.getCoord();
        } else {
            ASSERT_LE(magnitude(e - a), tolerance * magnitude(e) + 1e-30)
                << expected.getName() << it.getCoord() << ": " << e << " against " << a;
        }
    }
}

template <class GridT>
void expectSameGrid(const GridT& expected, const GridT& actual)
{
    expectNearGrid(expected, actual, 0.0);
}

void expectSameGrids(const TreeGrids& g, const TreeGrids& r, double tolerance)
{
    const auto same = [&](const auto& e, const auto& a) { expectNearGrid(e, a, tolerance); };
    same(*g.density, *r.density);
    same(*g.layerGradient, *r.layerGradient);
    same(*g.layerOpacity, *r.layerOpacity);
    same(*g.needleDirection, *r.needleDirection);
    same(*g.needleCoverage, *r.needleCoverage);
    same(*g.needleAlbedo, *r.needleAlbedo);
    ASSERT_EQ(r.densityPyramid.size(), g.densityPyramid.size());
    for (std::size_t i = 0; i < g.densityPyramid.size(); ++i) {
        same(*g.densityPyramid[i], *r.densityPyramid[i]);
    }
    EXPECT_EQ(r.voxelSize_cm, g.voxelSize_cm);
    EXPECT_EQ(r.extinctionLaw, g.extinctionLaw);
}

TEST(TreeGridsIo, RoundTripKeepsValuesInEveryUnitAndFrame)
{
    const test::TempDir dir;
    const TreeGrids g = twoBoughs();
    ASSERT_EQ(g.densityPyramid.size(), 2u);
    const fs::path file = dir.path() / "tree.vdb";
    // In cm and the world's frame nothing is converted: every voxel comes back bit for bit.
    writeTreeGrids(g, file, kProvenance, {LengthUnit::Centimetre, std::nullopt});
    ReadGrids r = readTreeGrids(file);
    expectSameGrids(g, r.grids, 0.0);
    EXPECT_EQ(r.unverified, "");
    EXPECT_EQ(r.provenance.scene, kProvenance.scene);
    EXPECT_EQ(r.provenance.tree, kProvenance.tree);
    EXPECT_EQ(r.provenance.seed, kProvenance.seed);
    EXPECT_EQ(r.provenance.treeDigest, kProvenance.treeDigest);
    // Every voxel is the file's tree (in memory only: no grid of it is written).
    ASSERT_TRUE(r.grids.tree);
    EXPECT_EQ(r.grids.tree->activeVoxelCount(), g.density->activeVoxelCount());
    const auto tree = r.grids.tree->getConstAccessor();
    for (auto it = g.density->cbeginValueOn(); it; ++it) {
        ASSERT_EQ(tree.getValue(it.getCoord()), kProvenance.tree) << it.getCoord();
    }
    BakeProvenance noTree = kProvenance;
    noTree.tree = -1;
    const test::TempDir other;
    writeTreeGrids(g, other.path() / "no-tree.vdb", noTree);
    EXPECT_FALSE(readTreeGrids(other.path() / "no-tree.vdb").grids.tree);
    // In metres, in a tree's frame, turned: back on the scene's lattice within float rounding
    // of the values (scaled by 100 and turned, then back).
    for (const double turn : {0.0, 0.7, -2.5}) {
        const FileLayout layout{LengthUnit::Metre, TreeFrame{Vec3(123.4, -56.7, 8.9), turn}};
        writeTreeGrids(g, file, kProvenance, layout);
        r = readTreeGrids(file);
        expectSameGrids(g, r.grids, 4e-7);
    }
    // Writing changes what it writes, not the caller's grids.
    EXPECT_FALSE(g.density->getMetadata<openvdb::StringMetadata>("pine:units"));
    EXPECT_EQ(g.density->transform(), *openvdb::math::Transform::createLinearTransform(0.4));
    // Only the file and its manifest: no temporary left behind.
    EXPECT_EQ(std::distance(fs::directory_iterator(dir.path()), fs::directory_iterator()), 2);
}

TEST(TreeGridsIo, InATreesFrameTheTreeStandsAtTheOriginInMetres)
{
    // What a Blender or Houdini user sees: world positions in the tree's frame, in metres,
    // extinction per metre, vectors turned with the tree.
    const test::TempDir dir;
    const TreeGrids g = twoBoughs();
    const fs::path file = dir.path() / "tree.vdb";
    const Vec3 base(-300.0, 250.0, 12.0);
    const double turn = 0.6;
    writeTreeGrids(g, file, kProvenance, {LengthUnit::Metre, TreeFrame{base, turn}});
    openvdb::io::File in(file.string());
    in.open();
    const openvdb::GridPtrVecPtr grids = in.getGrids();
    const openvdb::MetaMap::Ptr meta = in.getMetadata();
    in.close();
    const auto find = [&](const std::string& name) {
        for (const auto& grid : *grids) {
            if (grid->getName() == name) return grid;
        }
        return openvdb::GridBase::Ptr();
    };
    const auto density = openvdb::gridPtrCast<openvdb::FloatGrid>(find("density"));
    const auto needle = openvdb::gridPtrCast<openvdb::Vec3SGrid>(find("needle_direction"));
    const auto gradient = openvdb::gridPtrCast<openvdb::Vec3SGrid>(find("layer_gradient"));
    ASSERT_TRUE(density && needle && gradient);
    EXPECT_EQ(meta->metaValue<std::string>("pine:units"), "m");
    EXPECT_EQ(meta->metaValue<std::string>("pine:frame"), "tree");
    EXPECT_EQ(meta->metaValue<double>("pine:voxel_size"), 0.004);
    const double c = std::cos(turn), s = std::sin(turn);
    const auto intoTree = [&](const Vec3& p) {  // R(-turn) (p - base), independently of bake
        const Vec3 q = p - base;
        return Vec3(c * q.x + s * q.y, -s * q.x + c * q.y, q.z);
    };
    auto inMemory = g.density->getConstAccessor();
    auto memNeedle = g.needleDirection->getConstAccessor();
    auto memGradient = g.layerGradient->getConstAccessor();
    auto fileNeedle = needle->getConstAccessor();
    auto fileGradient = gradient->getConstAccessor();
    int checked = 0;
    for (auto it = density->cbeginValueOn(); it; ++it, ++checked) {
        const openvdb::Coord ijk = it.getCoord();
        // The same voxel of the scene's lattice, its centre in the tree's frame in metres.
        const openvdb::Vec3d w = density->indexToWorld(ijk);
        const Vec3 expected = intoTree(Vec3(ijk.x(), ijk.y(), ijk.z()) * 0.4) / 100.0;
        ASSERT_NEAR(w.x(), expected.x, 1e-9) << ijk;
        ASSERT_NEAR(w.y(), expected.y, 1e-9) << ijk;
        ASSERT_NEAR(w.z(), expected.z, 1e-9) << ijk;
        ASSERT_NEAR(*it, inMemory.getValue(ijk) * 100.0, 1e-5 * *it) << ijk;  // per m
        const auto mn = memNeedle.getValue(ijk), fn = fileNeedle.getValue(ijk);
        const Vec3 turned = intoTree(Vec3(mn.x(), mn.y(), mn.z()) + base);
        ASSERT_NEAR(fn.x(), turned.x, 1e-6);
        ASSERT_NEAR(fn.y(), turned.y, 1e-6);
        ASSERT_NEAR(fn.z(), turned.z, 1e-6);
        const auto mg = memGradient.getValue(ijk), fg = fileGradient.getValue(ijk);
        const Vec3 perMetre = intoTree(Vec3(mg.x(), mg.y(), mg.z()) + base) * 100.0;
        ASSERT_NEAR(fg.x(), perMetre.x, 1e-5 * glm::length(perMetre));
        ASSERT_NEAR(fg.y(), perMetre.y, 1e-5 * glm::length(perMetre));
        ASSERT_NEAR(fg.z(), perMetre.z, 1e-5 * glm::length(perMetre));
    }
    EXPECT_EQ(checked, int(g.density->activeVoxelCount()));
}

TEST(TreeGridsIo, OpenVdbSeesDensityFirstWithItsProvenance)
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
    // io::File lists grids by name; density is its first float grid (what vdb_render takes).
    ASSERT_EQ(grids->size(), std::size(kFields) + g.densityPyramid.size());
    const auto firstFloat = std::find_if(grids->begin(), grids->end(), [](const auto& grid) {
        return openvdb::gridConstPtrCast<openvdb::FloatGrid>(grid) != nullptr;
    });
    ASSERT_NE(firstFloat, grids->end());
    EXPECT_EQ((*firstFloat)->getName(), "density");
    // In the file itself (io::Stream reads it in order) density is written first; the levels
    // are named as vdb_lod names them.
    const std::vector<std::string> names = {"density", "layer_gradient", "layer_opacity",
                                            "needle_direction", "needle_coverage", "color",
                                            "density_level_1", "density_level_2"};
    {
        std::ifstream raw(file, std::ios::binary);
        openvdb::io::Stream stream(raw, /*delayLoad=*/false);
        const openvdb::GridPtrVecPtr inOrder = stream.getGrids();
        ASSERT_EQ(inOrder->size(), names.size());
        for (std::size_t i = 0; i < names.size(); ++i) {
            EXPECT_EQ((*inOrder)[i]->getName(), names[i]);
        }
    }

    // density is extinction per metre (the default unit), not a normalized fog volume.
    const auto density = openvdb::gridPtrCast<openvdb::FloatGrid>(*firstFloat);
    ASSERT_TRUE(density);
    EXPECT_EQ(density->getGridClass(), openvdb::GRID_UNKNOWN);
    auto inMemory = g.density->getConstAccessor();
    float lo = 1e30f, hi = -1.0f;
    for (auto it = density->cbeginValueOn(); it; ++it) {
        lo = std::min(lo, *it);
        hi = std::max(hi, *it);
        ASSERT_NEAR(*it, 100.0 * inMemory.getValue(it.getCoord()), 1e-6 * *it);
    }
    EXPECT_GT(lo, 0.0f);
    EXPECT_GT(hi, 2.0f * lo);  // a field, not an occupancy mask
    EXPECT_TRUE(density->getMetadata<openvdb::StringMetadata>("pine:units"));

    ASSERT_TRUE(meta);
    EXPECT_EQ(meta->metaValue<std::string>("pine:units"), "m");
    EXPECT_EQ(meta->metaValue<std::string>("pine:density_unit"), "extinction per m");
    EXPECT_EQ(meta->metaValue<std::string>("pine:frame"), "world");
    EXPECT_EQ(meta->metaValue<openvdb::Int32>("pine:format_version"), kFormatVersion);
    EXPECT_EQ(meta->metaValue<std::string>("pine:extinction_law"), "fibre");
    EXPECT_EQ(meta->metaValue<std::string>("pine:extinction"), extinctionLaw("fibre").formula());
    EXPECT_EQ(meta->metaValue<double>("pine:voxel_size_cm"), 0.4);
    EXPECT_EQ(meta->metaValue<double>("pine:voxel_size"), 0.004);
    EXPECT_EQ(meta->metaValue<std::string>("pine:scene"), "scenes/test.json");
    EXPECT_EQ(meta->metaValue<openvdb::Int32>("pine:tree"), 7);
    EXPECT_EQ(meta->metaValue<openvdb::Int64>("pine:seed"), 4200432988);
    EXPECT_EQ(meta->metaValue<std::string>("pine:tree_digest"), kProvenance.treeDigest);
    EXPECT_FALSE(meta->metaValue<std::string>("pine:tool_version").empty());
    // The full-resolution grids share one transform: voxel centres at ijk h, in metres.
    for (const auto& grid : *grids) {
        if (grid->getName().find("_level_") != std::string::npos) continue;
        EXPECT_EQ(grid->transform(), density->transform()) << grid->getName();
    }
    const openvdb::Vec3d p = density->indexToWorld(openvdb::Coord(3, -2, 5));
    EXPECT_NEAR(p.x(), 3 * 0.004, 1e-15);
    EXPECT_NEAR(p.y(), -2 * 0.004, 1e-15);
    EXPECT_NEAR(p.z(), 5 * 0.004, 1e-15);
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
                             "color", "density_level_1", "density_level_2"}) {
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
                                " -gain 0 -cutoff 0 -res 64x64 -translate 0,0,0.4"
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
    // Two 16 cm boughs 3.3 cm thick seen from 40 cm (the file is in metres) with a 44.8
    // degree field: a cross over
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
    const std::string mismatch = "does not match its manifest (damaged";

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

TEST(TreeGridsIo, AForeignManifestIsRefused)
{
    const test::TempDir dir;
    const fs::path file = written(dir);
    const fs::path manifest = file.string() + ".json";
    const std::string good = readFile(manifest);

    writeFile(manifest, "{\"file\": \"tree.vdb\"");
    expectRefused(file, "unreadable manifest");
    writeFile(manifest, "{\"file\": \"tree.vdb\", \"bytes\": \"many\", \"fnv1a64\": \"0\"}");
    expectRefused(file, "unreadable manifest");
    // In the manifest's words, without the JSON library's tags.
    writeFile(manifest, "{\"bytes\": 1, \"fnv1a64\": \"0\"}");
    expectRefused(file, "unreadable manifest: key 'file' not found");
    try {
        readTreeGrids(file);
        ADD_FAILURE() << "a manifest without 'file' was accepted";
    } catch (const BakeError& e) {
        EXPECT_EQ(std::string(e.what()).find("json.exception"), std::string::npos) << e.what();
    }
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

TEST(TreeGridsIo, AGridWithAZeroScaleIsRefusedNamingItsFile)
{
    // A flipped bit that makes a grid's voxel size 0 (the fuzz found one in a checkout whose
    // path moved the damage there): OpenVDB reads the stream, then throws ArithmeticError
    // building the map, which reached the user without the file's name. Each double of the
    // file equal to the density grid's voxel size (in file units) zeroed in turn, with a
    // matching manifest: refused, naming the file, on one line.
    const test::TempDir dir;
    const fs::path good = written(dir);
    const std::string bytes = readFile(good);
    double scale = 0.0;
    {
        std::istringstream in(bytes, std::ios::binary);
        openvdb::io::Stream stream(in, /*delayLoad=*/false);
        scale = stream.getGrids()->front()->voxelSize()[0];
    }
    ASSERT_GT(scale, 0.0);
    const std::string needle(reinterpret_cast<const char*>(&scale), sizeof scale);
    const fs::path file = dir.path() / "zero-scale.vdb";
    int zeroed = 0;
    for (std::size_t at = bytes.find(needle); at != std::string::npos;
         at = bytes.find(needle, at + 1)) {
        std::string damaged = bytes;
        damaged.replace(at, sizeof scale, std::string(sizeof scale, '\0'));
        writeFile(file, damaged);
        writeMatchingManifest(file);
        ++zeroed;
        try {
            (void)readTreeGrids(file);
        } catch (const BakeError& e) {
            const std::string why = e.what();
            EXPECT_NE(why.find(file.string()), std::string::npos) << why;
            EXPECT_EQ(why.find('\n'), std::string::npos) << why;
        }
    }
    EXPECT_GT(zeroed, 0);
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
    openvdb::GridPtrVec oldGrids = *grids;  // nor on the density grid (its copy is read too)
    for (auto& grid : oldGrids) {
        grid = grid->copyGrid();
        grid->removeMeta("pine:format_version");
    }
    rewrite(old, &oldGrids);
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
    wrongLod.back()->setName("density_level_1");
    rewrite(*meta, &wrongLod);
    expectRefused(file, "grid 'density_level_1' has type Tree_vec3s");
    openvdb::MetaMap noUnit = *meta;
    noUnit.insertMeta("pine:units", openvdb::StringMetadata("furlong"));
    rewrite(noUnit);
    expectRefused(file, "unknown length unit 'furlong'");
    openvdb::MetaMap noFrame = *meta;
    noFrame.insertMeta("pine:frame", openvdb::StringMetadata("tree"));
    rewrite(noFrame);
    expectRefused(file, "frame 'tree' without pine:tree_base_cm");
    // A grid moved off the lattice its metadata states (resampled elsewhere) is refused.
    openvdb::GridPtrVec moved = *grids;
    for (auto& grid : moved) {
        if (grid->getName() != "layer_opacity") continue;
        grid = grid->copyGrid();
        auto xform = grid->transform().copy();
        xform->postTranslate(openvdb::Vec3d(0.001, 0.0, 0.0));
        grid->setTransform(xform);
    }
    rewrite(*meta, &moved);
    expectRefused(file, "grid 'layer_opacity' is not on the lattice of 0.8 cm voxels");
    // Within a millionth of a voxel (what float transforms from another tool keep) it is read.
    openvdb::GridPtrVec nudged = *grids;
    for (auto& grid : nudged) {
        grid = grid->copyGrid();
        auto xform = grid->transform().copy();
        xform->postTranslate(openvdb::Vec3d(1e-9, 0.0, 0.0));  // metres: 1e-7 cm
        grid->setTransform(xform);
    }
    rewrite(*meta, &nudged);
    EXPECT_NO_THROW(readTreeGrids(file));
    rewrite(*meta);
    EXPECT_EQ(readTreeGrids(file).grids.extinctionLaw, BakeSettings{}.extinctionLaw);
}

TEST(TreeGridsIo, AGridWithoutAManifestIsReadUnverifiedFromItsMetadata)
{
    // A bake copied or edited elsewhere without its manifest: read, and said to be unverified.
    const test::TempDir dir;
    const fs::path file = written(dir);
    const ReadGrids verified = readTreeGrids(file);
    fs::remove(file.string() + ".json");
    const ReadGrids read = readTreeGrids(file);
    EXPECT_NE(read.unverified.find("no manifest 'tree.vdb.json'"), std::string::npos)
        << read.unverified;
    expectSameGrids(verified.grids, read.grids, 0.0);
    EXPECT_EQ(read.provenance.treeDigest, kProvenance.treeDigest);

    // Through a tool that keeps the grids but drops the file's metadata: the density grid's
    // copy of it is read.
    {
        openvdb::io::File in(file.string());
        in.open();
        const openvdb::GridPtrVecPtr grids = in.getGrids();
        in.close();
        const fs::path resaved = dir.path() / "resaved.vdb";
        openvdb::io::File out(resaved.string());
        out.write(*grids);  // no file metadata
        out.close();
        const ReadGrids again = readTreeGrids(resaved);
        EXPECT_FALSE(again.unverified.empty());
        expectSameGrids(verified.grids, again.grids, 0.0);
    }

    // A grid another tool made with nothing said of it: refused in one line.
    const fs::path foreign = dir.path() / "foreign.vdb";
    {
        openvdb::FloatGrid::Ptr density = openvdb::FloatGrid::create(0.0f);
        density->setName("density");
        density->tree().setValue(openvdb::Coord(1, 2, 3), 0.5f);
        openvdb::io::File out(foreign.string());
        out.write({density});
        out.close();
    }
    expectRefused(foreign, "no manifest beside it and no pine:format_version metadata");
    // Damaged bytes without a manifest: parsed in the isolated child, refused, never fatal.
    std::string bad = readFile(file);
    bad.resize(bad.size() / 2);
    writeFile(file, bad);
    try {
        readTreeGrids(file);
        ADD_FAILURE() << "a truncated file without a manifest was read";
    } catch (const BakeError& e) {
        EXPECT_NE(std::string(e.what()).find(file.string()), std::string::npos) << e.what();
    }
    EXPECT_THROW(readTreeGrids(dir.path() / "missing.vdb"), BakeError);
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
    const TreeGrids r = readTreeGrids(file).grids;
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
    EXPECT_EQ(readTreeGrids(file).grids.voxelSize_cm, 0.8);
    // The stale temporaries were removed by that write; nothing of its own is left.
    std::vector<std::string> names;
    for (const auto& e : fs::directory_iterator(dir.path())) {
        names.push_back(e.path().filename().string());
    }
    std::sort(names.begin(), names.end());
    EXPECT_EQ(names, (std::vector<std::string>{"tree.vdb", "tree.vdb.json"}));
    // And the next bake replaces both.
    writeTreeGrids(twoBoughs(0.5, 2), file, kProvenance);
    EXPECT_EQ(readTreeGrids(file).grids.voxelSize_cm, 0.5);
}

}  // namespace
}  // namespace pine::bake
