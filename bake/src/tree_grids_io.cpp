// Writing and reading a tree's grids: OpenVDB files that third-party tools open, with their
// provenance, written atomically and checked against their manifest before being parsed.
#include "pine/bake/tree_grids.h"

#include "manifest.h"
#include "pine/bake/extinction_law.h"
#include "pine/bake/resource_estimate.h"
#include "pine/support/atomic_file.h"
#include "pine/support/folder_lock.h"
#include "pine/support/isolated_process.h"

#include <openvdb/io/Stream.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <optional>
#include <sstream>
#include <system_error>

#ifndef PINE_TOOL_VERSION
#define PINE_TOOL_VERSION "unknown"
#endif

namespace pine::bake {

namespace fs = std::filesystem;

openvdb::Mat4d worldToFile(const FileLayout& layout)
{
    const double inv = 1.0 / centimetresPer(layout.unit);
    const TreeFrame frame = layout.treeFrame.value_or(TreeFrame{});
    // p' = R(-theta) (p - base) / u, R a turn about z.
    const double c = std::cos(frame.rotation_rad), s = std::sin(frame.rotation_rad);
    const double r[3][3] = {{c, s, 0.0}, {-s, c, 0.0}, {0.0, 0.0, 1.0}};  // R(-theta), [row][col]
    openvdb::Mat4d m = openvdb::Mat4d::identity();
    for (int i = 0; i < 3; ++i) {
        double t = 0.0;
        for (int j = 0; j < 3; ++j) {
            m[j][i] = r[i][j] * inv;  // row-vector convention: the transpose
            t -= r[i][j] * frame.base_cm[j];
        }
        m[3][i] = t * inv;
    }
    return m;
}

namespace {

constexpr const char* kFormatVersionKey = "pine:format_version";
constexpr const char* kExtinctionLawKey = "pine:extinction_law";
constexpr const char* kUnitsKey = "pine:units";
constexpr const char* kFrameKey = "pine:frame";
constexpr const char* kTreeBaseKey = "pine:tree_base_cm";
constexpr const char* kTreeRotationKey = "pine:tree_rotation_rad";
constexpr const char* kVoxelSizeKey = "pine:voxel_size_cm";

bool isIdentity(const FileLayout& layout)
{
    return layout.unit == LengthUnit::Centimetre &&
           (!layout.treeFrame ||
            (layout.treeFrame->base_cm == Vec3(0.0) && layout.treeFrame->rotation_rad == 0.0));
}

openvdb::Mat4d matrixOf(const openvdb::GridBase& grid)
{
    return grid.transform().baseMap()->getAffineMap()->getMat4();
}

/// The grid's values times `scale` and, for vectors, turned by `turn_rad` about z.
void convertValues(openvdb::GridBase& grid, double scale, double turn_rad)
{
    if (auto f = dynamic_cast<openvdb::FloatGrid*>(&grid)) {
        if (scale == 1.0) return;
        for (auto it = f->beginValueOn(); it; ++it) it.setValue(float(double(*it) * scale));
        return;
    }
    auto& v = dynamic_cast<openvdb::Vec3SGrid&>(grid);
    const double c = std::cos(turn_rad), s = std::sin(turn_rad);
    for (auto it = v.beginValueOn(); it; ++it) {
        const openvdb::Vec3s a = *it;
        it.setValue(openvdb::Vec3s(float((c * a.x() - s * a.y()) * scale),
                                   float((s * a.x() + c * a.y()) * scale), float(a.z() * scale)));
    }
}

/// How a field changes with the layout: extinction and layers per length scale with the unit,
/// vectors turn with the frame.
struct FieldConversion {
    bool perLength = false;
    bool turns = false;
};
FieldConversion conversionOf(Field field)
{
    switch (field) {
    case Field::Density: return {true, false};
    case Field::LayerGradient: return {true, true};
    case Field::NeedleDirection: return {false, true};
    default: return {};
    }
}

/// A grid as written in `layout`: a copy with the file's transform and values (the same grid
/// where nothing changes), with `meta` on it for tools that show only grid metadata.
openvdb::GridBase::Ptr forFile(const openvdb::GridBase& grid, Field field,
                               const FileLayout& layout, const openvdb::MetaMap* meta)
{
    const bool identity = isIdentity(layout);
    openvdb::GridBase::Ptr copy = identity ? std::const_pointer_cast<openvdb::GridBase>(
                                                 grid.copyGrid())  // shares the tree
                                           : grid.deepCopyGrid();
    if (!identity) {
        copy->setTransform(
            openvdb::math::Transform::createLinearTransform(matrixOf(grid) * worldToFile(layout)));
        const FieldConversion c = conversionOf(field);
        const double u = centimetresPer(layout.unit);
        const double turn = layout.treeFrame ? -layout.treeFrame->rotation_rad : 0.0;
        convertValues(*copy, c.perLength ? u : 1.0, c.turns ? turn : 0.0);
    }
    if (meta) {
        for (auto it = meta->beginMeta(); it != meta->endMeta(); ++it) {
            copy->insertMeta(it->first, *it->second);
        }
    }
    return copy;
}

openvdb::MetaMap fileMetadata(const TreeGrids& grids, const BakeProvenance& provenance,
                              const FileLayout& layout)
{
    const double u = centimetresPer(layout.unit);
    openvdb::MetaMap meta;
    meta.insertMeta(kFormatVersionKey, openvdb::Int32Metadata(kFormatVersion));
    meta.insertMeta(kUnitsKey, openvdb::StringMetadata(unitName(layout.unit)));
    meta.insertMeta("pine:density_unit",
                    openvdb::StringMetadata(std::string("extinction per ") +
                                            unitName(layout.unit)));
    meta.insertMeta(kFrameKey, openvdb::StringMetadata(layout.treeFrame ? "tree" : "world"));
    if (layout.treeFrame) {
        const Vec3& b = layout.treeFrame->base_cm;
        meta.insertMeta(kTreeBaseKey, openvdb::Vec3DMetadata(openvdb::Vec3d(b.x, b.y, b.z)));
        meta.insertMeta(kTreeRotationKey,
                        openvdb::DoubleMetadata(layout.treeFrame->rotation_rad));
    }
    meta.insertMeta(kExtinctionLawKey, openvdb::StringMetadata(grids.extinctionLaw));
    meta.insertMeta("pine:extinction",
                    openvdb::StringMetadata(extinctionLaw(grids.extinctionLaw).formula()));
    meta.insertMeta(kVoxelSizeKey, openvdb::DoubleMetadata(grids.voxelSize_cm));
    meta.insertMeta("pine:voxel_size", openvdb::DoubleMetadata(grids.voxelSize_cm / u));
    meta.insertMeta("pine:scene", openvdb::StringMetadata(provenance.scene));
    meta.insertMeta("pine:tree", openvdb::Int32Metadata(provenance.tree));
    meta.insertMeta("pine:seed", openvdb::Int64Metadata(openvdb::Int64(provenance.seed)));
    meta.insertMeta("pine:tree_digest", openvdb::StringMetadata(provenance.treeDigest));
    meta.insertMeta("pine:tool_version", openvdb::StringMetadata(PINE_TOOL_VERSION));
    return meta;
}

/// Calls f, turning the shared I/O layer's InputError into this component's BakeError.
template <class F>
void asBakeError(F&& f)
{
    try {
        f();
    } catch (const BakeError&) {
        throw;
    } catch (const InputError& e) {
        throw BakeError(e.what());
    }
}

openvdb::GridBase::Ptr findGrid(const openvdb::GridPtrVec& grids, const std::string& name)
{
    for (const auto& grid : grids) {
        if (grid && grid->getName() == name) return grid;
    }
    return nullptr;
}

/// The layout a file's metadata states; checks what the file says of itself against what this
/// build reads. `verified`: a manifest vouched for the file (else the metadata must say all).
FileLayout checkFileMetadata(const openvdb::MetaMap* meta, const fs::path& path, bool verified)
{
    const auto refuse = [&](const std::string& why) {
        return BakeError("'" + path.string() + "': " + why);
    };
    const auto version = meta ? meta->getMetadata<openvdb::Int32Metadata>(kFormatVersionKey)
                              : nullptr;
    if (!version) {
        throw refuse(verified ? "no " + std::string(kFormatVersionKey) + " (baked before format " +
                                    std::to_string(kFormatVersion) + "?): bake it again"
                              : "no manifest beside it and no " + std::string(kFormatVersionKey) +
                                    " metadata: not a bake (bake/README.md lists the metadata "
                                    "a grid needs to be read)");
    }
    if (version->value() != kFormatVersion) {
        throw refuse("format version " + std::to_string(version->value()) + ", this build reads " +
                     std::to_string(kFormatVersion) + ": bake it again");
    }
    const auto text = [&](const char* key) {
        const auto m = meta->getMetadata<openvdb::StringMetadata>(key);
        if (!m) throw refuse("no " + std::string(key) + " metadata");
        return m->value();
    };
    try {
        extinctionLaw(text(kExtinctionLawKey));
    } catch (const BakeError&) {
        throw;
    } catch (const InputError& e) {
        throw refuse(e.what());
    }
    FileLayout layout;
    const std::string unit = text(kUnitsKey);
    try {
        layout.unit = lengthUnit(unit);
    } catch (const BakeError& e) {
        throw refuse(std::string(kUnitsKey) + ": " + e.what());
    }
    const std::string frame = text(kFrameKey);
    if (frame == "tree") {
        const auto base = meta->getMetadata<openvdb::Vec3DMetadata>(kTreeBaseKey);
        const auto turn = meta->getMetadata<openvdb::DoubleMetadata>(kTreeRotationKey);
        if (!base || !turn) {
            throw refuse(std::string("frame 'tree' without ") + kTreeBaseKey + " and " +
                         kTreeRotationKey);
        }
        const openvdb::Vec3d b = base->value();
        layout.treeFrame = TreeFrame{Vec3(b.x(), b.y(), b.z()), turn->value()};
        if (!std::isfinite(b.x() + b.y() + b.z() + turn->value())) {
            throw refuse("the tree frame is not finite");
        }
    } else if (frame != "world") {
        throw refuse(std::string(kFrameKey) + " '" + frame + "': expected 'world' or 'tree'");
    }
    const auto h = meta->getMetadata<openvdb::DoubleMetadata>(kVoxelSizeKey);
    if (!h || !(std::isfinite(h->value()) && h->value() > 0.0)) {
        throw refuse("no positive " + std::string(kVoxelSizeKey) + " metadata");
    }
    return layout;
}

/// The transform the grids of lattice `h` have in the scene's world: lod k of the pyramid on
/// its coarser lattice (density_pyramid.h).
openvdb::math::Transform::Ptr latticeTransform(double h, int lod)
{
    auto t = openvdb::math::Transform::createLinearTransform(h);
    for (int k = 0; k < lod; ++k) {
        t->preTranslate(openvdb::Vec3d(0.5));
        t->preScale(2.0);
    }
    return t;
}

/// Brings a grid read from a file of `layout` back into the scene's world in cm, on the lattice
/// of `h` (lod k), refusing a transform that is not that lattice in the file's frame.
void intoScene(openvdb::GridBase& grid, Field field, const FileLayout& layout, double h, int lod,
               const fs::path& path)
{
    const auto lattice = latticeTransform(h, lod);
    const openvdb::Mat4d inScene = matrixOf(grid) * worldToFile(layout).inverse();
    const openvdb::Mat4d expected = lattice->baseMap()->getAffineMap()->getMat4();
    double off = 0.0;
    for (int i = 0; i < 4; ++i) {
        for (int j = 0; j < 3; ++j) off = std::max(off, std::abs(inScene[i][j] - expected[i][j]));
    }
    if (!(off <= 1e-6 * h)) {
        char size[32];
        std::snprintf(size, sizeof size, "%g", h);
        throw BakeError("'" + path.string() + "': grid '" + grid.getName() +
                        "' is not on the lattice of " + size +
                        " cm voxels its metadata states (resampled or moved elsewhere?)");
    }
    grid.setTransform(lattice);
    if (isIdentity(layout)) return;
    const FieldConversion c = conversionOf(field);
    const double u = centimetresPer(layout.unit);
    const double turn = layout.treeFrame ? layout.treeFrame->rotation_rad : 0.0;
    convertValues(grid, c.perLength ? 1.0 / u : 1.0, c.turns ? turn : 0.0);
}

}  // namespace

void writeTreeGrids(const TreeGrids& grids, const fs::path& path,
                    const BakeProvenance& provenance, const FileLayout& layout)
{
    openvdb::initialize();
    for (const FieldInfo& info : kFields) {
        if (!grids.grid(info.field)) {
            throw BakeError("cannot write '" + path.string() + "': grid '" + info.name +
                            "' is missing");
        }
    }
    for (const auto& lod : grids.densityPyramid) {
        if (!lod) throw BakeError("cannot write '" + path.string() + "': a pyramid level is null");
    }
    if (layout.treeFrame && !std::isfinite(layout.treeFrame->base_cm.x +
                                           layout.treeFrame->base_cm.y +
                                           layout.treeFrame->base_cm.z +
                                           layout.treeFrame->rotation_rad)) {
        throw BakeError("cannot write '" + path.string() + "': the tree frame is not finite");
    }
    asBakeError([&] { io::checkWritable(path); });

    const openvdb::MetaMap meta = fileMetadata(grids, provenance, layout);
    // In kFields' order, density first: tools that take the first grid (vdb_render) find it.
    openvdb::GridCPtrVec list;
    for (const FieldInfo& info : kFields) {
        list.push_back(forFile(*grids.grid(info.field), info.field, layout,
                               info.field == Field::Density ? &meta : nullptr));
    }
    for (const auto& lod : grids.densityPyramid) {
        list.push_back(forFile(*lod, Field::Density, layout, &meta));
    }

    // Runs writing into this folder take turns: each grid and manifest pair then comes from
    // one run, and the stale temporaries removed here are a killed run's, not a live one's.
    // Isolated: OpenVDB's write runs parallel statistics, and a thread waiting on them must not
    // take up another tree of a caller's parallel loop, which would wait for this lock.
    tbb::this_task_arena::isolate([&] {
        std::optional<io::FolderLock> turn;
        asBakeError([&] { turn.emplace(io::FolderLock::of(path)); });
        io::removeStaleTemporaries(path);
        io::removeStaleTemporaries(detail::manifestPath(path));
        // Written under a temporary name beside the target, synced, then renamed: a crash or an
        // error never leaves a half-written file under the final name (DESIGN.md). The manifest
        // goes in first, accepting both the new grid and the one it replaces, so that a kill
        // between the renames leaves a matching pair; then it is written again for the new grid
        // alone.
        const std::optional<detail::FileDigest> replaced = detail::acceptedDigest(path);
        detail::FileDigest digest;
        asBakeError([&] {
            io::writeAtomically(
                path,
                [&](const fs::path& tmp) {
                    openvdb::io::File file(tmp.string());
                    file.write(list, meta);  // openvdb::Exception derives from std::exception
                    file.close();
                    digest = detail::digestFile(tmp);
                },
                [&] { detail::writeManifest(path, digest, replaced); });
        });
        if (replaced) {
            // A failure here leaves a manifest that still matches the new grid: not an error.
            try {
                detail::writeManifest(path, digest);
            } catch (const BakeError&) {
            }
        }
    });
}

namespace {

/// The grids in `bytes`, read from `path`, checked as readTreeGrids promises, in the scene's
/// world in cm. `verified`: a manifest vouched for the bytes.
ReadGrids parseGrids(const std::string& bytes, const fs::path& path, bool verified)
{
    openvdb::GridPtrVecPtr grids;
    openvdb::MetaMap::Ptr meta;
    try {
        std::istringstream in(bytes, std::ios::binary);
        openvdb::io::Stream stream(in, /*delayLoad=*/false);
        grids = stream.getGrids();
        meta = stream.getMetadata();
    } catch (const std::bad_alloc&) {
        throw;  // the memory limit's answer, not the file's words
    } catch (const std::exception& e) {  // openvdb::Exception among them
        throw BakeError("cannot read '" + path.string() + "': " + e.what());
    }
    if (!grids) throw BakeError("cannot read '" + path.string() + "': no grids");
    // A tool that keeps grids but not the file's metadata (a round trip through another
    // program) leaves the copy bake puts on the density grid.
    if (!meta || !meta->getMetadata<openvdb::Int32Metadata>(kFormatVersionKey)) {
        const openvdb::GridBase::Ptr density = findGrid(*grids, kFields[0].name);
        if (density && density->getMetadata<openvdb::Int32Metadata>(kFormatVersionKey)) {
            meta = std::make_shared<openvdb::MetaMap>(
                static_cast<const openvdb::MetaMap&>(*density));
        }
    }

    const FileLayout layout = checkFileMetadata(meta.get(), path, verified);
    const double h = meta->metaValue<double>(kVoxelSizeKey);

    ReadGrids read;
    TreeGrids& out = read.grids;
    out.extinctionLaw = meta->metaValue<std::string>(kExtinctionLawKey);
    out.voxelSize_cm = h;
    for (const FieldInfo& info : kFields) {
        const openvdb::GridBase::Ptr grid = findGrid(*grids, info.name);
        if (!grid) throw BakeError("'" + path.string() + "': no grid '" + info.name + "'");
        try {
            out.setGrid(info.field, grid);
        } catch (const BakeError& e) {
            throw BakeError("'" + path.string() + "': " + e.what());
        }
        intoScene(*grid, info.field, layout, h, 0, path);
    }
    for (int level = 1;; ++level) {
        const openvdb::GridBase::Ptr grid = findGrid(*grids, densityLodName(level));
        if (!grid) break;
        auto lod = openvdb::gridPtrCast<openvdb::FloatGrid>(grid);
        if (!lod) {
            throw BakeError("'" + path.string() + "': grid '" + densityLodName(level) +
                            "' has type " + grid->type() + ", expected " +
                            openvdb::FloatGrid::gridType());
        }
        intoScene(*lod, Field::Density, layout, h, level, path);
        out.densityPyramid.push_back(lod);
    }
    // What made them, where the file says (a grid from elsewhere may not).
    BakeProvenance& p = read.provenance;
    if (const auto m = meta->getMetadata<openvdb::StringMetadata>("pine:scene")) {
        p.scene = m->value();
    }
    if (const auto m = meta->getMetadata<openvdb::Int32Metadata>("pine:tree")) p.tree = m->value();
    if (const auto m = meta->getMetadata<openvdb::Int64Metadata>("pine:seed")) {
        p.seed = unsigned(m->value());
    }
    if (const auto m = meta->getMetadata<openvdb::StringMetadata>("pine:tree_digest")) {
        p.treeDigest = m->value();
    }
    if (p.tree >= 0) {  // every voxel is that tree's, tiles staying tiles
        out.tree = openvdb::Int32Grid::create(std::make_shared<openvdb::Int32Tree>(
            out.density->tree(), -1, p.tree, openvdb::TopologyCopy()));
        out.tree->setTransform(out.density->transform().copy());
    }
    return read;
}

/// parseGrids, with what OpenVDB throws once the stream is read (a damaged map of zero scale
/// throws ArithmeticError where it is used) refused as the file's.
ReadGrids parseTreeGrids(const std::string& bytes, const fs::path& path, bool verified)
{
    try {
        return parseGrids(bytes, path, verified);
    } catch (const openvdb::Exception& e) {
        throw BakeError("cannot read '" + path.string() + "': " + e.what());
    }
}

}  // namespace

ReadGrids readTreeGrids(const fs::path& path, double maxMemoryBytes)
{
    openvdb::initialize();
    // Refused before OpenVDB sees a byte: a damaged .vdb can crash OpenVDB 10.0.1 (DESIGN.md).
    // A file without a manifest (made or edited in another tool) is read for its metadata.
    std::error_code error;
    const bool verified = fs::exists(detail::manifestPath(path), error);
    const std::string bytes = verified ? detail::readVerified(path) : detail::readWhole(path);
    // A matching manifest says the bytes are those someone wrote, not that OpenVDB survives
    // them (a file edited or produced elsewhere comes with one), so they are parsed first in a
    // child process, its memory limited, where a crash or a runaway allocation is an answer.
    // What a sound file needs: its nodes grow to some hundred times their compressed size
    // (a 32^3 internal node is 400 KB in memory, a few KB on disk); damaged counts ask for
    // gigabytes, or loop for minutes, on a file of kilobytes.
    const double size = double(bytes.size());
    const double limit = maxMemoryBytes > 0.0 ? maxMemoryBytes : defaultMemoryLimit();
    const double soundFileCap = 1024.0 * 1024 * 1024 + 256.0 * size;
    const io::IsolationLimits limits{std::min(limit, soundFileCap), std::round(10.0 + size / 2e6)};
    io::IsolatedOutcome trial;
    try {
        trial = io::runIsolated([&] { (void)parseTreeGrids(bytes, path, verified); }, limits);
    } catch (const std::system_error& e) {
        throw BakeError("cannot read '" + path.string() + "': " + e.what());
    }
    if (trial.kind == io::IsolatedOutcome::Kind::Threw) throw BakeError(trial.why);
    if (!trial.returned()) {
        // Under the caller's limit, a sound file may fail as a damaged one does (OpenVDB
        // aborts or crashes where an allocation fails): say which limit it was.
        const bool outOfMemory = trial.kind == io::IsolatedOutcome::Kind::OutOfMemory;
        const bool crashed = trial.kind == io::IsolatedOutcome::Kind::Crashed;
        const std::string cause =
            limit < soundFileCap && (outOfMemory || crashed)
                ? (outOfMemory ? "" : " within the memory limit of " + formatBytes(limit)) +
                      " (the limit too low for a file of " + formatBytes(size) +
                      ", or the file damaged)"
                : " (damaged?)";
        throw BakeError("cannot read '" + path.string() + "': OpenVDB " + trial.why + " on it" +
                        cause);
    }
    ReadGrids read = parseTreeGrids(bytes, path, verified);
    if (!verified) {
        read.unverified = "no manifest '" + detail::manifestPath(path).filename().string() +
                          "' beside it: read from its metadata alone, unverified";
    }
    return read;
}

}  // namespace pine::bake
