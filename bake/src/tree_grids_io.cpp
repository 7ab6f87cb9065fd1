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

namespace {

constexpr const char* kDensityScaleKey = "pine:density_scale_per_cm";
constexpr const char* kFormatVersionKey = "pine:format_version";
constexpr const char* kExtinctionLawKey = "pine:extinction_law";

openvdb::MetaMap fileMetadata(const TreeGrids& grids, const BakeProvenance& provenance)
{
    openvdb::MetaMap meta;
    meta.insertMeta(kFormatVersionKey, openvdb::Int32Metadata(kFormatVersion));
    meta.insertMeta("pine:units", openvdb::StringMetadata("cm"));
    meta.insertMeta(kExtinctionLawKey, openvdb::StringMetadata(grids.extinctionLaw));
    meta.insertMeta("pine:extinction",
                    openvdb::StringMetadata(extinctionLaw(grids.extinctionLaw).formula()));
    meta.insertMeta("pine:voxel_size_cm", openvdb::DoubleMetadata(grids.voxelSize_cm));
    meta.insertMeta("pine:scene", openvdb::StringMetadata(provenance.scene));
    meta.insertMeta("pine:tree", openvdb::Int32Metadata(provenance.tree));
    meta.insertMeta("pine:seed", openvdb::Int64Metadata(openvdb::Int64(provenance.seed)));
    meta.insertMeta("pine:tool_version", openvdb::StringMetadata(PINE_TOOL_VERSION));
    return meta;
}

/// A density grid as written: sharing the caller's tree, with the scale (and, for tools that
/// show only grid metadata, the file's metadata) on the grid.
openvdb::GridBase::Ptr densityForWriting(const openvdb::FloatGrid& grid, double scale_per_cm,
                                         const openvdb::MetaMap& fileMeta)
{
    // A shallow copy (the tree is shared, not copied); only its metadata is changed.
    openvdb::GridBase::Ptr copy = std::const_pointer_cast<openvdb::GridBase>(grid.copyGrid());
    for (auto it = fileMeta.beginMeta(); it != fileMeta.endMeta(); ++it) {
        copy->insertMeta(it->first, *it->second);
    }
    copy->insertMeta(kDensityScaleKey, openvdb::DoubleMetadata(scale_per_cm));
    return copy;
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

/// Checks what the file says of itself against what this build reads.
void checkFileMetadata(const openvdb::MetaMap* meta, const fs::path& path)
{
    const auto refuse = [&](const std::string& why) {
        return BakeError("'" + path.string() + "': " + why);
    };
    const auto version = meta ? meta->getMetadata<openvdb::Int32Metadata>(kFormatVersionKey)
                              : nullptr;
    if (!version) {
        throw refuse("no " + std::string(kFormatVersionKey) + " (baked before format " +
                     std::to_string(kFormatVersion) + "?): bake it again");
    }
    if (version->value() != kFormatVersion) {
        throw refuse("format version " + std::to_string(version->value()) + ", this build reads " +
                     std::to_string(kFormatVersion) + ": bake it again");
    }
    const auto law = meta->getMetadata<openvdb::StringMetadata>(kExtinctionLawKey);
    if (!law) throw refuse("no " + std::string(kExtinctionLawKey));
    try {
        extinctionLaw(law->value());
    } catch (const InputError& e) {
        throw refuse(e.what());
    }
}

}  // namespace

void writeTreeGrids(const TreeGrids& grids, const fs::path& path,
                    const BakeProvenance& provenance)
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
    asBakeError([&] { io::checkWritable(path); });

    const openvdb::MetaMap meta = fileMetadata(grids, provenance);
    // In kFields' order, density first: tools that take the first grid (vdb_render) find it.
    openvdb::GridCPtrVec list;
    for (const FieldInfo& info : kFields) {
        list.push_back(info.field == Field::Density
                           ? densityForWriting(*grids.density, grids.densityScale_per_cm, meta)
                           : grids.grid(info.field));
    }
    for (const auto& lod : grids.densityPyramid) {
        list.push_back(densityForWriting(*lod, grids.densityScale_per_cm, meta));
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

/// The grids in `bytes`, read from `path`, checked as readTreeGrids promises.
TreeGrids parseTreeGrids(const std::string& bytes, const fs::path& path)
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

    checkFileMetadata(meta.get(), path);

    TreeGrids out;
    out.extinctionLaw = meta->metaValue<std::string>(kExtinctionLawKey);
    for (const FieldInfo& info : kFields) {
        const openvdb::GridBase::Ptr grid = findGrid(*grids, info.name);
        if (!grid) throw BakeError("'" + path.string() + "': no grid '" + info.name + "'");
        try {
            out.setGrid(info.field, grid);
        } catch (const BakeError& e) {
            throw BakeError("'" + path.string() + "': " + e.what());
        }
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
        out.densityPyramid.push_back(lod);
    }
    const auto scale = out.density->getMetadata<openvdb::DoubleMetadata>(kDensityScaleKey);
    if (!scale) {
        throw BakeError("'" + path.string() + "': density lacks metadata " +
                        std::string(kDensityScaleKey));
    }
    out.densityScale_per_cm = scale->value();
    out.voxelSize_cm = out.density->voxelSize()[0];
    return out;
}

}  // namespace

TreeGrids readTreeGrids(const fs::path& path, double maxMemoryBytes)
{
    openvdb::initialize();
    // Refused before OpenVDB sees a byte: a damaged .vdb can crash OpenVDB 10.0.1 (DESIGN.md).
    const std::string bytes = detail::readVerified(path);
    // A matching manifest says the bytes are those someone wrote, not that OpenVDB survives
    // them (a file edited or produced elsewhere comes with one), so they are parsed first in a
    // child process, its memory limited, where a crash or a runaway allocation is an answer.
    // What a sound file needs: its nodes grow to some hundred times their compressed size
    // (a 32^3 internal node is 400 KB in memory, a few KB on disk); damaged counts ask for
    // gigabytes, or loop for minutes, on a file of kilobytes.
    const double size = double(bytes.size());
    const double limit = maxMemoryBytes > 0.0 ? maxMemoryBytes : defaultMemoryLimit();
    const io::IsolationLimits limits{std::min(limit, 1024.0 * 1024 * 1024 + 256.0 * size),
                                     std::round(10.0 + size / 2e6)};
    io::IsolatedOutcome trial;
    try {
        trial = io::runIsolated([&] { (void)parseTreeGrids(bytes, path); }, limits);
    } catch (const std::system_error& e) {
        throw BakeError("cannot read '" + path.string() + "': " + e.what());
    }
    if (trial.kind == io::IsolatedOutcome::Kind::Threw) throw BakeError(trial.why);
    if (!trial.returned()) {
        throw BakeError("cannot read '" + path.string() + "': OpenVDB " + trial.why +
                        " on it (damaged?)");
    }
    return parseTreeGrids(bytes, path);
}

}  // namespace pine::bake
