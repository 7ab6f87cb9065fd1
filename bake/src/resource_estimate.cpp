#include "pine/bake/resource_estimate.h"

#include "pine/analytic/cone_shader.h"
#include "pine/bake/tree_boughs.h"
#include "pine/scenes/tree.h"
#include "pine/support/input_error.h"

#include <unistd.h>
#include <glm/common.hpp>
#include <glm/geometric.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <map>
#include <unordered_set>
#include <vector>

namespace pine::bake {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kGiB = 1024.0 * 1024.0 * 1024.0;

// Bytes per item, from the peaks of `vdbtrace render` measured 2026-12-04 (the paper forest,
// its 1280 firs and the 10,000-fir landscape; docs/architecture.md, "Memory"): an image pixel
// with its AOVs, the EXR's interleaved copy and the previews; a branch or bough as the tracer
// holds it (its record, its share of the BVH, a bough's law evaluation); a bough's law
// profiles (multiscale: the view of level 3, 790 bytes with one light, and the opacity seen
// from each light, 200: the stats' law_profiles count them); a bough of a grown tree, held by
// every method until the boughs are made (its tree's segments and boughs: 155 bytes a bough on
// the paper's fir, 165 with a margin for the allocations; 20,000 firs without variants, all
// grown, peaked at 4.03 GiB where the other parts sum to 3.23); a needle cylinder with Embree's
// BVH; a voxel of the six grids and a light grid.
constexpr double kBytesPerPixel = 96.0;
constexpr double kBytesPerBranch = 110.0;
constexpr double kBytesPerBough = 380.0;
constexpr double kBytesPerBoughView = 800.0, kBytesPerBoughLight = 200.0;
constexpr double kBytesPerGrownBough = 165.0;
// A directional light's shadow columns, per branch or bough (64 on the paper forest, 59 since
// their entries say which cell is a primitive's first; the bound kept), made only within
// kShadowColumnsMax_bytes.
constexpr double kBytesPerColumnPrimitive = 64.0;
constexpr double kBytesPerNeedle = 140.0;
// A voxel's place in a leaf (OpenVDB allocates a leaf's 8^3 values whole, and a thin bough fills
// few of them: the paper forest's leaves hold 101 voxels at 0.5 cm, 55 at 1 cm, 33 at 2 cm):
// the six grids (48 bytes), the bake's keys and sums (12), each light's grid (8). Measured
// 2026-12-06, the paper forest's reference peaked at 876 MiB at 1 cm and 3.3 GiB at 0.5 cm
// (23,375 and 102,785 leaves), about 30 KB a leaf beside the rest; counting voxels as if
// they filled their leaves had estimated 426 MiB and 1.9 GiB.
constexpr double kBytesPerVoxel = 60.0, kBytesPerVoxelLight = 8.0;
// Of them, the grids a bake's file holds: what `render --grids` reads.
constexpr double kBytesPerVoxelGrids = 48.0;
// A render's bake also names each voxel's tree (TreeGrids::tree, an int).
constexpr double kBytesPerVoxelTree = 4.0;
// A bake written in metres or in a tree's frame converts a copy of every grid while writing:
// the grids' 48 bytes a voxel and the density levels, 60 in all. Measured (bake, 2 cores):
// the paper forest at 0.25 cm peaked at 741 MiB, estimated 859; one fir at 0.125 cm 1.6 GiB,
// estimated 2.0.
constexpr double kBytesPerVoxelWritten = 60.0;
constexpr double kVoxelsPerLeaf = 512.0;
constexpr double kProgramBytes = 185.0 * 1024 * 1024;  // its libraries, before any scene
constexpr const char* kProgram = "the program";

using TreeSample = TreeTotals;

/// The cylinder a bough's cones fill: from its base along its axis for its length and the
/// cones' reach l cos(phi), radius l sin(phi).
struct BoughCylinder {
    Vec3 base, axis;
    double extent_cm, radius_cm;
};

/// One grown tree of a species: its totals, and its boughs' cylinders for the voxels' leaves.
struct SpeciesSample {
    TreeSample totals;
    std::vector<BoughCylinder> boughs;
};

SpeciesSample sampleTree(const scenes::Scene& scene, const scenes::TreePlacement& placement)
{
    const scenes::Tree tree = scenes::growTree(scene.species.at(placement.species), placement);
    const scenes::TreeCounts counts = tree.counts();
    SpeciesSample s;
    s.totals.branches = double(tree.segments.size());
    s.totals.boughs = double(counts.boughs);
    s.totals.needles = counts.needles;
    for (const BoughSpec& b : treeBoughs(tree)) {
        const analytic::ConeGeometry& c = b.needles.cone;
        const double R = analytic::boughRadius(c);  // l sin(phi)
        const double length = glm::length(b.tip_cm - b.base_cm);
        const double extent = length + c.needleLength_cm * std::cos(c.aperture_rad);
        s.totals.boughVolume_cm3 += kPi * R * R * extent;
        // The boughs the bake leaves empty (bake/src/layer_field.cpp) fill no leaf.
        if (length > 0.0 && R > 0.0 && analytic::layerCoverage(c) > 0.0) {
            s.boughs.push_back({b.base_cm, (b.tip_cm - b.base_cm) / length, extent, R});
        }
    }
    return s;
}

// One sample per species among the trees of `indices`: its first placement there.
std::map<std::string, SpeciesSample> samples(const scenes::Scene& scene,
                                             const std::vector<std::size_t>& indices)
{
    std::map<std::string, SpeciesSample> bySpecies;
    for (const std::size_t i : indices) {
        const scenes::TreePlacement& p = scene.trees.at(i);
        if (!bySpecies.count(p.species)) bySpecies.emplace(p.species, sampleTree(scene, p));
    }
    return bySpecies;
}

/// The cylinder of the voxels a bough fills at h: half a voxel wider (up to half a diagonal)
/// where the bake averages voxels' boxes, which fills every voxel one of whose points is inside.
BoughCylinder filledBy(const BoughCylinder& b, double h)
{
    if (boxPointsPerEdge(b.radius_cm, h) == 1) return b;
    return BoughCylinder{b.base - 0.5 * h * b.axis, b.axis, b.extent_cm + h, b.radius_cm + 0.5 * h};
}

/// The volume of the voxels a tree's boughs fill at h, cm^3.
double filledVolume_cm3(const SpeciesSample& tree, double h)
{
    double volume = 0.0;
    for (const BoughCylinder& bough : tree.boughs) {
        const BoughCylinder b = filledBy(bough, h);
        volume += kPi * b.radius_cm * b.radius_cm * b.extent_cm;
    }
    return volume;
}

/// The OpenVDB leaves (8^3 voxels of h cm) a tree's boughs reach: points at most a quarter of
/// a leaf apart through each bough's cylinder, each leaf counted once however many boughs
/// share it. Where leaves are small against the boughs (more than kMostPoints points), the
/// boughs' volume fills them: its voxels over a leaf's, a quarter more for the leaves its
/// surface cuts.
double leavesOf(const SpeciesSample& tree, double h)
{
    constexpr double kMostPoints = 4e6;
    const double leaf = 8.0 * h, step = 0.25 * leaf;
    const double filled = filledVolume_cm3(tree, h) / (leaf * leaf * leaf);
    // Points across and along a bough: each centred in one of n equal cells at most a step wide.
    const auto cells = [step](double width) { return std::max(1.0, std::ceil(width / step)); };
    double points = 0.0;
    for (const BoughCylinder& bough : tree.boughs) {
        const BoughCylinder b = filledBy(bough, h);
        points += cells(b.extent_cm) * cells(2.0 * b.radius_cm) * cells(2.0 * b.radius_cm);
    }
    if (!(points <= kMostPoints)) return 1.25 * filled;
    struct Hash {
        std::size_t operator()(const std::array<long long, 3>& c) const
        {
            // Unsigned, so that the products wrap rather than overflow.
            return std::size_t(std::uint64_t(c[0]) * 73856093u ^ std::uint64_t(c[1]) * 19349663u ^
                               std::uint64_t(c[2]) * 83492791u);
        }
    };
    std::unordered_set<std::array<long long, 3>, Hash> leaves;
    // A leaf index a long long cannot hold (tiny leaves far out) falls back to the volume.
    constexpr double kMostIndex = 1e18;
    for (const BoughCylinder& bough : tree.boughs) {
        const BoughCylinder b = filledBy(bough, h);
        const Vec3 helper = std::abs(b.axis.x) < 0.9 ? Vec3(1, 0, 0) : Vec3(0, 1, 0);
        const Vec3 u = glm::normalize(glm::cross(b.axis, helper)), v = glm::cross(b.axis, u);
        const int along = int(cells(b.extent_cm)), across = int(cells(2.0 * b.radius_cm));
        const auto at = [](int i, int n) { return (i + 0.5) / n; };  // in (0, 1)
        for (int i = 0; i < along; ++i) {
            const Vec3 centre = b.base + b.extent_cm * at(i, along) * b.axis;
            for (int j = 0; j < across; ++j) {
                for (int k = 0; k < across; ++k) {
                    const double x = b.radius_cm * (2.0 * at(j, across) - 1.0),
                                 y = b.radius_cm * (2.0 * at(k, across) - 1.0);
                    if (x * x + y * y > b.radius_cm * b.radius_cm) continue;
                    const Vec3 p = glm::floor((centre + x * u + y * v) / leaf);
                    if (!(std::abs(p.x) < kMostIndex && std::abs(p.y) < kMostIndex &&
                          std::abs(p.z) < kMostIndex)) {
                        return 1.25 * filled;
                    }
                    leaves.insert({(long long)p.x, (long long)p.y, (long long)p.z});
                }
            }
        }
    }
    return std::max(double(leaves.size()), filled);
}

// The trees of `indices`, each counted as its species' sample.
TreeSample sumTrees(const scenes::Scene& scene, const std::vector<std::size_t>& indices)
{
    const std::map<std::string, SpeciesSample> bySpecies = samples(scene, indices);
    TreeSample total;
    for (const std::size_t i : indices) {
        const TreeSample& one = bySpecies.at(scene.trees[i].species).totals;
        total.branches += one.branches;
        total.boughs += one.boughs;
        total.needles += one.needles;
        total.boughVolume_cm3 += one.boughVolume_cm3;
    }
    return total;
}

std::vector<std::size_t> allTrees(const scenes::Scene& scene)
{
    std::vector<std::size_t> all(scene.trees.size());
    for (std::size_t i = 0; i < all.size(); ++i) all[i] = i;
    return all;
}

/// Trees like `sample`, `count` of them.
struct SampledTrees {
    const SpeciesSample* sample;
    double count;
};

/// The voxels of `trees` at `voxelSize_cm`, as OpenVDB holds them: in whole leaves.
void addVoxels(ResourceEstimate& e, const std::vector<SampledTrees>& trees, double voxelSize_cm,
               double lights, double bytesPerVoxel = kBytesPerVoxel)
{
    if (!(voxelSize_cm > 0.0)) return;
    double voxels = 0.0, leaves = 0.0;
    for (const SampledTrees& t : trees) {
        voxels += t.count * filledVolume_cm3(*t.sample, voxelSize_cm) / std::pow(voxelSize_cm, 3);
        leaves += t.count * leavesOf(*t.sample, voxelSize_cm);
    }
    char size[32];
    std::snprintf(size, sizeof size, "%.3g cm", voxelSize_cm);
    e.parts.push_back({formatCount(voxels) + " voxels of " + size,
                       leaves * kVoxelsPerLeaf * (bytesPerVoxel + kBytesPerVoxelLight * lights)});
}

/// Every tree of `indices` as its species' sample.
std::vector<SampledTrees> sampledTrees(const std::map<std::string, SpeciesSample>& bySpecies,
                                       const scenes::Scene& scene,
                                       const std::vector<std::size_t>& indices)
{
    std::map<std::string, double> count;
    for (const std::size_t i : indices) count[scene.trees[i].species] += 1.0;
    std::vector<SampledTrees> trees;
    for (const auto& [species, n] : count) trees.push_back({&bySpecies.at(species), n});
    return trees;
}

}  // namespace

TreeTotals estimateTrees(const scenes::Scene& scene, const std::vector<std::size_t>& trees)
{
    return sumTrees(scene, trees);
}

double ResourceEstimate::bytes() const
{
    double sum = 0.0;
    for (const Part& p : parts) sum += p.bytes;
    return sum;
}

const ResourceEstimate::Part& ResourceEstimate::largest() const
{
    // The program itself is not something the user can lower: named only when alone.
    static const Part none{"nothing", 0.0};
    const Part* best = parts.empty() ? &none : &parts.front();
    for (const Part& p : parts) {
        const bool program = p.what == kProgram, bestProgram = best->what == kProgram;
        if ((bestProgram && !program) || (program == bestProgram && p.bytes > best->bytes)) {
            best = &p;
        }
    }
    return *best;
}

ResourceEstimate estimateRender(const scenes::Scene& scene, const std::string& method,
                                double voxelSize_cm, double voxelsRead, bool instanceVariants,
                                double lawProfileBudget_bytes)
{
    ResourceEstimate e;
    e.parts.push_back({kProgram, kProgramBytes});
    const double pixels = double(scene.camera.width) * double(scene.camera.height);
    e.parts.push_back({"image " + std::to_string(scene.camera.width) + " x " +
                           std::to_string(scene.camera.height),
                       pixels * kBytesPerPixel});
    const TreeSample trees = sumTrees(scene, allTrees(scene));
    const double lights = double(scene.pointLights.size() + scene.directionalLights.size());
    e.parts.push_back({formatCount(double(scene.trees.size())) + " trees (" +
                           formatCount(trees.boughs) + " boughs, " + formatCount(trees.branches) +
                           " branches)",
                       trees.branches * kBytesPerBranch + trees.boughs * kBytesPerBough});
    // Each variant is grown once, at its first tree, every other tree for itself; all are
    // held until the boughs are made. The reference bakes from every tree, a variant's copies
    // moved copies of its first, and holds them all to the end (vdbtrace's methods.cpp: its
    // TracedSceneParts keep the grown trees).
    std::vector<std::size_t> firsts;
    for (std::size_t i = 0; i < scene.trees.size(); ++i) {
        if (scene.trees[i].variantOf < 0) firsts.push_back(i);
    }
    const bool copies = firsts.size() < scene.trees.size();
    const TreeSample grown = copies ? sumTrees(scene, firsts) : trees;
    const TreeSample& held = method == "reference" ? trees : grown;
    e.parts.push_back({"grown trees", held.boughs * kBytesPerGrownBough});
    const double columns = (trees.branches + trees.boughs) * kBytesPerColumnPrimitive;
    if ((method == "multiscale" || method == "reference") && scene.effects.shadows &&
        !scene.directionalLights.empty() && columns <= double(kShadowColumnsMax_bytes)) {
        e.parts.push_back({"shadow columns", columns * double(scene.directionalLights.size())});
    }
    if (method == "multiscale") {
        // At most every bough's, as many as the render meets (95% of the paper forest's, 40%
        // of the landscape's), within the budget where one is given.
        const double all = trees.boughs * (kBytesPerBoughView + kBytesPerBoughLight * lights);
        const bool bounded = lawProfileBudget_bytes < all;
        e.parts.push_back({bounded ? "the law profiles, within --law-cache"
                                   : "the law profiles of up to " + formatCount(trees.boughs) +
                                         " boughs (--law-cache MIB bounds them)",
                           bounded ? lawProfileBudget_bytes : all});
    } else if (method == "geometry") {
        // Instanced, the variants' first trees' needles are the only cylinders laid out.
        const bool shared = copies && instanceVariants;
        const TreeSample own = shared ? grown : trees;
        e.parts.push_back({formatCount(own.needles) + " needle cylinders" +
                               (shared ? " (a variant's trees share them)" : ""),
                           own.needles * kBytesPerNeedle});
    } else if (method == "reference") {
        if (voxelsRead > 0.0) {
            // Read and merged before the render, held to its end (the per-file copies are let
            // go once merged, so the merged grids stand for them).
            e.parts.push_back({"the baked grids read (" + formatCount(voxelsRead) + " voxels)",
                               voxelsRead * (kBytesPerVoxelGrids + kBytesPerVoxelTree)});
            e.parts.push_back({"light grids", voxelsRead * kBytesPerVoxelLight * lights});
        } else {
            const std::vector<std::size_t> all = allTrees(scene);
            const std::map<std::string, SpeciesSample> bySpecies = samples(scene, all);
            addVoxels(e, sampledTrees(bySpecies, scene, all), voxelSize_cm, lights,
                      kBytesPerVoxel + kBytesPerVoxelTree);
        }
    }
    return e;
}

ResourceEstimate estimateCompare(const scenes::Scene& scene, double smallestVoxel_cm,
                                 std::size_t images)
{
    ResourceEstimate largest;
    for (const char* method : {"multiscale", "reference", "geometry"}) {
        ResourceEstimate e = estimateRender(scene, method, smallestVoxel_cm);
        if (e.bytes() > largest.bytes()) largest = std::move(e);
    }
    const double pixels = double(scene.camera.width) * double(scene.camera.height);
    if (images > 1) {
        largest.parts.push_back(
            {formatCount(double(images - 1)) + " more images kept for the report",
             double(images - 1) * pixels * kBytesPerPixel});
    }
    return largest;
}

ResourceEstimate estimateBake(const scenes::Scene& scene, const std::vector<std::size_t>& trees,
                              double voxelSize_cm, std::size_t concurrent)
{
    ResourceEstimate e;
    e.parts.push_back({kProgram, kProgramBytes});
    // The largest tree, as many times as trees are baked at once.
    const std::map<std::string, SpeciesSample> bySpecies = samples(scene, trees);
    const SpeciesSample* largest = nullptr;
    for (const auto& [species, one] : bySpecies) {
        if (!largest || one.totals.boughVolume_cm3 > largest->totals.boughVolume_cm3) {
            largest = &one;
        }
    }
    if (largest == nullptr) return e;
    const double copies = double(std::max<std::size_t>(1, std::min(concurrent, trees.size())));
    addVoxels(e, {{largest, copies}}, voxelSize_cm, 0.0, kBytesPerVoxel + kBytesPerVoxelWritten);
    return e;
}

double defaultMemoryLimit()
{
    const long pages = ::sysconf(_SC_PHYS_PAGES), size = ::sysconf(_SC_PAGE_SIZE);
    if (pages <= 0 || size <= 0) return 16.0 * kGiB;
    return 0.8 * double(pages) * double(size);
}

double memoryLimit(double gib)
{
    return gib > 0.0 ? gib * kGiB : defaultMemoryLimit();
}

std::string formatCount(double n)
{
    if (!std::isfinite(n)) return "more than 1e308";
    char text[64];
    std::snprintf(text, sizeof text, n < 1e6 ? "%.0f" : "%.3g", n);
    return text;
}

std::string formatBytes(double bytes)
{
    // Rounded up below a GiB, so that an estimate is never shown as less than it is; small
    // limits (--max-memory 1e-6) get small units, not "1 MiB" beside an estimate of 1 MiB.
    if (!std::isfinite(bytes)) return "an unbounded amount";
    char text[48];
    if (bytes >= 1e6 * kGiB) {
        std::snprintf(text, sizeof text, "%.3g GiB", bytes / kGiB);
    } else if (bytes >= kGiB) {
        std::snprintf(text, sizeof text, "%.1f GiB", bytes / kGiB);
    } else if (bytes >= 1024.0 * 1024.0) {
        std::snprintf(text, sizeof text, "%.0f MiB", std::ceil(bytes / (1024.0 * 1024.0)));
    } else if (bytes >= 1024.0) {
        std::snprintf(text, sizeof text, "%.0f KiB", std::ceil(bytes / 1024.0));
    } else if (bytes >= 1.0) {
        std::snprintf(text, sizeof text, "%.0f bytes", std::ceil(bytes));
    } else {
        std::snprintf(text, sizeof text, "%.3g bytes", bytes);
    }
    return text;
}

void checkMemory(const ResourceEstimate& estimate, double limitBytes, const std::string& task)
{
    const double total = estimate.bytes();
    if (!(total > limitBytes)) return;
    if (!std::isfinite(total)) {
        throw InputError(task + ": " + estimate.largest().what +
                         " would need more memory than any machine has");
    }
    throw InputError(task + ": " + estimate.largest().what + " needs about " +
                     formatBytes(estimate.largest().bytes) + " (" + formatBytes(total) +
                     " in all), more than --max-memory " + formatBytes(limitBytes) +
                     " allows (lower it, or raise --max-memory)");
}

}  // namespace pine::bake
