// A tree's baked proxy: OpenVDB grids of its boughs' layer field, written so that other tools
// open them (vdb_print, vdb_render, Houdini, Blender) and so that a damaged file is refused
// before OpenVDB reads it (DESIGN.md).
#pragma once

#include "pine/bake/layer_field.h"
#include "pine/support/input_error.h"

#include <openvdb/openvdb.h>

#include <filesystem>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

namespace pine::bake {

/// What bake throws: always about the user's input or output (a bough, a setting, a file).
class BakeError : public InputError {
public:
    using InputError::InputError;
};

/// The fields a bake writes, in the file's order: density first, so that tools that take the
/// first grid (vdb_render) find it.
enum class Field {
    Density,
    LayerGradient,
    LayerOpacity,
    NeedleDirection,
    NeedleCoverage,
    NeedleAlbedo
};

struct FieldInfo {
    Field field;
    const char* name;  ///< the grid's name in the file
    bool vector;       ///< a Vec3SGrid (in world space), else a FloatGrid
    /// How a tool must transform the vectors with the grid: G = grad g / dh is a gradient
    /// (covariant: by the inverse transpose), the needle a direction (contravariant), the
    /// albedo a colour (invariant).
    openvdb::VecType vectorType;
    const char* meaning;
};

/// The table bake, write, read and merge loop over.
inline constexpr FieldInfo kFields[] = {
    {Field::Density, "density", false, openvdb::VEC_INVARIANT,
     "mean extinction over directions, per world unit (pine:units)"},
    {Field::LayerGradient, "layer_gradient", true, openvdb::VEC_COVARIANT,
     "G = grad g / dh, layers crossed per world unit along each axis"},
    {Field::LayerOpacity, "layer_opacity", false, openvdb::VEC_INVARIANT,
     "A = 2 N r / (pi R), the opacity of one layer"},
    {Field::NeedleDirection, "needle_direction", true, openvdb::VEC_CONTRAVARIANT_RELATIVE,
     "unit needle direction, cos(phi) axis + sin(phi) radial"},
    {Field::NeedleCoverage, "needle_coverage", false, openvdb::VEC_INVARIANT,
     "min(1, N r / (pi rho)): the needles' coverage of their cone there (fibre law)"},
    {Field::NeedleAlbedo, "color", true, openvdb::VEC_INVARIANT,
     "needle albedo, linear RGB (Blender's color, Houdini's Cd)"},
};

/// The name of density pyramid level `level` >= 1, as vdb_lod names its levels
/// ("density_level_1", ...).
inline std::string densityLodName(int level)
{
    return std::string(kFields[0].name) + "_level_" + std::to_string(level);
}

/// The layout of what writeTreeGrids writes (pine:format_version); readTreeGrids refuses
/// another. 2: the first with a version and an extinction law by name; 3: needle_coverage;
/// 4: density as extinction per world unit, `color`, vdb_lod's level names, units and frames.
inline constexpr int kFormatVersion = 4;

struct BakeSettings {
    double voxelSize_cm = 0.5;
    int pyramidLevels = 3;  ///< density at voxel sizes h, 2h, 4h, ...: "density_level_1", ...
    std::string extinctionLaw = "fibre";  ///< a name of extinctionLawNames()
};

/// A tree's grids in world space (cm), all on one transform of voxel size h, voxels sampled at
/// their centres. Density is the mean extinction, per cm, summed over the boughs that overlap
/// a voxel; the other fields are the densest of them, its layer gradient scaled so that its
/// extinction is that sum.
struct TreeGrids {
    openvdb::FloatGrid::Ptr density;
    openvdb::Vec3SGrid::Ptr layerGradient;
    openvdb::FloatGrid::Ptr layerOpacity;
    openvdb::Vec3SGrid::Ptr needleDirection;
    openvdb::FloatGrid::Ptr needleCoverage;
    openvdb::Vec3SGrid::Ptr needleAlbedo;
    /// Coarser densities, lod 1, 2, ...: lod k has voxels of 2^k h, each the mean of its 8
    /// children, centred on their mean centre (its own transform, shifted by (2^k - 1) h / 2).
    std::vector<openvdb::FloatGrid::Ptr> densityPyramid;
    /// Per voxel the scene's tree whose layered fields the voxel keeps: its densest bough's
    /// (BoughSpec::tree; -1 for a bough naming none), or where mergeTreeGrids meets trees the
    /// denser of the next tree and those before it summed; background -1, null if no bough or
    /// file names a tree. A voxel's whole extinction counts for that tree, so where crowns
    /// share voxels a per-tree sum gives the neighbour's share to it. Held in memory only,
    /// never written: each file is one tree's and says which (pine:tree).
    openvdb::Int32Grid::Ptr tree;
    double voxelSize_cm = 0.5;
    std::string extinctionLaw = "fibre";  ///< the law density was made with, and sigma's

    /// The grid of a field of kFields, untyped (null if not set).
    openvdb::GridBase::Ptr grid(Field field) const;
    /// Sets the grid of a field; throws BakeError unless it has the field's type.
    void setGrid(Field field, const openvdb::GridBase::Ptr& grid);
};

/// The voxels OpenVDB holds for grids of g's topology (its layer opacity's): each leaf's 8^3
/// whole, however few of them are active, and the voxels of its active tiles, which a grid made
/// from it allocates once voxelized (the reference's light grids are).
double allocatedVoxels(const TreeGrids& g);

/// Throws BakeError unless `voxelSize_cm` is > 0 and at most a kilometre (a voxel that holds
/// whole forests as one value; near 1e308 OpenVDB cannot invert its transform).
void checkVoxelSize(double voxelSize_cm);

/// Points per voxel edge at which the bake averages a bough of radius R = l sin(phi) over a
/// voxel's box: 1 (the voxel's centre alone) while the voxel is at most R / 4 wide, else
/// ceil(h / (R / 4)), at most 32. Where it is more than 1, every voxel that one of the points
/// of a bough's region falls in is filled: the bough's voxels reach about half a voxel (up to
/// half a diagonal) further than their centres do.
int boxPointsPerEdge(double boughRadius_cm, double voxelSize_cm);

/// Voxelizes the boughs (not the branches: the tracers draw those as cylinders). Each voxel
/// holds a bough's extinction at its centre, or over its box (boxPointsPerEdge: the extinction
/// whose opacity over its mean chord 2h/3 is its points' mean opacity), and where boughs overlap
/// their sum (bake/README.md); `tree` where any bough names its tree. Boughs are
/// split among TBB threads; the result does not depend on the split (ties keep the bough listed
/// first). Throws BakeError for a voxel size checkVoxelSize refuses, pyramid levels
/// outside [1, 16], or a bough outside its domain (non-finite, phi outside (0, pi/2], a
/// negative size, dh <= 0); zero-size boughs bake to nothing.
TreeGrids bakeBoughs(const std::vector<BoughSpec>& boughs, const BakeSettings& settings);

/// File metadata: what made the grids.
struct BakeProvenance {
    std::string scene;
    int tree = -1;
    unsigned seed = 0;
    /// treeDigest of the boughs baked: a render refuses grids of another tree (empty: unknown).
    std::string treeDigest;
};

/// A length unit of a file's world space (pine:units): Blender and Houdini scenes are in
/// metres, the scene format in cm.
enum class LengthUnit { Centimetre, Metre };

/// "cm" or "m"; lengthUnit throws BakeError for another name.
const char* unitName(LengthUnit unit);
LengthUnit lengthUnit(const std::string& name);
inline double centimetresPer(LengthUnit unit)
{
    return unit == LengthUnit::Metre ? 100.0 : 1.0;
}

/// Where a tree stands in its scene: the origin of its own frame at its base, and its rotation
/// about z (scenes::TreePlacement).
struct TreeFrame {
    Vec3 base_cm{0.0};
    double rotation_rad = 0.0;
};

/// How a file lays out the grids: its unit and frame. In the tree's frame the grids' transform
/// maps the scene's voxel lattice into the tree's frame (so a tool finds the tree at its origin,
/// upright, and a render maps it back onto the scene's lattice voxel for voxel), vectors turned
/// with it; lengths, extinction and layers per length in `unit`.
struct FileLayout {
    LengthUnit unit = LengthUnit::Metre;
    std::optional<TreeFrame> treeFrame;  ///< empty: the scene's world frame
};

/// The affine map from the scene's world (cm) into the world of a file laid out as `layout`,
/// as OpenVDB composes maps: row vectors, p' = p M, the translation in the last row.
openvdb::Mat4d worldToFile(const FileLayout& layout);

/// Writes the grids atomically (temporary file in the same folder, synced, then renamed) with
/// file metadata (format version, units, frame, extinction law and its formula, voxel size,
/// scene, tree, seed, tree digest, tool version) and a manifest `PATH.json` beside it recording
/// the file's size and checksum, put in place before the grid (accepting the grid it replaces
/// too, until the grid is renamed): if writing either fails or the bake is killed, a grid under
/// its final name matches its manifest. Runs writing into one folder take turns
/// (io::FolderLock). Removes the temporaries of a killed earlier write first. Throws BakeError.
void writeTreeGrids(const TreeGrids& grids, const std::filesystem::path& path,
                    const BakeProvenance& provenance, const FileLayout& layout = {});

/// What readTreeGrids found: the grids in the scene's world space (cm), what made them, and
/// whether a manifest vouched for the bytes. grids.tree names the file's tree (pine:tree) over
/// every voxel, where the file names one.
struct ReadGrids {
    TreeGrids grids;
    BakeProvenance provenance;
    /// Empty when a manifest matched; else why the grids are unverified (read from their
    /// metadata alone: a grid made or edited in another tool).
    std::string unverified;
};

/// Reads grids written by writeTreeGrids, back in the scene's world space in cm whatever their
/// unit and frame. With a manifest beside it, the file must match its size and checksum
/// (a damaged file is refused with BakeError, never opened by OpenVDB); without one, it is
/// read if its metadata says what it holds (format version, units, frame, extinction law) and
/// marked unverified, else refused. Refuses a file of another format version, of an extinction
/// law not registered here, or missing a field. Also catches what OpenVDB throws. The bytes are
/// parsed first in a child process with at most `maxMemoryBytes` (0: defaultMemoryLimit()),
/// 1 GiB plus 256 times the file's size and 10 s plus 1 s per 2 MB: where OpenVDB crashes,
/// hangs or runs out of memory on them, BakeError says so. Call it before parallel work.
ReadGrids readTreeGrids(const std::filesystem::path& path, double maxMemoryBytes = 0.0);

}  // namespace pine::bake

namespace pine::bake {

/// The grids of several trees as one set (what a renderer marches through): all must share a
/// voxel size (BakeError otherwise); where two overlap, their densities add and the denser
/// tree's layered fields stay, scaled to the sum, as overlapping boughs within a tree do. So
/// the same trees baked as one set have the same density (to float rounding), and the same
/// fields wherever crowns do not overlap; where they do, the fields are the denser tree's,
/// not the densest bough's. The density pyramid is not merged.
TreeGrids mergeTreeGrids(const std::vector<TreeGrids>& trees);

}  // namespace pine::bake
