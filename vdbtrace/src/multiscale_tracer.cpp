#include "pine/vdbtrace/multiscale_tracer.h"

#include "pine/analytic/needle_shader.h"
#include "pine/vdbtrace/cone_crossings.h"
#include "pine/vdbtrace/effects_plan.h"
#include "pine/vdbtrace/layer_model.h"
#include "pine/vdbtrace/needle_layout.h"
#include "pine/vdbtrace/render_driver.h"
#include "pine/vdbtrace/surface_shading.h"

#include <glm/geometric.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>
#include <vector>

namespace pine::vdbtrace {
namespace {

constexpr double kPi = analytic::kPi;

// One thread's tracer. Its light transport is the cone shadow ray through the branches and
// the boughs, each bough by its law's opacity seen from the light.
class MultiscaleRayTracer final : public ShadingMethod::RayTracer, private LightTransport {
public:
    MultiscaleRayTracer(const TracedScene& scene, const EffectsPlan& plan, int forceLevel,
                        RenderStats& stats)
        : mScene(scene), mPlan(plan), mSettings(scene.scene->render), mForceLevel(forceLevel),
          mStats(stats), mSurfaces(scene, plan, *this, stats)
    {
    }

    void trace(const ConeRay& ray, FrontToBack& composite) override;

private:
    double transmittance(const Vec3& x, std::size_t light, double footprint_cm,
                         std::size_t self) override
    {
        return shadowConeTransmittance(mScene, x, light, footprint_cm, self, true);
    }
    void addBough(const ConeRay& ray, std::size_t index);
    void addCrossings(const ConeRay& ray, std::size_t index, const TracedBough& b, double tIn,
                      double tOut, double coverage, Level level);
    // A needle of cone `cone` at x, its light through the bough's other layers under the
    // layer model (section 6's self-shadowing at levels 1-2, counted, not approximated).
    void shadeNeedle(const TracedBough& b, long cone, const Vec3& needle, const Vec3& x,
                     const Vec3& V, double alpha, double t, int level,
                     const std::vector<Incident>& light);

    const TracedScene& mScene;
    const EffectsPlan& mPlan;
    const scenes::RenderSettings& mSettings;
    int mForceLevel;
    RenderStats& mStats;
    SurfaceShading mSurfaces;
    std::vector<Fragment> mFragments;
    std::vector<std::pair<long, long>> mNeedlesSeen;  ///< (cone, needle) found on this ray
    std::vector<LayerHit> mLayerHits;                 ///< a bough's layers on this ray
};

void MultiscaleRayTracer::shadeNeedle(const TracedBough& b, long cone, const Vec3& needle,
                                      const Vec3& x, const Vec3& V, double alpha, double t,
                                      int level, const std::vector<Incident>& light)
{
    Fragment f{t, alpha, Vec3(0.0), Vec3(0.0), level, true};
    for (const Incident& l : light) {
        double self = 1.0;
        if (mPlan.selfShadowing) {
            ++mStats.selfShadowEvaluations;
            self = mScene.layers->transmittance(b, x, l.towards, cone);
        }
        const Vec3 E = l.irradiance * self;
        if (mPlan.diffuse) {
            f.diffuse +=
                alpha * b.needleAlbedo / kPi * E * analytic::needleDiffuse(needle, l.towards, V);
            ++mStats.diffuseEvaluations;
        }
        if (mPlan.specular) {
            f.specular += alpha * b.specularWeight * E *
                          analytic::needleSpecular(needle, l.towards, V, b.exponent);
            ++mStats.specularEvaluations;
        }
    }
    mFragments.push_back(f);
}

void MultiscaleRayTracer::addCrossings(const ConeRay& ray, std::size_t index,
                                       const TracedBough& b, double tIn, double tOut,
                                       double coverage, Level level)
{
    const double phi = b.geometry.cone.aperture_rad;
    const double cotPhi = 1.0 / std::tan(phi), sinPhi = std::sin(phi), cosPhi = std::cos(phi);
    const Vec3 V = -ray.direction;
    const Vec3 mid = ray.origin + 0.5 * (tIn + tOut) * ray.direction;
    const std::vector<Incident>& light = mSurfaces.lightAt(mid, ray.width(0.5 * (tIn + tOut)),
                                                           index);
    // The same needles as the explicit-needle ground truth (needle_layout.h).
    const NeedleLayout layout(b);
    const Vec3 e1 = layout.e1(), e2 = layout.e2();
    const int needles = layout.needlesPerCone();
    const double r = layout.radius(), l = layout.length();

    if (level == Level::Cone) {
        // Level 2: each layer as the layer model stops the ray, shaded as its needle there.
        // The bough covers `coverage` of the footprint and its layers lie over one another
        // within it: together they cover coverage (1 - prod(1 - alpha_i)), which the layers
        // composited alone, each of opacity coverage alpha_i, exceed where coverage < 1 (the
        // edge of the strip). So each layer's share of the bough's coverage is what it
        // composites.
        mLayerHits.clear();
        mScene.layers->layers(b, ray.origin, ray.direction, tIn, tOut,
                              [&](const LayerHit& hit) { mLayerHits.push_back(hit); });
        std::stable_sort(mLayerHits.begin(), mLayerHits.end(),
                         [](const LayerHit& x, const LayerHit& y) { return x.t < y.t; });
        double covered = 0.0;  // by this bough's layers in front, of the footprint
        for (const LayerHit& hit : mLayerHits) {
            double rho;
            Vec3 radial;
            coneHeight(b, cotPhi, ray.origin + hit.t * ray.direction, &rho, &radial);
            if (!(rho > 1e-9)) continue;
            ++mStats.coneHits;
            double alpha = coverage * hit.opacity;
            if (coverage < 1.0) {
                const double share = (coverage - covered) * hit.opacity;
                alpha = covered < 1.0 ? share / (1.0 - covered) : 0.0;
                covered += share;
            }
            const Vec3 needle = cosPhi * b.axis + sinPhi * radial;
            shadeNeedle(b, hit.cone, needle, ray.origin + hit.t * ray.direction, V, alpha,
                        hit.t, 2, light);
        }
        return;
    }
    // Level 1: the needles of each cone the ray passes (cone_crossings.h's bands: also where it
    // passes a cone without crossing it, as along its silhouette), nearest the azimuth where
    // it passes them, as cylinders; each needle once, though the ray may pass its cone twice.
    mNeedlesSeen.clear();
    forEachConeBand(b, ray.origin, ray.direction, tIn, tOut, [&](const ConeBand& band) {
        const long j = band.cone;
        const double tc = band.t;
        double rho;
        Vec3 radial;
        coneHeight(b, cotPhi, ray.origin + tc * ray.direction, &rho, &radial);
        if (!(rho > 1e-9)) return true;
        const double theta = std::atan2(glm::dot(radial, e2), glm::dot(radial, e1));
        const long nearest = std::lround((theta - layout.roll(j)) * needles / (2 * kPi));
        const Vec3 apex = layout.apex(j);
        // The nearest needle and its two neighbours, each once: with fewer than three
        // needles per cone the neighbours wrap onto the same needles.
        const long from = needles >= 3 ? nearest - 1 : 0;
        const long to = needles >= 3 ? nearest + 1 : needles - 1;
        for (long i = from; i <= to; ++i) {
            const std::pair<long, long> key{j, ((i % needles) + needles) % needles};
            if (std::find(mNeedlesSeen.begin(), mNeedlesSeen.end(), key) != mNeedlesSeen.end()) {
                continue;
            }
            mNeedlesSeen.push_back(key);
            const Vec3 needle = layout.direction(layout.azimuth(j, i));
            Passage p;
            if (!closestPassage(ray, apex, apex + l * needle, p)) continue;
            const double c = stripCoverage(p.gap, r, ray.width(p.t));
            if (c <= 0.0) continue;
            ++mStats.needleHits;
            shadeNeedle(b, j, needle, ray.origin + p.t * ray.direction, V, c, p.t, 1, light);
        }
        return true;
    });
}

void MultiscaleRayTracer::addBough(const ConeRay& ray, std::size_t index)
{
    const TracedBough& b = mScene.bough(index);
    // Where the cone passes the needles: they reach from the base to the cones' end.
    Passage p;
    if (!closestPassage(ray, b.base_cm, b.conesEnd_cm, p)) return;
    const double w = ray.width(p.t);
    const double c = stripCoverage(p.gap, b.radius_cm, w);
    if (c <= 0.0) return;
    // The chord's signed offset from the axis, across the strip (bough_law.h).
    const double xi =
        std::copysign(p.gap, glm::dot(ray.origin + p.t * ray.direction - b.base_cm, b.across));
    const Level level = mForceLevel ? Level(mForceLevel)
                                    : chooseLevel(w, b.geometry.coneSpacing_cm, mSettings);
    double tIn, tOut;
    if (level != Level::Bough) {
        // Cones and needles are found along the cone's axis; where the axis misses them the
        // footprint only grazes the bough: shade the volume.
        if (layeredInterval(b, ray.origin, ray.direction, tIn, tOut)) {
            addCrossings(ray, index, b, tIn, tOut, c, level);
            return;
        }
    }
    // The volume spans base to the law's strip end: the tip (the cones' region sheared into a
    // cylinder of equal volume) or the cones' end (the exact law, whose chords cover them).
    if (!closestPassage(ray, b.base_cm, b.stripEnd_cm, p)) return;
    if (!intersectCylinder(ray, b.base_cm, b.stripEnd_cm, b.radius_cm, tIn, tOut)) {
        tIn = tOut = p.t;
    }

    // Level 3: section 6 per light under the bough law, front half at the entry and rear
    // half at the middle, so that the branch inside sorts between them. Each profile is read
    // over the footprint at the chord's signed offset from the axis.
    ++mStats.boughHits;
    const Vec3 passage = ray.origin + p.t * ray.direction;
    const double R = b.radius_cm;
    const double frontAlpha = b.alpha.front.overFootprint(xi, R, w);
    // What the rear's share is divided by to composite behind the front (bough_law.h).
    const double behindFront =
        b.rearComposite == RearComposite::Share ? 1.0 - frontAlpha : 1.0;
    const auto rearPart = [&](const StripProfile& profile) {
        return behindFront > 1e-9 ? profile.overFootprint(xi, R, w) / behindFront : 0.0;
    };
    const std::vector<Incident>& light = mSurfaces.lightAt(passage, w, index);
    Fragment front{tIn, frontAlpha, Vec3(0.0), Vec3(0.0), 3, true};
    Fragment rear{0.5 * (tIn + tOut), rearPart(b.alpha.rear), Vec3(0.0), Vec3(0.0), 3, true};
    for (std::size_t i = 0; i < light.size(); ++i) {
        const BoughLighting& lit = b.lighting[i];
        const Vec3& E = light[i].irradiance;
        // Without self-shadowing the whole opacity reflects; with it, the law's transfer.
        const FrontRearProfile& transfer = mPlan.selfShadowing ? lit.transfer : b.alpha;
        const double tf = transfer.front.overFootprint(xi, R, w);
        const double tr = rearPart(transfer.rear);
        mStats.selfShadowEvaluations += mPlan.selfShadowing ? 2 : 0;
        if (mPlan.diffuse) {
            front.diffuse += tf * lit.front.diffuse * b.needleAlbedo / kPi * E;
            rear.diffuse += tr * lit.rear.diffuse * b.needleAlbedo / kPi * E;
            mStats.diffuseEvaluations += 2;
        }
        if (mPlan.specular) {
            front.specular += tf * lit.front.specular * b.specularWeight * E;
            rear.specular += tr * lit.rear.specular * b.specularWeight * E;
            mStats.specularEvaluations += 2;
        }
    }
    mFragments.push_back(front);
    mFragments.push_back(rear);
}

void MultiscaleRayTracer::trace(const ConeRay& ray, FrontToBack& composite)
{
    mFragments.clear();
    Fragment ground;
    const bool hasGround = mSurfaces.ground(ray, ground);
    const double tMax = hasGround ? ground.t : std::numeric_limits<double>::infinity();
    mScene.bvh.query(ray, tMax, [&](std::uint32_t index) {
        if (!mScene.isBranch(index)) return addBough(ray, index);
        Fragment f;
        if (mSurfaces.branch(ray, index, tMax, f)) mFragments.push_back(f);
    });
    if (hasGround) mFragments.push_back(ground);
    std::sort(mFragments.begin(), mFragments.end(),
              [](const Fragment& a, const Fragment& b) { return a.t < b.t; });
    for (const Fragment& f : mFragments) {
        if (composite.opaque()) break;
        composite.add(f);
    }
}

class Multiscale final : public ShadingMethod {
public:
    Multiscale(const TracedScene& scene, const MultiscaleOptions& options)
        : mScene(scene), mPlan(EffectsPlan::from(scene.scene->effects)), mOptions(options)
    {
    }
    int samplesPerPixel() const override { return 1; }
    ConeRay sample(const ConeCamera& camera, int x, int y, int) const override
    {
        return camera.cone(x, y);
    }
    std::unique_ptr<RayTracer> rayTracer(RenderStats& stats) const override
    {
        return std::make_unique<MultiscaleRayTracer>(mScene, mPlan, mOptions.forceLevel, stats);
    }

private:
    const TracedScene& mScene;
    EffectsPlan mPlan;
    MultiscaleOptions mOptions;
};

}  // namespace

Level chooseLevel(double footprint_cm, double coneSpacing_cm, const scenes::RenderSettings& s)
{
    const double q = footprint_cm / coneSpacing_cm;
    if (q < s.needleLevelMax) return Level::Needle;
    if (q < s.coneLevelMax) return Level::Cone;
    return Level::Bough;
}

RenderResult renderMultiscale(const TracedScene& scene, const MultiscaleOptions& method,
                              const RenderOptions& options)
{
    return renderImage(scene, Multiscale(scene, method), options);
}

}  // namespace pine::vdbtrace
