// Writing and reading a tree's grids: OpenVDB files that third-party tools open, with their
// provenance, written atomically and checked against their manifest before being parsed.
#include "pine/bake/tree_grids.h"

#include "manifest.h"

#include <openvdb/io/Stream.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <sstream>

#ifndef PINE_TOOL_VERSION
#define PINE_TOOL_VERSION "unknown"
#endif

namespace pine::bake {

namespace fs = std::filesystem;

namespace {

constexpr const char* kDensityScaleKey = "pine:density_scale_per_cm";
constexpr const char* kExtinction =
    "sigma(d) = -ln(1 - layer_opacity) |d . layer_gradient| per cm; "
    "density = mean extinction / pine:density_scale_per_cm";

openvdb::MetaMap fileMetadata(const TreeGrids& grids, const BakeProvenance& provenance)
{
    openvdb::MetaMap meta;
    meta.insertMeta("pine:units", openvdb::StringMetadata("cm"));
    meta.insertMeta("pine:extinction", openvdb::StringMetadata(kExtinction));
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

template <class GridT>
typename GridT::Ptr findGrid(const openvdb::GridPtrVec& grids, const std::string& name,
                             const fs::path& path, bool required)
{
    for (const auto& grid : grids) {
        if (grid && grid->getName() == name) {
            if (auto typed = openvdb::gridPtrCast<GridT>(grid)) return typed;
            throw BakeError("'" + path.string() + "': grid '" + name + "' has type " +
                            grid->type() + ", expected " + GridT::gridType());
        }
    }
    if (required) throw BakeError("'" + path.string() + "': no grid '" + name + "'");
    return nullptr;
}

}  // namespace

void checkWritable(const fs::path& file)
{
    const auto refuse = [&](const std::string& why) {
        return BakeError("cannot write '" + file.string() + "': " + why);
    };
    if (file.empty() || !file.has_filename()) throw refuse("no file name");
    std::error_code error;
    if (fs::is_directory(file, error)) throw refuse("it is a folder");
    const fs::path folder = file.has_parent_path() ? file.parent_path() : fs::path(".");
    if (!fs::is_directory(folder, error)) {
        throw refuse("folder '" + folder.string() + "' is missing");
    }
    // Permission bits do not tell the whole story (read-only mounts, ACLs, root): try it.
    const fs::path probe = detail::temporaryBeside(file);
    std::FILE* f = std::fopen(probe.c_str(), "wx");
    if (!f) {
        throw refuse("folder '" + folder.string() + "' is not writable: " + std::strerror(errno));
    }
    std::fclose(f);
    fs::remove(probe, error);
}

void writeTreeGrids(const TreeGrids& grids, const fs::path& path,
                    const BakeProvenance& provenance)
{
    openvdb::initialize();
    if (!grids.density || !grids.layerGradient || !grids.layerOpacity || !grids.needleDirection ||
        !grids.needleAlbedo) {
        throw BakeError("cannot write '" + path.string() + "': a grid is missing");
    }
    for (const auto& lod : grids.densityPyramid) {
        if (!lod) throw BakeError("cannot write '" + path.string() + "': a pyramid level is null");
    }
    checkWritable(path);

    const openvdb::MetaMap meta = fileMetadata(grids, provenance);
    // Density first: tools that take the first grid (vdb_render) find it.
    openvdb::GridCPtrVec list = {
        densityForWriting(*grids.density, grids.densityScale_per_cm, meta),
        grids.layerGradient, grids.layerOpacity, grids.needleDirection, grids.needleAlbedo};
    for (const auto& lod : grids.densityPyramid) {
        list.push_back(densityForWriting(*lod, grids.densityScale_per_cm, meta));
    }

    // Written under a temporary name beside the target, then renamed: a crash or an error never
    // leaves a half-written file under the final name (DESIGN.md).
    const fs::path tmp = detail::temporaryBeside(path);
    std::error_code error;
    try {
        openvdb::io::File file(tmp.string());
        file.write(list, meta);
        file.close();
    } catch (const std::exception& e) {  // openvdb::Exception derives from std::exception
        fs::remove(tmp, error);
        throw BakeError("cannot write '" + path.string() + "': " + e.what());
    }
    detail::FileDigest digest;
    try {
        digest = detail::digestFile(tmp);
    } catch (...) {
        fs::remove(tmp, error);
        throw;
    }
    fs::rename(tmp, path, error);
    if (error) {
        const std::string why = error.message();
        fs::remove(tmp, error);
        throw BakeError("cannot write '" + path.string() + "': " + why);
    }
    detail::writeManifest(path, digest);
}

TreeGrids readTreeGrids(const fs::path& path)
{
    openvdb::initialize();
    // Refused before OpenVDB sees a byte: a damaged .vdb can crash OpenVDB 10.0.1 (DESIGN.md).
    const std::string bytes = detail::readVerified(path);

    openvdb::GridPtrVecPtr grids;
    try {
        std::istringstream in(bytes, std::ios::binary);
        openvdb::io::Stream stream(in, /*delayLoad=*/false);
        grids = stream.getGrids();
    } catch (const openvdb::Exception& e) {
        throw BakeError("cannot read '" + path.string() + "': " + e.what());
    } catch (const std::exception& e) {
        throw BakeError("cannot read '" + path.string() + "': " + e.what());
    }
    if (!grids) throw BakeError("cannot read '" + path.string() + "': no grids");

    TreeGrids out;
    out.density = findGrid<openvdb::FloatGrid>(*grids, grid_names::kDensity, path, true);
    out.layerGradient =
        findGrid<openvdb::Vec3SGrid>(*grids, grid_names::kLayerGradient, path, true);
    out.layerOpacity = findGrid<openvdb::FloatGrid>(*grids, grid_names::kLayerOpacity, path, true);
    out.needleDirection =
        findGrid<openvdb::Vec3SGrid>(*grids, grid_names::kNeedleDirection, path, true);
    out.needleAlbedo = findGrid<openvdb::Vec3SGrid>(*grids, grid_names::kNeedleAlbedo, path, true);
    for (int level = 1;; ++level) {
        const std::string name =
            std::string(grid_names::kDensity) + "_lod" + std::to_string(level);
        auto lod = findGrid<openvdb::FloatGrid>(*grids, name, path, false);
        if (!lod) break;
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

}  // namespace pine::bake
