#include "pine/vdbtrace/reference_tracer.h"

#include "pine/analytic/needle_shader.h"
#include "pine/bake/extinction_law.h"
#include "pine/vdbtrace/effects_plan.h"
#include "pine/vdbtrace/layer_bands.h"
#include "pine/vdbtrace/progress_steps.h"
#include "pine/vdbtrace/render_driver.h"
#include "pine/vdbtrace/surface_shading.h"

#include <openvdb/tools/Interpolation.h>
#include <openvdb/tools/Morphology.h>
#include <openvdb/tools/RayIntersector.h>
#include <openvdb/tree/LeafManager.h>
#include <glm/geometric.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <optional>
#include <vector>

namespace pine::vdbtrace {
namespace {

constexpr double kPi = analytic::kPi;
using Intersector = openvdb::tools::VolumeRayIntersector<openvdb::FloatGrid>;

Vec3 toGlm(const openvdb::Vec3s& v) { return Vec3(v.x(), v.y(), v.z()); }

// Walks the voxels of size h (centres at i h) that the ray o + t d crosses for t in [t0, t1],
// calling visit(ijk, ta, tb) for each span, in order (Amanatides & Woo).
template <class Visit>
void walkVoxels(const Vec3& o, const Vec3& d, double h, double t0, double t1, Visit&& visit)
{
    if (!(t1 > t0)) return;
    const Vec3 p = o + t0 * d;
    int cell[3], step[3];
    double next[3], delta[3];
    for (int a = 0; a < 3; ++a) {
        cell[a] = int(std::floor(p[a] / h + 0.5));
        if (d[a] > 0.0) {
            step[a] = 1;
            next[a] = t0 + ((cell[a] + 0.5) * h - p[a]) / d[a];
            delta[a] = h / d[a];
        } else if (d[a] < 0.0) {
            step[a] = -1;
            next[a] = t0 + ((cell[a] - 0.5) * h - p[a]) / d[a];
            delta[a] = -h / d[a];
        } else {
            step[a] = 0;
            next[a] = delta[a] = std::numeric_limits<double>::infinity();
        }
    }
    double t = t0;
    while (t < t1) {
        const int a = next[0] < next[1] ? (next[0] < next[2] ? 0 : 2) : (next[1] < next[2] ? 1 : 2);
        const double end = std::min(next[a], t1);
        if (end > t) visit(openvdb::Coord(cell[0], cell[1], cell[2]), t, end);
        t = end;
        cell[a] += step[a];
        next[a] += delta[a];
    }
}

// Whether the grids hold any voxel of the boughs to march through.
bool hasVolume(const bake::TreeGrids& g)
{
    return g.layerOpacity && g.layerOpacity->activeVoxelCount() > 0;
}

// Calls visit(ijk, ta, tb) for each voxel span of o + t d, t in [0, tMax], in order, through the
// active parts of the grid `intersector` was made for (voxels of size h).
template <class Visit>
void marchVoxels(Intersector& intersector, double h, const Vec3& o, const Vec3& d, double tMax,
                 Visit&& visit)
{
    // OpenVDB's rays start after t = 0 (Ray::setTimes asserts t0 > 0, which a debug build
    // checks): the 1e-9 cm skipped is far below any voxel.
    const double tStart = openvdb::math::Delta<double>::value();
    if (!(tMax > tStart)) return;
    using RayT = openvdb::math::Ray<double>;
    const RayT ray(openvdb::Vec3d(o.x, o.y, o.z), openvdb::Vec3d(d.x, d.y, d.z), tStart, tMax);
    if (!intersector.setWorldRay(ray)) return;
    double i0, i1;
    while (intersector.march(i0, i1)) {
        const double w0 = std::max(0.0, intersector.getWorldTime(i0));
        const double w1 = std::min(tMax, intersector.getWorldTime(i1));
        walkVoxels(o, d, h, w0, w1, visit);
    }
}

// The grids as one thread reads them, through the extinction law they were baked with.
struct FieldReader {
    const bake::ExtinctionLaw& law;
    openvdb::Vec3SGrid::ConstAccessor gradient, needle, albedo;
    openvdb::FloatGrid::ConstAccessor opacity, coverage;
    std::optional<openvdb::Int32Grid::ConstAccessor> trees;
    explicit FieldReader(const bake::TreeGrids& g)
        : law(bake::extinctionLaw(g.extinctionLaw)),
          gradient(g.layerGradient->getConstAccessor()),
          needle(g.needleDirection->getConstAccessor()),
          albedo(g.needleAlbedo->getConstAccessor()),
          opacity(g.layerOpacity->getConstAccessor()),
          coverage(g.needleCoverage->getConstAccessor())
    {
        if (g.tree) trees = g.tree->getConstAccessor();
    }
    /// The tree whose layered fields voxel ijk keeps (bake::TreeGrids::tree), -1 if unknown.
    int tree(const openvdb::Coord& ijk) { return trees ? trees->getValue(ijk) : -1; }
    /// A line along d through voxel ijk, per cm: the law's sigma(d) and the layers crossed,
    /// d . G (signed); both 0 outside the boughs.
    struct Rates {
        double sigma = 0.0, layers = 0.0;
    };
    Rates rates(const openvdb::Coord& ijk, const Vec3& d)
    {
        float A;
        if (!opacity.probeValue(ijk, A) || !(A > 0.0f)) return {};
        bake::LayerSample field;  // all of it: a law may read any field
        field.layerOpacity = A;
        field.gradient = toGlm(gradient.getValue(ijk));
        field.needle = toGlm(needle.getValue(ijk));
        field.needleCoverage = coverage.getValue(ijk);
        return {law.extinction(field, d), glm::dot(d, field.gradient)};
    }
};

// One line's spans through the field, in order: the transmittance of each, exp(-sigma dt) for
// an extinction law, the bands of evenly spaced needles for a banded one (layer_bands.h).
//
// A line that enters a bough from outside (a view's line, or a light's past its own bough)
// meets its layers at an unknown phase, and LayerBands averages over it. A line from a
// needle's point (towards a light) starts on one of its bough's layers: there the layers lie
// where it has crossed a whole number of them, on its way out and, past the axis, on its way
// back (LayersFromALayer); bands spread from the point counted half a layer too many where the
// line left the bough and again at each turn (the reference's needles read 16-19% dark under
// self-shadowing on three firs, docs/models.md). (The light grid's lines start at voxel
// centres, each standing for the needles of its voxel.) The point's bough ends at a gap in the
// medium or a voxel of none, and boughs met after it at a phase of their own; a bough touching
// it with no gap is counted on as if its layers were in step.
class LineThroughField {
public:
    explicit LineThroughField(const bake::ExtinctionLaw& law) : mBanded(law.banded()) {}
    /// A line from a needle's point, on a layer: `gap_cm` is how far apart two spans may be
    /// and still be one stretch of the point's bough.
    LineThroughField(const bake::ExtinctionLaw& law, double gap_cm)
        : mBanded(law.banded()), mOnOwnBough(mBanded), mGap_cm(gap_cm)
    {
    }

    /// The span's own transmittance.
    double transmittance(const FieldReader::Rates& r, double ta, double tb)
    {
        if (!mBanded) return std::exp(-r.sigma * (tb - ta));
        if (!(tb > ta)) return 1.0;  // an empty span (a surface on a voxel's face) is no gap
        if (ta > mEnd) mBands.span(0.0, 0.0);  // out of the medium and in again: a new band
        mEnd = tb;
        return mBands.span(r.sigma * (tb - ta), r.layers * (tb - ta));
    }

    /// T, the line's transmittance up to the span, carried across it.
    double attenuated(double T, const FieldReader::Rates& r, double ta, double tb)
    {
        if (mOnOwnBough && (ta > mOwnEnd + mGap_cm || !(r.sigma > 0.0))) mOnOwnBough = false;
        if (!mOnOwnBough) return T * transmittance(r, ta, tb);
        mOwnEnd = tb;
        return T * mOwn.span(r.sigma * (tb - ta), r.layers * (tb - ta));
    }

private:
    bool mBanded;
    LayerBands mBands;
    double mEnd = -std::numeric_limits<double>::infinity();
    bool mOnOwnBough = false;  ///< a line from a needle's point, still in its bough
    LayersFromALayer mOwn;
    double mGap_cm = 0.0, mOwnEnd = 0.0;
};

// The light o + t d, t in [0, tMax], lets through the field, read by `line`'s rule.
double lineTransmittance(Intersector& intersector, FieldReader& field, double h,
                         LineThroughField line, const Vec3& o, const Vec3& d, double tMax)
{
    double T = 1.0;
    marchVoxels(intersector, h, o, d, tMax, [&](const openvdb::Coord& ijk, double ta, double tb) {
        if (T > 0.0) T = line.attenuated(T, field.rates(ijk, d), ta, tb);
    });
    return T;
}

class ReferenceRayTracer;

// What every thread shares: the grids, their intersector, and the light reaching each voxel.
class Reference final : public ShadingMethod {
public:
    /// `preparing` hears how far the light grids are (RenderOptions::preparing).
    Reference(const TracedScene& scene, const bake::TreeGrids& grids,
              const ReferenceOptions& options,
              const std::function<void(const std::string&, double)>& preparing = {});

    int samplesPerPixel() const override { return mSubpixels * mSubpixels; }
    ConeRay sample(const ConeCamera& camera, int x, int y, int s) const override
    {
        return camera.subpixelCone(x, y, s, mSubpixels);
    }
    std::unique_ptr<RayTracer> rayTracer(RenderStats& stats) const override;

    /// One thread's view of the grids.
    struct Thread {
        explicit Thread(const Reference& r)
            : intersector(r.mHasVolume ? std::make_unique<Intersector>(*r.mIntersector)
                                       : nullptr),
              field(r.mGrids)
        {
        }
        std::unique_ptr<Intersector> intersector;
        FieldReader field;
    };

    /// Calls visit(ijk, ta, tb) for each voxel span of o + t d, t in [0, tMax], in order.
    template <class Visit>
    void march(Thread& thread, const Vec3& o, const Vec3& d, double tMax, Visit&& visit) const
    {
        if (mHasVolume) marchVoxels(*thread.intersector, mH, o, d, tMax, visit);
    }

    /// Transmittance from x to light `light` through the grids, and with shadows through the
    /// branches (the shadow cone as wide as `footprint_cm` at x). `onLayer`: x is a needle's,
    /// which lies on one of its bough's layers.
    double transmittance(Thread& thread, const Vec3& x, std::size_t light, double footprint_cm,
                         std::size_t self, bool onLayer = false) const
    {
        Vec3 L, irradiance;
        double distance;
        mScene.lights[light].at(x, L, distance, irradiance);
        const double tMax = std::isfinite(distance) ? distance : 1e7;
        double T = 1.0;
        if (mHasVolume) {
            T = lineTransmittance(*thread.intersector, thread.field, mH,
                                  onLayer ? LineThroughField(thread.field.law, 1e-6 * mH)
                                          : LineThroughField(thread.field.law),
                                  x, L, tMax);
        }
        if (mPlan.shadowRays) {
            T *= shadowConeTransmittance(mScene, x, light, footprint_cm, self, false);
        }
        return T;
    }

private:
    friend class ReferenceRayTracer;  // reads the grids and the light grids per thread
    const TracedScene& mScene;
    const bake::TreeGrids& mGrids;
    const EffectsPlan mPlan;
    const int mSubpixels;
    const bool mHasVolume;
    const double mH;
    std::unique_ptr<Intersector> mIntersector;
    // Per light, the transmittance at voxel centres: each voxel of the boughs and its 26
    // neighbours, so that a point anywhere in the medium interpolates between centres that
    // were all computed (background 1 only farther out).
    std::vector<openvdb::FloatGrid::Ptr> mLightTransmittance;
    // The needles' specular lobe (not baked): per tree, the first bough's (species set it);
    // for voxels of no known tree, the scene's first bough's.
    struct Specular {
        double weight = 0.0, exponent = 100.0;
    };
    std::vector<Specular> mSpecularOfTree;
    Specular mSpecular;
    const Specular& specularOf(int tree) const
    {
        return tree >= 0 && std::size_t(tree) < mSpecularOfTree.size()
                   ? mSpecularOfTree[std::size_t(tree)]
                   : mSpecular;
    }
};

class ReferenceRayTracer final : public ShadingMethod::RayTracer, private LightTransport {
public:
    ReferenceRayTracer(const Reference& method, RenderStats& stats)
        : mMethod(method), mThread(method), mStats(stats),
          mSurfaces(method.mScene, method.mPlan, *this, stats)
    {
        for (const auto& g : method.mLightTransmittance) mLightT.push_back(g->getConstAccessor());
        for (std::size_t i = 0; i < mLightT.size(); ++i) {  // each reads its own accessor
            mLightAt.emplace_back(mLightT[i], method.mLightTransmittance[i]->transform());
        }
    }

    void trace(const ConeRay& ray, FrontToBack& composite) override;

private:
    double transmittance(const Vec3& x, std::size_t light, double footprint_cm,
                         std::size_t self, const ShadowSamples*) override
    {
        return mMethod.transmittance(mThread, x, light, footprint_cm, self);
    }
    // The needles' emission J of voxel ijk of tree `tree` (diffuse, specular) at x, lit through
    // the light grids read trilinearly at x.
    void emission(const openvdb::Coord& ijk, int tree, const Vec3& x, const Vec3& V, Vec3& jd,
                  Vec3& js);

    const Reference& mMethod;
    Reference::Thread mThread;
    RenderStats& mStats;
    SurfaceShading mSurfaces;
    std::vector<openvdb::FloatGrid::ConstAccessor> mLightT;
    using LightSampler =
        openvdb::tools::GridSampler<openvdb::FloatGrid::ConstAccessor, openvdb::tools::BoxSampler>;
    std::vector<LightSampler> mLightAt;  // over mLightT, which must not move
    std::vector<Fragment> mSurfaceFragments;
};

Reference::Reference(const TracedScene& scene, const bake::TreeGrids& grids,
                     const ReferenceOptions& options,
                     const std::function<void(const std::string&, double)>& preparing)
    : mScene(scene),
      mGrids(grids),
      mPlan(EffectsPlan::from(scene.scene->effects)),
      mSubpixels(std::max(1, options.subpixels)),
      mHasVolume(hasVolume(grids)),
      mH(grids.voxelSize_cm)
{
    if (mHasVolume) mIntersector = std::make_unique<Intersector>(*grids.layerOpacity);
    if (!scene.boughs.empty()) {
        mSpecular = {scene.boughs.front().specularWeight, scene.boughs.front().exponent};
    }
    mSpecularOfTree.assign(scene.treeCounts.size(), mSpecular);
    std::vector<bool> seen(mSpecularOfTree.size(), false);
    for (const TracedBough& b : scene.boughs) {
        const std::size_t t = std::size_t(b.tree);
        if (b.tree < 0 || t >= seen.size() || seen[t]) continue;
        seen[t] = true;
        mSpecularOfTree[t] = {b.specularWeight, b.exponent};
    }
    if (!mHasVolume || !(mPlan.shadowRays || mPlan.selfShadowing)) return;
    // The light reaching each voxel's centre depends on the voxel, not on the view: once per
    // voxel and light, through every bough's layers (and branches, with shadows). A span reads
    // it trilinearly where it lies: read at its voxel's centre, the light a span near the lit
    // face of a bough sees was what half a voxel of needles lets through, which darkened the
    // reference against the needles by about what that half voxel stops (docs/models.md).
    // Minutes on a forest at 0.25 cm: told by the leaves lit, over every light.
    const std::size_t lights = mScene.lights.size();
    std::optional<ProgressSteps> steps;
    std::string stage;
    for (std::size_t li = 0; li < lights; ++li) {
        auto grid = openvdb::FloatGrid::create(1.0f);
        grid->setTransform(mGrids.layerOpacity->transform().copy());
        grid->tree().topologyUnion(mGrids.layerOpacity->tree());
        grid->tree().voxelizeActiveTiles();  // a pruned bake's tiles get values too
        openvdb::tools::dilateActiveValues(grid->tree(), 1, openvdb::tools::NN_FACE_EDGE_VERTEX,
                                           openvdb::tools::EXPAND_TILES);
        openvdb::tree::LeafManager<openvdb::FloatTree> leaves(grid->tree());
        if (li == 0) {
            steps.emplace(leaves.leafCount() * lights, 100);
            stage = "lighting " + std::to_string(grid->activeVoxelCount()) + " voxels" +
                    (lights > 1 ? " for " + std::to_string(lights) + " lights" : "");
        }
        leaves.foreach([&](openvdb::FloatTree::LeafNodeType& leaf, std::size_t) {
            Thread thread(*this);
            for (auto it = leaf.beginValueOn(); it; ++it) {
                const openvdb::Vec3d c = grid->transform().indexToWorld(it.getCoord());
                const Vec3 x(c.x(), c.y(), c.z());
                it.setValue(float(transmittance(thread, x, li, mH, kNoPrimitive, true)));
            }
            double fraction;
            if (steps->finished(fraction) && preparing) preparing(stage, fraction);
        });
        mLightTransmittance.push_back(grid);
    }
}

std::unique_ptr<ShadingMethod::RayTracer> Reference::rayTracer(RenderStats& stats) const
{
    return std::make_unique<ReferenceRayTracer>(*this, stats);
}

void ReferenceRayTracer::emission(const openvdb::Coord& ijk, int tree, const Vec3& x, const Vec3& V,
                                  Vec3& jd, Vec3& js)
{
    const EffectsPlan& plan = mMethod.mPlan;
    const Reference::Specular& specular = mMethod.specularOf(tree);
    const Vec3 needle = toGlm(mThread.field.needle.getValue(ijk));
    const Vec3 albedo = toGlm(mThread.field.albedo.getValue(ijk));
    for (std::size_t i = 0; i < mMethod.mScene.lights.size(); ++i) {
        Vec3 L, E;
        double distance;
        mMethod.mScene.lights[i].at(x, L, distance, E);
        if (!mLightAt.empty()) E *= double(mLightAt[i].wsSample(openvdb::Vec3d(x.x, x.y, x.z)));
        if (plan.diffuse) {
            jd += albedo / kPi * E * analytic::needleDiffuse(needle, L, V);
            ++mStats.diffuseEvaluations;
        }
        if (plan.specular) {
            js += specular.weight * E * analytic::needleSpecular(needle, L, V, specular.exponent);
            ++mStats.specularEvaluations;
        }
    }
}

void ReferenceRayTracer::trace(const ConeRay& ray, FrontToBack& composite)
{
    const TracedScene& scene = mMethod.mScene;
    // Surfaces first (branches and ground), sorted, then composited where they lie among the
    // volume's spans.
    std::vector<Fragment>& surfaces = mSurfaceFragments;
    surfaces.clear();
    Fragment ground;
    const bool hasGround = mSurfaces.ground(ray, ground);
    const double tEnd = hasGround ? ground.t : 1e7;
    scene.bvh.query(ray, tEnd, [&](std::uint32_t index) {
        Fragment f;
        if (scene.isBranch(index) && mSurfaces.branch(ray, index, tEnd, f)) surfaces.push_back(f);
    });
    if (hasGround) surfaces.push_back(ground);
    std::sort(surfaces.begin(), surfaces.end(),
              [](const Fragment& a, const Fragment& b) { return a.t < b.t; });

    const Vec3 V = -ray.direction;
    LineThroughField line(mThread.field.law);
    std::size_t next = 0;
    mMethod.march(mThread, ray.origin, ray.direction, tEnd,
                  [&](const openvdb::Coord& ijk, double ta, double tb) {
        if (composite.opaque()) return;
        ++mStats.voxelSpans;
        const FieldReader::Rates rates = mThread.field.rates(ijk, ray.direction);
        Vec3 jd(0.0), js(0.0);
        int tree = -1;
        if (rates.sigma > 0.0) {
            tree = mThread.field.tree(ijk);
            emission(ijk, tree, ray.origin + 0.5 * (ta + tb) * ray.direction, V, jd, js);
        }
        // The volume over [t0, t1] as a fragment: its opacity, and J premultiplied by it.
        const auto volume = [&](double t0, double t1) {
            const double alpha = 1.0 - line.transmittance(rates, t0, t1);
            composite.add(Fragment{t0, alpha, alpha * jd, alpha * js, 0, true, tree});
        };
        while (next < surfaces.size() && surfaces[next].t <= tb) {
            const double ts = std::max(ta, surfaces[next].t);
            if (rates.sigma > 0.0) volume(ta, ts);
            composite.add(surfaces[next++]);
            ta = ts;
        }
        if (rates.sigma > 0.0) volume(ta, tb);
    });
    while (next < surfaces.size() && !composite.opaque()) composite.add(surfaces[next++]);
}

}  // namespace

struct FieldTransmittance::Reader {
    explicit Reader(const bake::TreeGrids& g)
        : intersector(*g.layerOpacity), field(g), h(g.voxelSize_cm)
    {
    }
    Intersector intersector;
    FieldReader field;
    double h;
};

FieldTransmittance::FieldTransmittance(const bake::TreeGrids& grids)
    : mReader(hasVolume(grids) ? std::make_unique<Reader>(grids) : nullptr)
{
}

FieldTransmittance::FieldTransmittance(FieldTransmittance&&) noexcept = default;
FieldTransmittance& FieldTransmittance::operator=(FieldTransmittance&&) noexcept = default;
FieldTransmittance::~FieldTransmittance() = default;

double FieldTransmittance::operator()(const Vec3& o, const Vec3& d, double tMax)
{
    if (!mReader) return 1.0;
    return lineTransmittance(mReader->intersector, mReader->field, mReader->h,
                             LineThroughField(mReader->field.law), o, d, tMax);
}

RenderResult renderReference(const TracedScene& scene, const bake::TreeGrids& grids,
                             const ReferenceOptions& method, const RenderOptions& options)
{
    using Clock = std::chrono::steady_clock;
    const auto start = Clock::now();
    const Reference reference(scene, grids, method, options.preparing);  // every voxel's light
    const double prepSeconds = std::chrono::duration<double>(Clock::now() - start).count();
    RenderResult result = renderImage(scene, reference, options);
    result.seconds += prepSeconds;
    result.prepSeconds += prepSeconds;
    return result;
}

}  // namespace pine::vdbtrace
