// Voxelizing a tree's boughs: each bough over the cylinder that holds its cones, runs of boughs
// in parallel into grids of their own, merged, then every kept voxel filled from its densest
// bough, scaled to all the boughs' extinction there.
#include "pine/bake/tree_grids.h"

#include "box_opacity.h"
#include "density_pyramid.h"
#include "pine/bake/extinction_law.h"
#include "prepared_bough.h"

#include <openvdb/tools/Composite.h>
#include <openvdb/tools/Prune.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

namespace pine::bake {

namespace {

using detail::extinctionStopping;
using detail::kMeanChordOverSize;
using detail::opacityOver;
using detail::PreparedBough;

/// Which bough a voxel keeps, as one integer so that the runs' grids merge by a plain max
/// (tools::compMax) and the result does not depend on how boughs were split among them:
/// the larger extinction wins (high word: the float's bits, ordered as the floats are for
/// positive values), and of equal ones the bough listed first (low word: ~index).
std::int64_t voxelKey(double meanExtinction, std::size_t bough)
{
    const auto bits = std::bit_cast<std::uint32_t>(float(meanExtinction));
    const auto low = std::uint32_t(0xFFFFFFFFu - std::uint32_t(bough));
    return std::int64_t((std::uint64_t(bits) << 32) | low);
}

std::size_t boughOfKey(std::int64_t key)
{
    return std::size_t(0xFFFFFFFFu - std::uint32_t(std::uint64_t(key) & 0xFFFFFFFFu));
}

/// World position of voxel ijk's centre: the same as Transform::createLinearTransform(h)
/// ->indexToWorld(ijk), which multiplies index by voxel size.
Vec3 voxelCentre(const openvdb::Coord& ijk, double h)
{
    return Vec3(double(ijk.x()) * h, double(ijk.y()) * h, double(ijk.z()) * h);
}

/// Interval [lo, hi] of z (world cm) on the vertical line through (x, y) that lies inside the
/// cylinder holding the bough's region; empty when lo > hi.
struct Interval {
    double lo, hi;
};

/// `columnInside` of the cylinder grown by `margin`: radius R + margin, from -margin to
/// extent + margin along the axis, which holds every point within `margin` of the cylinder.
Interval columnInside(const PreparedBough& b, double x, double y, Interval bounds, double margin)
{
    const double radius = b.radius_cm() + margin;
    const Vec3& a = b.axis();
    const Vec3 c(x - b.base().x, y - b.base().y, -b.base().z);  // q(z) = c + z e_z, from base
    const double ca = c.x * a.x + c.y * a.y + c.z * a.z;
    // Distance to the axis line: |q|^2 - (q.a)^2 <= R^2, a quadratic in z.
    const double a2 = 1.0 - a.z * a.z;
    const double b1 = c.z - ca * a.z;
    const double c0 = c.x * c.x + c.y * c.y + c.z * c.z - ca * ca - radius * radius;
    Interval in = bounds;
    if (a2 > 1e-12) {
        const double disc = b1 * b1 - a2 * c0;
        if (disc < 0.0) return {1.0, 0.0};
        const double root = std::sqrt(disc);
        in.lo = std::max(in.lo, (-b1 - root) / a2);
        in.hi = std::min(in.hi, (-b1 + root) / a2);
    } else if (c0 > 0.0) {
        return {1.0, 0.0};
    }
    // Along the axis: 0 <= q.a = ca + z a_z <= extent.
    if (std::abs(a.z) > 1e-12) {
        double z0 = (-margin - ca) / a.z, z1 = (b.extent_cm() + margin - ca) / a.z;
        if (z0 > z1) std::swap(z0, z1);
        in.lo = std::max(in.lo, z0);
        in.hi = std::min(in.hi, z1);
    } else if (ca < -margin || ca > b.extent_cm() + margin) {
        return {1.0, 0.0};
    }
    return in;
}

/// 64 bits that depend on the arguments alone (splitmix64's finalizer).
std::uint64_t hashBits(std::uint64_t a, std::uint64_t b)
{
    std::uint64_t k = a * 0x9E3779B97F4A7C15ull ^ (b + 0x632BE59BD9B4E019ull);
    k = (k ^ (k >> 30)) * 0xBF58476D1CE4E5B9ull;
    k = (k ^ (k >> 27)) * 0x94D049BB133111EBull;
    return k ^ (k >> 31);
}

/// Point (x, y, z) of voxel ijk's n^3, as an offset from its centre in units of h: the centre
/// for n = 1, else one point in each of the n^3 cells of the box, placed in its cell by a hash
/// of the voxel and the cell. A lattice of points lined up with the voxels', as the centres
/// are, errs the same way all along a branch lined up with it (a disc of radius R holds 3.25
/// R^2 of a square lattice R / 4 apart half a step off its centre, 3.4% more than pi R^2, and
/// 3.06 R^2 of one through its centre, 2.5% less); the hashed points err at random, and their
/// errors cancel over the voxels. They are the same points on every machine and thread.
Vec3 boxPoint(const openvdb::Coord& ijk, int x, int y, int z, int n)
{
    if (n == 1) return Vec3(0.0);
    const std::uint64_t voxel = (std::uint64_t(std::uint32_t(ijk.x())) << 42) ^
                                (std::uint64_t(std::uint32_t(ijk.y())) << 21) ^
                                std::uint64_t(std::uint32_t(ijk.z()));
    const std::uint64_t bits = hashBits(voxel, std::uint64_t((x * 64 + y) * 64 + z));
    const auto unit = [bits](int shift) {  // 21 bits each: [0, 1) in steps of 2^-21
        return double((bits >> shift) & 0x1FFFFFu) * 0x1.0p-21;
    };
    return Vec3((double(x) + unit(0)) / n - 0.5, (double(y) + unit(21)) / n - 0.5,
                (double(z) + unit(42)) / n - 0.5);
}

/// The field that stands for the bough in voxel ijk: at its centre if the bough's region
/// holds it, as it does for every voxel it fills from one point (n = 1); else what the region
/// holds beside the centre, at the same distance from the axis (at most R) and direction.
std::optional<LayerSample> voxelSample(const PreparedBough& b, const openvdb::Coord& ijk, double h)
{
    const Vec3 centre = voxelCentre(ijk, h);
    if (auto s = b.sample(centre)) return s;
    return b.sampleAcross(centre);
}

/// Writes the keys of one bough's voxels, keeping larger keys already there, and adds its
/// extinction to each voxel's sum: the field's at the voxel's centre for n = 1; for n > 1 the
/// extinction whose opacity over the voxel's mean chord l is the mean over its n^3 points
/// (boxPoint) of each point's own, 1 - exp(-sigma_i l), 0 outside the region (box_opacity.h;
/// l = 2h/3). A line across the voxel meets the needles about where it passes, and lets
/// through about exp(-sigma_i l) there, so the voxel lets through as much light as the needles
/// do on average. Where the bough fills the voxel evenly that is its extinction; where it
/// fills part of it, less than its mean (bake/README.md has the forest's numbers).
void voxelizeBough(const PreparedBough& b, std::size_t index, const ExtinctionLaw& law, double h,
                   openvdb::Int64Grid::Accessor& keys, openvdb::FloatGrid::Accessor& sums)
{
    if (b.empty()) return;
    const int n = boxPointsPerEdge(b.radius_cm(), h);
    const double cell = h / n;  // the points' cells: voxel k's are k n + c, c in [0, n)
    const double chord = kMeanChordOverSize * h;
    // A cell whose point is in the region has its centre within half a diagonal of it (for
    // n = 1 the point is the centre).
    const double margin = n == 1 ? 0.0 : 0.5 * std::sqrt(3.0) * cell;
    const Vec3& a = b.axis();
    const Vec3 p0 = b.base() - margin * a, p1 = b.base() + (b.extent_cm() + margin) * a;
    Vec3 lo, hi;
    for (int i = 0; i < 3; ++i) {
        // A cylinder's extent along a world axis: its ends, widened by R sin(angle to axis).
        const double widen = (b.radius_cm() + margin) * std::sqrt(std::max(0.0, 1.0 - a[i] * a[i]));
        lo[i] = std::min(p0[i], p1[i]) - widen;
        hi[i] = std::max(p0[i], p1[i]) + widen;
    }
    // One voxel of slack around the box, one cell at each end of a column's interval: the
    // exact test is sample()'s.
    const auto first = [h](double v) { return int(std::ceil(v / h)) - 1; };
    const auto last = [h](double v) { return int(std::floor(v / h)) + 1; };
    const int k0 = first(lo.z), k1 = last(hi.z);
    std::vector<double> column(std::size_t(k1 - k0 + 1), 0.0);  // per voxel: its points' sum
    for (int i = first(lo.x); i <= last(hi.x); ++i) {
        for (int j = first(lo.y); j <= last(hi.y); ++j) {
            int low = k1 + 1, high = k0 - 1;  // the voxels of this column a point was in
            for (int x = 0; x < n; ++x) {
                for (int y = 0; y < n; ++y) {
                    // The line through the centres of this column of cells.
                    const double cx = double(i) * h + (x + 0.5) * cell - 0.5 * h;
                    const double cy = double(j) * h + (y + 0.5) * cell - 0.5 * h;
                    const Interval z = columnInside(b, cx, cy, {lo.z, hi.z}, margin);
                    if (z.lo > z.hi) continue;
                    // Cell g spans [g cell - h / 2, (g + 1) cell - h / 2] along z.
                    const auto g0 = std::int64_t(std::floor((z.lo + 0.5 * h) / cell)) - 1;
                    const auto g1 = std::int64_t(std::floor((z.hi + 0.5 * h) / cell)) + 1;
                    for (std::int64_t g = std::max(g0, std::int64_t(k0) * n);
                         g <= std::min(g1, std::int64_t(k1) * n + n - 1); ++g) {
                        const auto k = int(g >= 0 ? g / n : -((-g + n - 1) / n));
                        const openvdb::Coord ijk(i, j, k);
                        const auto s =
                            b.sample(voxelCentre(ijk, h) +
                                     h * boxPoint(ijk, x, y, int(g - std::int64_t(k) * n), n));
                        if (!s) continue;
                        const double sigma = law.meanExtinction(*s);
                        column[std::size_t(k - k0)] += n == 1 ? sigma : opacityOver(sigma, chord);
                        low = std::min(low, k);
                        high = std::max(high, k);
                    }
                }
            }
            for (int k = low; k <= high; ++k) {
                double& sum = column[std::size_t(k - k0)];
                const double extinction =
                    n == 1 ? sum : extinctionStopping(sum / (double(n) * n * n), chord);
                sum = 0.0;
                if (!(extinction > 0.0)) continue;
                const openvdb::Coord ijk(i, j, k);
                const std::int64_t key = voxelKey(extinction, index);
                if (key > keys.getValue(ijk)) keys.setValue(ijk, key);
                sums.setValue(ijk, sums.getValue(ijk) + float(extinction));
            }
        }
    }
}

/// Per voxel, the bough it keeps (its key) and the sum of every bough's extinction there.
struct VoxelKeys {
    openvdb::Int64Grid::Ptr keys = openvdb::Int64Grid::create(0);
    openvdb::FloatGrid::Ptr sums = openvdb::FloatGrid::create(0.0f);  // floats: the grids' own
};

/// The boughs voxelized in a fixed number of runs of consecutive boughs (a branch's boughs
/// are neighbours, so a run's grid shares its leaves among them), in parallel, then merged in
/// pairs, (0, 1), (2, 3), ..., and again, to one. The runs depend on the boughs alone, not on
/// the threads, so the sums are added in the same order on every machine (floating-point
/// addition is not associative). Few runs, since each holds leaves of its own: 1,650 runs of
/// 16 boughs took the paper forest's reference at 0.5 cm to 4.1 GiB, 16 runs to 3.3 (3.0
/// GiB before the sums); and a bake of one tree runs on at most 16 threads here.
VoxelKeys voxelKeys(const std::vector<PreparedBough>& boughs, const ExtinctionLaw& law, double h)
{
    constexpr std::size_t kRuns = 16;
    const std::size_t runs = std::min(kRuns, boughs.size());
    if (runs == 0) return {};
    std::vector<VoxelKeys> partial(runs);
    tbb::parallel_for(std::size_t(0), runs, [&](std::size_t run) {
        auto keys = partial[run].keys->getAccessor();
        auto sums = partial[run].sums->getAccessor();
        const std::size_t end = (run + 1) * boughs.size() / runs;
        for (std::size_t b = run * boughs.size() / runs; b < end; ++b) {
            voxelizeBough(boughs[b], b, law, h, keys, sums);
        }
    });
    for (std::size_t step = 1; step < runs; step *= 2) {
        tbb::parallel_for(std::size_t(0), (runs + 2 * step - 1) / (2 * step), [&](std::size_t i) {
            const std::size_t into = 2 * step * i, from = into + step;
            if (from >= runs) return;
            openvdb::tools::compMax(*partial[into].keys, *partial[from].keys);
            openvdb::tools::compSum(*partial[into].sums, *partial[from].sums);
            partial[from] = VoxelKeys{nullptr, nullptr};  // freed as soon as merged
        });
    }
    return std::move(partial.front());
}

/// An empty grid of `info`'s type, named and described as kFields says.
openvdb::GridBase::Ptr makeGrid(const FieldInfo& info, const openvdb::math::Transform::Ptr& xform)
{
    openvdb::GridBase::Ptr grid;
    if (info.vector) {
        grid = openvdb::Vec3SGrid::create(openvdb::Vec3s(0.0f));
        grid->setVectorType(info.vectorType);
        grid->setIsInWorldSpace(true);
    } else {
        grid = openvdb::FloatGrid::create(0.0f);
    }
    grid->setName(info.name);
    grid->setTransform(xform);
    return grid;
}

}  // namespace

int boxPointsPerEdge(double boughRadius_cm, double voxelSize_cm)
{
    // Read at its centre alone, a voxel wider than R / 4 misses or doubles whole rows of a
    // bough: a straight branch whose axis ran through voxel centres kept 0.73 of its
    // extinction at 1 cm and nothing at 2 cm, a fir lost 1.4% at 2 cm and 4.8% at 4 cm. With
    // one point in each cell at most R / 4 wide (up to h = 8R), a bake samples about as many
    // points as one at R / 4, whatever its voxel size (MassOfALongBoughMatchesTheIntegral
    // holds the centres to the mass down to there; the 1e-9 keeps h = R / 4 on them).
    constexpr double kMostSpacingOverRadius = 0.25;
    constexpr int kMost = 32;  // 32^3 points a voxel, for voxels 8 R wide and more
    const double n = std::ceil(voxelSize_cm / (kMostSpacingOverRadius * boughRadius_cm) - 1e-9);
    return n > 1.0 ? int(std::min(n, double(kMost))) : 1;  // 1 for a NaN radius too
}

void checkVoxelSize(double voxelSize_cm)
{
    constexpr double kMost_cm = 1e5;
    if (!(std::isfinite(voxelSize_cm) && voxelSize_cm > 0.0 && voxelSize_cm <= kMost_cm)) {
        std::ostringstream why;
        why << "voxel size must be > 0 and at most " << kMost_cm << " cm (a kilometre), got "
            << voxelSize_cm;
        throw BakeError(why.str());
    }
}

TreeGrids bakeBoughs(const std::vector<BoughSpec>& boughs, const BakeSettings& settings)
{
    openvdb::initialize();
    const double h = settings.voxelSize_cm;
    checkVoxelSize(h);
    if (settings.pyramidLevels < 1 || settings.pyramidLevels > 16) {
        throw BakeError("pyramid levels must be in [1, 16], got " +
                        std::to_string(settings.pyramidLevels));
    }
    if (boughs.size() >= 0xFFFFFFFFu) throw BakeError("too many boughs to bake");
    std::vector<PreparedBough> prepared;
    prepared.reserve(boughs.size());
    for (std::size_t i = 0; i < boughs.size(); ++i) {
        prepared.emplace_back(boughs[i]);
        if (const char* why = prepared.back().invalidReason()) {
            throw BakeError("baking bough " + std::to_string(i) + ": " + why);
        }
    }

    const ExtinctionLaw& law = extinctionLaw(settings.extinctionLaw);
    const VoxelKeys kept = voxelKeys(prepared, law, h);
    const openvdb::Int64Grid::Ptr& keys = kept.keys;
    const auto sums = kept.sums->getConstAccessor();

    TreeGrids out;
    out.voxelSize_cm = h;
    out.extinctionLaw = settings.extinctionLaw;
    const auto xform = openvdb::math::Transform::createLinearTransform(h);
    for (const FieldInfo& info : kFields) out.setGrid(info.field, makeGrid(info, xform));

    // Each kept voxel, filled from its bough's field at the voxel's centre (voxelSample). Where
    // boughs overlap, their needles are all there (a bough's region holds only the needles of
    // its own cones, so a chain's boughs do not overlap): the density is the sum of their
    // extinctions, and the layered fields, which hold one bough's layers, are the densest
    // bough's with its layer gradient scaled by the sum over its own mean. Every law is linear
    // in |layer_gradient| (layers per cm), so the reference meets the summed extinction there.
    // (In a voxel wider than R / 4, boughs that fill disjoint parts of it are summed as if they
    // overlapped: parts p and q of opacities a and b let through (1 - pa)(1 - qb), not 1 - pa
    // - qb; bake/README.md.) Per direction
    // it keeps the densest bough's anisotropy (its needles' and layers' directions), and under
    // the banded law each band meets as many needles, the bands being more.
    auto density = out.density->getAccessor();
    auto gradient = out.layerGradient->getAccessor();
    auto opacity = out.layerOpacity->getAccessor();
    auto needle = out.needleDirection->getAccessor();
    auto coverage = out.needleCoverage->getAccessor();
    auto albedo = out.needleAlbedo->getAccessor();
    const bool treesKnown =
        std::any_of(boughs.begin(), boughs.end(), [](const BoughSpec& b) { return b.tree >= 0; });
    if (treesKnown) {
        out.tree = openvdb::Int32Grid::create(-1);
        out.tree->setTransform(xform->copy());
    }
    std::optional<openvdb::Int32Grid::Accessor> tree;
    if (treesKnown) tree = out.tree->getAccessor();
    for (auto it = keys->cbeginValueOn(); it; ++it) {
        const openvdb::Coord ijk = it.getCoord();
        const std::size_t b = boughOfKey(*it);
        auto s = voxelSample(prepared[b], ijk, h);
        if (!s) continue;  // cannot happen: the bough, which wrote the key, is not empty
        // A voxel read at its centre, of one bough, sums its own mean rounded to a float (as the
        // density always was): then the sample is kept exactly, as is a sum that others change
        // by less than a float can. A box's (n > 1) is its opacity's extinction, so rescaled.
        const double own = law.meanExtinction(*s);
        const float sum = sums.getValue(ijk);
        if (sum != float(own)) s->gradient *= double(sum) / own;
        const auto vec = [](const Vec3& v) {
            return openvdb::Vec3s(float(v.x), float(v.y), float(v.z));
        };
        density.setValue(ijk, float(law.meanExtinction(*s)));
        gradient.setValue(ijk, vec(s->gradient));
        opacity.setValue(ijk, float(s->layerOpacity));
        needle.setValue(ijk, vec(s->needle));
        coverage.setValue(ijk, float(s->needleCoverage));
        albedo.setValue(ijk, vec(boughs[b].needleAlbedo));
        if (tree) tree->setValue(ijk, boughs[b].tree);
    }

    openvdb::tools::prune(out.density->tree());
    openvdb::tools::prune(out.layerOpacity->tree());
    openvdb::tools::prune(out.needleAlbedo->tree());
    if (out.tree) openvdb::tools::prune(out.tree->tree());

    openvdb::FloatGrid::Ptr previous = out.density;
    for (int level = 1; level < settings.pyramidLevels; ++level) {
        openvdb::FloatGrid::Ptr coarse = detail::halveResolution(*previous);
        coarse->setName(densityLodName(level));
        openvdb::tools::prune(coarse->tree());
        out.densityPyramid.push_back(coarse);
        previous = coarse;
    }
    return out;
}

}  // namespace pine::bake
