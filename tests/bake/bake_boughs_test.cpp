// Voxelized boughs against the continuous field: mass, values at voxel centres, overlapping
// boughs, the density pyramid.
#include "pine/bake/extinction_law.h"
#include "pine/bake/tree_grids.h"

#include "test_support.h"

#include <gtest/gtest.h>
#include <glm/geometric.hpp>

#include <tbb/task_arena.h>

#include <cmath>
#include <utility>
#include <vector>

namespace pine::bake {
namespace {

const ExtinctionLaw& layerLaw()
{
    return extinctionLaw("layer");
}

constexpr double kPi = 3.14159265358979323846;

/// Sum over active values (voxels and tiles) of value x its volume in index units.
double indexSum(const openvdb::FloatGrid& grid)
{
    double sum = 0.0;
    for (auto it = grid.cbeginValueOn(); it; ++it) {
        sum += double(*it) * double(it.getVoxelCount());
    }
    return sum;
}

/// Sum over voxels of mean extinction x h^3: the voxelized "mass", per cm^0 (optical depth
/// x area).
double voxelizedMass(const TreeGrids& g)
{
    return indexSum(*g.density) * std::pow(g.voxelSize_cm, 3);
}

TEST(BakeBoughs, MassOfALongBoughMatchesTheIntegral)
{
    // The region {rho <= R, 0 <= h - rho cot(phi) <= L} is a cylinder sheared along its axis:
    // volume pi R^2 L; the mean extinction is uniform in it, mu |G| / 2 with |G| =
    // 1 / (dh sin(phi)). So sum(mean extinction x h^3) must be mu / (2 dh sin(phi)) pi R^2 L.
    //
    // Tolerance: counting voxel centres in a body errs only in the cells its surface cuts, all
    // within sqrt(3) h / 2 of it, so |error| <= sqrt(3) h S / V relative (first order in h / R),
    // with S / V = 2 / R (side) + 2 / (L sin(phi)) (the end cones, pi R^2 / sin(phi) each).
    // That bound assumes every cut cell errs the same way; a systematic error does (a layer of
    // boundary voxels dropped or added costs ~ h S / V = bound / sqrt(3)), while a correct
    // count's cut cells gain and lose alike and cancel: measured, the error is ~1% of the bound.
    // So each error must stay under bound / 10, and the mean over sub-voxel shifts of the bough
    // must shrink with h. The axis is oblique so that no face lines up with the voxels.
    const BoughSpec b = test::paperBough(Vec3(0.3, -0.7, 0.1), Vec3(0.3, 0.5, 0.8), 60.0);
    const double phi = b.needles.cone.aperture_rad,
                 R = b.needles.cone.needleLength_cm * std::sin(phi), L = 60.0;
    const double A =
        2.0 * b.needles.cone.needlesPerCone * b.needles.cone.needleRadius_cm / (kPi * R);
    const double mu = -std::log(1.0 - A);
    const double exact = mu / (2.0 * b.needles.coneSpacing_cm * std::sin(phi)) * kPi * R * R * L;
    const double surfaceOverVolume = 2.0 / R + 2.0 / (L * std::sin(phi));

    double previousMean = 0.0;
    for (const double h : {R / 4, R / 8, R / 16}) {
        const double bound = std::sqrt(3.0) * h * surfaceOverVolume;
        constexpr int kShifts = 8;
        double sumError = 0.0;
        for (int k = 0; k < kShifts; ++k) {
            // Sub-voxel shifts of the bough: a deterministic low-discrepancy set.
            const Vec3 shift =
                h * Vec3(std::fmod(0.5 + k * 0.618034, 1.0), std::fmod(0.5 + k * 0.754878, 1.0),
                         std::fmod(0.5 + k * 0.569840, 1.0));
            BoughSpec shifted = b;
            shifted.base_cm += shift;
            shifted.tip_cm += shift;
            const TreeGrids g = bakeBoughs({shifted}, BakeSettings{h, 1, "layer"});
            const double error = std::abs(voxelizedMass(g) / exact - 1.0);
            EXPECT_LT(error, bound / 10) << "h " << h << ", shift " << k;
            sumError += error;
        }
        const double mean = sumError / kShifts;
        if (previousMean > 0.0) {
            EXPECT_LT(mean, previousMean) << "h " << h;
        }
        previousMean = mean;
    }
}

TEST(BakeBoughs, CoarseVoxelsKeepTheBoughsExtinction)
{
    // A voxel wider than R / 4 holds the extinction whose opacity over its mean chord is the
    // mean of its points' own. Three consequences, each checked from R / 2 to 4R, for a bough
    // whose axis runs along a lattice axis through voxel centres (where centres alone lose
    // whole rows: a 2R bake of it was empty, every centre on the axis or beyond R) and an
    // oblique one:
    // - needles so thin that every opacity is linear in the extinction: the mean over the box,
    //   so the mass is the integral's (MassOfALongBoughMatchesTheIntegral);
    // - a voxel the paper's bough fills wholly keeps its extinction, uniform there;
    // - every voxel's layered fields meet its density, under each law, as the reference reads
    //   them.
    const double L = 60.0;
    for (const Vec3& axis : {Vec3(1, 0, 0), glm::normalize(Vec3(0.3, 0.5, 0.8))}) {
        const BoughSpec paper = test::paperBough(Vec3(0.0), axis, L);
        BoughSpec thin = paper;
        thin.needles.cone.needleRadius_cm = 5e-5;  // A = 2.3e-4, mean extinction 3.4e-4 / cm
        const analytic::ConeGeometry& c = thin.needles.cone;
        const double phi = c.aperture_rad, R = c.needleLength_cm * std::sin(phi);
        const double mu = -std::log(1.0 - 2.0 * c.needlesPerCone * c.needleRadius_cm / (kPi * R));
        const double exact =
            mu / (2.0 * thin.needles.coneSpacing_cm * std::sin(phi)) * kPi * R * R * L;
        for (const double h : {R / 2, R, 2 * R, 4 * R}) {
            EXPECT_NEAR(voxelizedMass(bakeBoughs({thin}, BakeSettings{h, 1, "layer"})) / exact, 1.0,
                        0.015)
                << "axis " << axis.x << " h " << h;
            for (const char* name : {"layer", "fibre", "poisson"}) {
                const TreeGrids g = bakeBoughs({paper}, BakeSettings{h, 1, name});
                const ExtinctionLaw& law = extinctionLaw(name);
                auto gradient = g.layerGradient->getConstAccessor();
                auto needle = g.needleDirection->getConstAccessor();
                auto opacity = g.layerOpacity->getConstAccessor();
                auto coverage = g.needleCoverage->getConstAccessor();
                int whole = 0;
                for (auto it = g.density->cbeginValueOn(); it; ++it) {
                    const openvdb::Coord ijk = it.getCoord();
                    const auto vec = [](const openvdb::Vec3s& v) {
                        return Vec3(v.x(), v.y(), v.z());
                    };
                    LayerSample s;
                    s.gradient = vec(gradient.getValue(ijk));
                    s.needle = vec(needle.getValue(ijk));
                    s.layerOpacity = opacity.getValue(ijk);
                    s.needleCoverage = coverage.getValue(ijk);
                    ASSERT_NEAR(law.meanExtinction(s), *it, 1e-5 * *it) << name << " " << ijk;
                    if (std::string(name) != "layer") continue;
                    // Wholly inside: every corner within R of the axis (a disc is convex), and
                    // the voxel well clear of the bough's ends.
                    const Vec3 centre = h * Vec3(ijk.x(), ijk.y(), ijk.z());
                    bool inside = glm::dot(centre, axis) > 8.0 && glm::dot(centre, axis) < L - 8.0;
                    for (int corner = 0; corner < 8 && inside; ++corner) {
                        const Vec3 x = centre + 0.5 * h *
                                                    Vec3(corner & 1 ? 1 : -1, corner & 2 ? 1 : -1,
                                                         corner & 4 ? 1 : -1);
                        inside = glm::length(x - glm::dot(x, axis) * axis) < R;
                    }
                    if (!inside) continue;
                    ++whole;
                    const auto field = sampleBough(paper, centre);
                    ASSERT_TRUE(field);
                    ASSERT_NEAR(*it, law.meanExtinction(*field), 1e-5 * *it) << ijk;
                }
                if (std::string(name) == "layer" && h <= R / 2) {
                    EXPECT_GT(whole, 10) << "axis " << axis.x;
                }
            }
        }
    }
}

/// Index box around a bough's region (its cones' reach), widened by one voxel.
openvdb::CoordBBox searchBox(const BoughSpec& b, double h)
{
    const double R = b.needles.cone.needleLength_cm * std::sin(b.needles.cone.aperture_rad);
    const Vec3 axis = glm::normalize(b.tip_cm - b.base_cm);
    const Vec3 end = b.tip_cm + axis * (R / std::tan(b.needles.cone.aperture_rad));
    openvdb::CoordBBox box;
    for (const Vec3& p : {b.base_cm, end}) {
        for (const double dx : {-R, R}) {
            for (const double dy : {-R, R}) {
                for (const double dz : {-R, R}) {
                    box.expand(openvdb::Coord(int(std::floor((p.x + dx) / h)),
                                              int(std::floor((p.y + dy) / h)),
                                              int(std::floor((p.z + dz) / h))));
                }
            }
        }
    }
    box.expand(1);
    return box;
}

TEST(BakeBoughs, VoxelsWiderThanAQuarterOfTheRadiusAverageTheirBoxes)
{
    // One point (the centre) up to R / 4, then cells at most R / 4 wide, up to 32 a side.
    const double R = 1.6;
    EXPECT_EQ(boxPointsPerEdge(R, R / 8), 1);
    EXPECT_EQ(boxPointsPerEdge(R, R / 4), 1);
    EXPECT_EQ(boxPointsPerEdge(R, R / 4 * 1.001), 2);
    EXPECT_EQ(boxPointsPerEdge(R, R), 4);
    EXPECT_EQ(boxPointsPerEdge(R, R * 1.1), 5);
    EXPECT_EQ(boxPointsPerEdge(R, 8 * R), 32);
    EXPECT_EQ(boxPointsPerEdge(R, 100 * R), 32);
    EXPECT_EQ(boxPointsPerEdge(std::nan(""), 1.0), 1);
}

TEST(BakeBoughs, PoissonMassIsTheNeedlesMeanProjectedArea)
{
    // Cauchy: a thin needle of length l and radius r shows a mean projected area (pi / 4) 2 r l
    // over all directions, so under the Poisson law sum(mean extinction x h^3) is (pi / 4) 2 r
    // times the needles' total length, N l L / dh, less what the cap on their coverage
    // removes near the axis: there min(1, N r / (pi rho)) = 1 for rho < rho0 = N r / pi, which
    // takes pi rho0^2 L / (dh sin(phi)) (pi / 4) from the integral of the uncapped coverage.
    const BoughSpec b = test::paperBough(Vec3(0.3, -0.7, 0.1), Vec3(0.3, 0.5, 0.8), 60.0);
    const analytic::ConeGeometry& c = b.needles.cone;
    const double L = 60.0, dh = b.needles.coneSpacing_cm, sinPhi = std::sin(c.aperture_rad);
    const double rho0 = c.needlesPerCone * c.needleRadius_cm / kPi;
    const double exact = 0.25 * kPi *
                         (2.0 * c.needleRadius_cm * c.needlesPerCone * c.needleLength_cm * L / dh -
                          kPi * rho0 * rho0 * L / (dh * sinPhi));
    const double h = c.needleLength_cm * sinPhi / 16;
    const TreeGrids g = bakeBoughs({b}, BakeSettings{h, 1, "poisson"});
    // The coverage's 1 / rho near the axis adds a little to the voxel error of the layer law.
    EXPECT_NEAR(voxelizedMass(g) / exact, 1.0, 0.01);
}

TEST(BakeBoughs, EveryVoxelSamplesTheFieldAtItsCentre)
{
    // Every voxel of the box around the bough: active exactly where the field exists at the
    // voxel's centre, indexToWorld(ijk) = ijk h, with the field's values there. Catches a
    // voxel dropped by the voxelizer's column bounds as much as a half-voxel shift.
    const BoughSpec b = test::paperBough(Vec3(-2.1, 3.4, 0.7), Vec3(-0.6, 0.2, 0.7), 12.0);
    const double h = 0.35;
    const TreeGrids g = bakeBoughs({b}, BakeSettings{h, 1, "layer"});
    EXPECT_EQ(g.voxelSize_cm, h);
    const auto& xform = g.density->transform();
    EXPECT_EQ(g.layerOpacity->transform(), xform);
    EXPECT_EQ(g.layerGradient->transform(), xform);
    EXPECT_EQ(g.needleDirection->transform(), xform);
    EXPECT_EQ(g.needleAlbedo->transform(), xform);

    auto density = g.density->getConstAccessor();
    auto gradient = g.layerGradient->getConstAccessor();
    auto opacity = g.layerOpacity->getConstAccessor();
    auto needle = g.needleDirection->getConstAccessor();
    auto albedo = g.needleAlbedo->getConstAccessor();
    int inside = 0;
    const openvdb::CoordBBox box = searchBox(b, h);
    for (auto it = box.begin(); it; ++it) {
        const openvdb::Coord ijk = *it;
        const openvdb::Vec3d w = xform.indexToWorld(ijk);
        ASSERT_EQ(w, openvdb::Vec3d(ijk.x() * h, ijk.y() * h, ijk.z() * h));
        const auto s = sampleBough(b, Vec3(w.x(), w.y(), w.z()));
        ASSERT_EQ(bool(s), density.isValueOn(ijk)) << ijk;
        if (!s) continue;
        ++inside;
        // The mean extinction per cm.
        EXPECT_NEAR(density.getValue(ijk), layerLaw().meanExtinction(*s),
                    1e-6 * layerLaw().meanExtinction(*s));
        const auto near = [](const openvdb::Vec3s& a, const Vec3& e) {
            return std::abs(a.x() - e.x) < 1e-6 && std::abs(a.y() - e.y) < 1e-6 &&
                   std::abs(a.z() - e.z) < 1e-6;
        };
        EXPECT_TRUE(near(gradient.getValue(ijk), s->gradient)) << ijk;
        EXPECT_TRUE(near(needle.getValue(ijk), s->needle)) << ijk;
        EXPECT_TRUE(near(albedo.getValue(ijk), b.needleAlbedo)) << ijk;
        EXPECT_NEAR(opacity.getValue(ijk), s->layerOpacity, 1e-7);
    }
    EXPECT_GT(inside, 1000);
}

/// Two 16 cm paper boughs crossing at right angles, the second denser (24 needles per cone,
/// albedo 0.5).
std::pair<BoughSpec, BoughSpec> crossingBoughs()
{
    const BoughSpec thin = test::paperBough(Vec3(-8.0, 0.0, 0.0), Vec3(1, 0, 0), 16.0);
    BoughSpec dense = test::paperBough(Vec3(0.0, -8.0, 0.3), Vec3(0, 1, 0), 16.0);
    dense.needles.cone.needlesPerCone = 24;
    dense.needleAlbedo = Vec3(0.5);
    return {thin, dense};
}

TEST(BakeBoughs, OverlappingBoughsAddTheirExtinctionWhateverTheOrder)
{
    // Two boughs crossing at right angles, the second denser (more needles per cone): where
    // both reach, both boughs' needles are there, so the density is the sum of their mean
    // extinctions, and the layered fields are the denser bough's (its albedo, its layers with
    // the gradient scaled to that sum), whichever is listed first. Under the layer law a
    // bough's extinction is uniform, so the denser is the same everywhere. The voxelized mass
    // of the two is the sum of each one's alone.
    const auto [thin, dense] = crossingBoughs();
    const BakeSettings settings{0.3, 1, "layer"};
    const TreeGrids ab = bakeBoughs({thin, dense}, settings);
    const TreeGrids ba = bakeBoughs({dense, thin}, settings);
    const double alone =
        voxelizedMass(bakeBoughs({thin}, settings)) + voxelizedMass(bakeBoughs({dense}, settings));
    EXPECT_NEAR(voxelizedMass(ab), alone, 1e-6 * alone);
    ASSERT_EQ(ab.density->activeVoxelCount(), ba.density->activeVoxelCount());
    auto a = ab.needleAlbedo->getConstAccessor();
    auto b = ba.needleAlbedo->getConstAccessor();
    auto da = ab.density->getConstAccessor();
    auto db = ba.density->getConstAccessor();
    auto gradient = ab.layerGradient->getConstAccessor();
    int overlap = 0;
    for (auto it = ab.density->cbeginValueOn(); it; ++it) {
        const openvdb::Coord ijk = it.getCoord();
        const openvdb::Vec3d w = ab.density->indexToWorld(ijk);
        const Vec3 x(w.x(), w.y(), w.z());
        const auto sThin = sampleBough(thin, x), sDense = sampleBough(dense, x);
        EXPECT_EQ(da.getValue(ijk), db.getValue(ijk)) << ijk;
        EXPECT_EQ(a.getValue(ijk), b.getValue(ijk)) << ijk;
        if (!sThin || !sDense) continue;
        ++overlap;
        const double sum = layerLaw().meanExtinction(*sThin) + layerLaw().meanExtinction(*sDense);
        EXPECT_NEAR(da.getValue(ijk), sum, 1e-6 * sum) << ijk;
        EXPECT_EQ(a.getValue(ijk), openvdb::Vec3s(0.5f)) << ijk;
        // The dense bough's layers, as many more per cm as the thin one's extinction adds.
        const Vec3 scaled = sDense->gradient * (sum / layerLaw().meanExtinction(*sDense));
        const openvdb::Vec3s g = gradient.getValue(ijk);
        EXPECT_NEAR(g.x(), scaled.x, 1e-5 * glm::length(scaled)) << ijk;
        EXPECT_NEAR(g.y(), scaled.y, 1e-5 * glm::length(scaled)) << ijk;
        EXPECT_NEAR(g.z(), scaled.z, 1e-5 * glm::length(scaled)) << ijk;
    }
    EXPECT_GT(overlap, 50);
}

TEST(BakeBoughs, TreesMergedOverlapAsTheirBoughsBakedTogetherDo)
{
    // Two crossing boughs, each baked as a tree of its own and merged (a render's --grids), or
    // baked together (a render's own bake): the same voxels, densities and fields, and each
    // voxel the tree of the denser bough there (its albedo tells which).
    auto [thin, dense] = crossingBoughs();
    const BakeSettings settings{0.3, 1, "layer"};
    EXPECT_FALSE(bakeBoughs({thin, dense}, settings).tree) << "no bough names its tree";
    thin.tree = 0;
    dense.tree = 1;
    const TreeGrids together = bakeBoughs({thin, dense}, settings);
    const TreeGrids merged =
        mergeTreeGrids({bakeBoughs({thin}, settings), bakeBoughs({dense}, settings)});
    ASSERT_EQ(merged.density->activeVoxelCount(), together.density->activeVoxelCount());
    auto d = merged.density->getConstAccessor();
    auto g = merged.layerGradient->getConstAccessor();
    auto tg = together.layerGradient->getConstAccessor();
    auto a = merged.needleAlbedo->getConstAccessor();
    auto ta = together.needleAlbedo->getConstAccessor();
    for (auto it = together.density->cbeginValueOn(); it; ++it) {
        const openvdb::Coord c = it.getCoord();
        ASSERT_NEAR(d.getValue(c), *it, 1e-6f * *it) << c;
        ASSERT_TRUE((g.getValue(c) - tg.getValue(c)).length() <= 1e-5f * tg.getValue(c).length())
            << c;
        ASSERT_EQ(a.getValue(c), ta.getValue(c)) << c;
    }
    ASSERT_TRUE(together.tree && merged.tree);
    EXPECT_EQ(together.tree->activeVoxelCount(), together.density->activeVoxelCount());
    const auto t = together.tree->getConstAccessor(), m = merged.tree->getConstAccessor();
    int denseVoxels = 0, overlap = 0;
    const TreeGrids thinAlone = bakeBoughs({thin}, settings);
    const auto thinDensity = thinAlone.density->getConstAccessor();
    for (auto it = together.density->cbeginValueOn(); it; ++it) {
        const openvdb::Coord c = it.getCoord();
        const int expected = ta.getValue(c) == openvdb::Vec3s(0.5f) ? 1 : 0;
        ASSERT_EQ(t.getValue(c), expected) << c;
        ASSERT_EQ(m.getValue(c), expected) << c;
        denseVoxels += expected;
        overlap += expected && thinDensity.isValueOn(c);
    }
    EXPECT_GT(overlap, 10) << "the boughs must cross for the merge's overlap to be tested";
    EXPECT_GT(denseVoxels, overlap);
}

// Grids of one tree `tree` holding a tile: the leaf of voxels [origin, origin + 7]^3 filled
// with one value per field (as a bake's prune leaves a constant leaf, and a file keeps it).
TreeGrids oneTile(const TreeGrids& like, const openvdb::Coord& origin, float density, int tree)
{
    TreeGrids out;
    out.voxelSize_cm = like.voxelSize_cm;
    out.extinctionLaw = like.extinctionLaw;
    const openvdb::CoordBBox leaf(origin, origin.offsetBy(7));
    for (const FieldInfo& info : kFields) {
        const openvdb::GridBase::Ptr grid = like.grid(info.field)->copyGridWithNewTree();
        if (info.vector) {
            const openvdb::Vec3s v(info.field == Field::NeedleAlbedo ? 0.7f : 0.0f, 0.0f, density);
            static_cast<openvdb::Vec3SGrid&>(*grid).fill(leaf, v, true);
        } else {
            static_cast<openvdb::FloatGrid&>(*grid).fill(leaf, density, true);
        }
        out.setGrid(info.field, grid);
    }
    out.tree = openvdb::Int32Grid::create(-1);
    out.tree->setTransform(like.density->transform().copy());
    out.tree->fill(leaf, tree, true);
    return out;
}

TEST(BakeBoughs, AMergedVoxelNamesTheTreeWhoseFieldsItKeeps)
{
    // The denser tree's, whichever is merged first; voxels of grids that name no tree -1; a
    // tile (a leaf of one value, as a bake's prune makes) merged voxel by voxel, where the
    // trees before it hold nothing and where they do.
    auto [thin, dense] = crossingBoughs();
    const BakeSettings settings{0.3, 1, "layer"};
    thin.tree = 0;
    dense.tree = 1;
    const TreeGrids t0 = bakeBoughs({thin}, settings), t1 = bakeBoughs({dense}, settings);
    const TreeGrids ab = mergeTreeGrids({t0, t1}), ba = mergeTreeGrids({t1, t0});
    ASSERT_EQ(ab.tree->activeVoxelCount(), ab.density->activeVoxelCount());
    const auto a = ab.tree->getConstAccessor(), b = ba.tree->getConstAccessor();
    const auto d1 = t1.density->getConstAccessor();
    int ones = 0;
    for (auto it = ab.density->cbeginValueOn(); it; ++it) {
        const openvdb::Coord c = it.getCoord();
        ASSERT_EQ(a.getValue(c), b.getValue(c)) << c;
        ASSERT_EQ(a.getValue(c), d1.isValueOn(c) ? 1 : 0) << c;
        ones += a.getValue(c);
    }
    EXPECT_GT(ones, 0);

    thin.tree = -1;  // a tree of no known index, merged first or last
    const TreeGrids unnamed = bakeBoughs({thin}, settings);
    for (const TreeGrids& m : {mergeTreeGrids({unnamed, t1}), mergeTreeGrids({t1, unnamed})}) {
        ASSERT_TRUE(m.tree);
        const auto t = m.tree->getConstAccessor();
        for (auto it = m.density->cbeginValueOn(); it; ++it) {
            ASSERT_EQ(t.getValue(it.getCoord()), d1.isValueOn(it.getCoord()) ? 1 : -1);
        }
    }

    // Tiles: one far from tree 0's voxels, one over a leaf it holds voxels in.
    const openvdb::Coord far(800, 800, 800);
    openvdb::Coord near = t0.density->cbeginValueOn().getCoord();
    near = openvdb::Coord(near.x() & ~7, near.y() & ~7, near.z() & ~7);
    for (const openvdb::Coord& origin : {far, near}) {
        const TreeGrids tile = oneTile(t0, origin, 50.0f, 2);
        ASSERT_GT(tile.needleAlbedo->tree().activeTileCount(), 0u) << "fill made no tile";
        const TreeGrids m = mergeTreeGrids({t0, tile});
        const auto density = m.density->getConstAccessor();
        const auto albedo = m.needleAlbedo->getConstAccessor();
        const auto tree = m.tree->getConstAccessor();
        const auto before = t0.density->getConstAccessor();
        for (auto ijk = openvdb::CoordBBox(origin, origin.offsetBy(7)).begin(); ijk; ++ijk) {
            ASSERT_EQ(density.getValue(*ijk), 50.0f + before.getValue(*ijk)) << *ijk;
            ASSERT_EQ(albedo.getValue(*ijk).x(), 0.7f) << *ijk;
            ASSERT_EQ(tree.getValue(*ijk), 2) << *ijk;
        }
    }
}

TEST(BakeBoughs, TheGridsDoNotDependOnTheThreads)
{
    // Boughs crossing in a star, several in most voxels: their sums are added in an order set
    // by the boughs alone, so every arena bakes the same bits.
    std::vector<BoughSpec> star;
    for (int i = 0; i < 40; ++i) {
        const double a = 0.157 * i, b = 0.31 * i;
        const Vec3 axis(std::cos(a) * std::cos(b), std::sin(a) * std::cos(b), std::sin(b));
        star.push_back(test::paperBough(-6.0 * axis + Vec3(0.01 * i), axis, 12.0));
    }
    // Voxels read at their centres (0.2 cm) and averaged over their boxes (0.8 cm, 8 points).
    for (const double h : {0.2, 0.8}) {
        const BakeSettings settings{h, 1, "fibre"};
        const auto bakeWith = [&](int threads) {
            tbb::task_arena arena(threads);
            return arena.execute([&] { return bakeBoughs(star, settings); });
        };
        const TreeGrids one = bakeWith(1);
        for (const int threads : {2, 3, 7}) {
            const TreeGrids many = bakeWith(threads);
            ASSERT_EQ(one.density->activeVoxelCount(), many.density->activeVoxelCount());
            auto d = many.density->getConstAccessor();
            auto g = many.layerGradient->getConstAccessor();
            auto og = one.layerGradient->getConstAccessor();
            int differ = 0;
            for (auto it = one.density->cbeginValueOn(); it; ++it) {
                differ += *it != d.getValue(it.getCoord()) ||
                          og.getValue(it.getCoord()) != g.getValue(it.getCoord());
            }
            EXPECT_EQ(differ, 0) << threads << " threads, " << h << " cm";
        }
    }
}

TEST(BakeBoughs, PyramidLevelsAverageTheirChildrensOpacity)
{
    // Each level's voxel holds the extinction whose opacity over its mean chord (2/3 of its
    // size) is its 8 children's mean opacity over that chord, as the bake fills a coarse voxel:
    // children of one value keep it (the layer law is uniform inside the bough), and a level
    // holds at most its children's mass (-ln of a mean of exp is at most the mean).
    const BoughSpec b = test::paperBough(Vec3(1.1, -0.4, 2.0), Vec3(0.2, 0.9, 0.3), 20.0);
    const double h = 0.25;
    const TreeGrids g = bakeBoughs({b}, BakeSettings{h, 3, "layer"});
    ASSERT_EQ(g.densityPyramid.size(), 2u);
    const openvdb::FloatGrid* fine = g.density.get();
    for (std::size_t level = 0; level < 2; ++level) {
        const openvdb::FloatGrid& coarse = *g.densityPyramid[level];
        EXPECT_EQ(coarse.getName(), "density_level_" + std::to_string(level + 1));
        EXPECT_NEAR(coarse.voxelSize()[0], 2.0 * fine->voxelSize()[0], 1e-12);
        EXPECT_LT(indexSum(coarse) * 8.0, indexSum(*fine));
        EXPECT_GT(indexSum(coarse) * 8.0, 0.8 * indexSum(*fine));
        const double chord = 2.0 / 3.0 * coarse.voxelSize()[0];
        auto f = fine->getConstAccessor();
        int uniform = 0;
        for (auto it = coarse.cbeginValueOn(); it; ++it) {
            const openvdb::Coord c = it.getCoord();
            double opacity = 0.0;
            openvdb::Vec3d centre(0.0);
            bool same = true;
            for (int i = 0; i < 8; ++i) {
                const openvdb::Coord child(2 * c.x() + (i & 1), 2 * c.y() + ((i >> 1) & 1),
                                           2 * c.z() + ((i >> 2) & 1));
                opacity += (1.0 - std::exp(-double(f.getValue(child)) * chord)) / 8.0;
                same = same && f.isValueOn(child) &&
                       f.getValue(child) ==
                           f.getValue(openvdb::Coord(2 * c.x(), 2 * c.y(), 2 * c.z()));
                centre += fine->indexToWorld(child) / 8.0;
            }
            ASSERT_NEAR(1.0 - std::exp(-double(*it) * chord), opacity, 1e-6) << c;
            if (same) {
                ++uniform;
                ASSERT_NEAR(*it, f.getValue(openvdb::Coord(2 * c.x(), 2 * c.y(), 2 * c.z())),
                            1e-5 * *it)
                    << c;
            }
            // The coarse voxel's centre is its children's.
            ASSERT_TRUE((coarse.indexToWorld(c) - centre).length() < 1e-9) << c;
        }
        EXPECT_GT(uniform, 10) << "level " << level + 1;
        fine = &coarse;
    }
}

TEST(BakeBoughs, RejectsWhatItCannotBake)
{
    const BoughSpec b = test::paperBough(Vec3(0.0), Vec3(0, 0, 1), 5.0);
    EXPECT_THROW(bakeBoughs({b}, BakeSettings{0.0, 1}), BakeError);
    EXPECT_THROW(bakeBoughs({b}, BakeSettings{std::nan(""), 1}), BakeError);
    EXPECT_THROW(bakeBoughs({b}, BakeSettings{0.5, 0, "layer"}), BakeError);
    BoughSpec bad = b;
    bad.needles.cone.aperture_rad = 2.0;
    EXPECT_THROW(bakeBoughs({b, bad}, BakeSettings{0.5, 1, "layer"}), BakeError);
    // Named by its index, without the tool's own prefix (bake printed "bake: bake: bough 1").
    try {
        (void)bakeBoughs({b, bad}, BakeSettings{0.5, 1, "layer"});
    } catch (const BakeError& e) {
        EXPECT_EQ(std::string(e.what()).rfind("baking bough 1: ", 0), 0u) << e.what();
    }
    bad = b;
    bad.tip_cm.x = INFINITY;
    EXPECT_THROW(bakeBoughs({bad}, BakeSettings{0.5, 1, "layer"}), BakeError);
}

TEST(BakeBoughs, NothingToBakeGivesEmptyGrids)
{
    BoughSpec zero = test::paperBough(Vec3(0.0), Vec3(0, 0, 1), 5.0);
    zero.tip_cm = zero.base_cm;
    for (const auto& boughs : {std::vector<BoughSpec>{}, std::vector<BoughSpec>{zero}}) {
        const TreeGrids g = bakeBoughs(boughs, BakeSettings{0.5, 3, "layer"});
        ASSERT_TRUE(g.density && g.layerGradient && g.layerOpacity && g.needleDirection &&
                    g.needleAlbedo);
        EXPECT_EQ(g.density->activeVoxelCount(), 0u);
        EXPECT_EQ(g.densityPyramid.size(), 2u);
    }
}

}  // namespace
}  // namespace pine::bake
