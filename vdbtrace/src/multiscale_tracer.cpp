#include "pine/vdbtrace/multiscale_tracer.h"

#include "pine/analytic/needle_shader.h"
#include "pine/vdbtrace/bough_shadows.h"
#include "pine/vdbtrace/cone_crossings.h"
#include "pine/vdbtrace/effects_plan.h"
#include "pine/vdbtrace/ground_hit.h"
#include "pine/vdbtrace/layer_model.h"
#include "pine/vdbtrace/needle_layout.h"
#include "pine/vdbtrace/render_driver.h"
#include "pine/vdbtrace/surface_shading.h"

#include <glm/geometric.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <memory>
#include <utility>
#include <vector>

namespace pine::vdbtrace {
namespace {

constexpr double kPi = analytic::kPi;

// Where a bough's needles lie along a cone ray's chord through it, at level 3: each half from
// the chord's end to its middle, less the bark about the axis within which the layer models
// count no needle (TracedBough::barkRadius_cm). Each half is taken as three even thirds. The
// bark is taken along the whole strip, past the tip to the cones' end too (where the law's
// strip reaches it), where the next bough of a chain continues the branch: there the front's
// last third, taken to the axis, sorted behind that bough's branch (bough.json's junctions
// lost up to 0.075 of their foliage along the axis).
struct ChordHalves {
    double tIn, tMid, tOut;      ///< the chord through the bough's cylinder, and its middle
    double frontEnd, rearStart;  ///< where the bark begins and ends along it (else tMid)
    /// The middle of third `j` (0-2, front to back) of the front half (`half` 0) or the rear.
    double third(int half, int j) const
    {
        const double u = (j + 0.5) / 3.0;
        return half == 0 ? tIn + u * (frontEnd - tIn) : rearStart + u * (tOut - rearStart);
    }
};

// The chord [tIn, tOut] of `ray` through bough `b`, whose axis the ray passes at `p`, in halves.
ChordHalves chordHalves(const ConeRay& ray, const TracedBough& b, const Passage& p, double tIn,
                        double tOut)
{
    const double tMid = 0.5 * (tIn + tOut);
    ChordHalves chord{tIn, tMid, tOut, tMid, tMid};
    const double sinTheta = glm::length(glm::cross(b.axis, ray.direction));
    if (b.barkRadius_cm > p.gap && sinTheta > 1e-9) {
        // The bark about the axis, entered and left at p.t -+ its half chord there.
        const double half = std::sqrt(b.barkRadius_cm * b.barkRadius_cm - p.gap * p.gap) / sinTheta;
        chord.frontEnd = std::clamp(p.t - half, tIn, tMid);
        chord.rearStart = std::clamp(p.t + half, tMid, tOut);
    }
    return chord;
}

bool contains(const std::vector<std::uint32_t>& indices, std::uint32_t index)
{
    return std::find(indices.begin(), indices.end(), index) != indices.end();
}

// One thread's tracer. Its light transport is the cone shadow ray through the branches and
// the boughs, each bough by its law's opacity seen from the light.
class MultiscaleRayTracer final : public ShadingMethod::RayTracer, private LightTransport {
public:
    MultiscaleRayTracer(const TracedScene& scene, const EffectsPlan& plan, int forceLevel,
                        const BoughShadows* boughShadows, RenderStats& stats)
        : mScene(scene), mPlan(plan), mSettings(scene.scene->render), mForceLevel(forceLevel),
          mBoughShadows(boughShadows), mStats(stats), mSurfaces(scene, plan, *this, stats)
    {
    }

    void trace(const ConeRay& ray, FrontToBack& composite) override;
    int pixelSplit(const ConeRay& pixel, const ConeRay& square) const override
    {
        const double qMax = mSettings.model.pixelSplitQ;
        if (!(qMax > 0.0)) return 1;
        const double q = mShadedBough ? mCoarsestQ : coarsestQ(pixel, square);
        if (!(q > qMax)) return 1;
        return int(std::min(std::ceil(q / qMax), double(scenes::ModelChoices::kMaxPixelSplit)));
    }

private:
    double transmittance(const Vec3& x, std::size_t light, double footprint_cm,
                         std::size_t self, const ShadowSamples* samples) override
    {
        return shadowConeTransmittance(mScene, x, light, footprint_cm, self, true, samples);
    }
    void addBough(const ConeRay& ray, std::size_t index);
    // After trace(pixel) shaded no bough: the largest footprint / dh of a bough within
    // `square`, the disc through the pixel's corners, nearer than where the pixel's cone
    // turned opaque, each at the pixel's footprint where its segment comes nearest the pixel's
    // axis. The cone's own disc misses the corners: a bough there alone left its pixel one
    // cone, its foliage a 1-D box across the strip, where its neighbours' split cones weigh it
    // by the square (the three firs' far tree lost 3.2% of its coverage). Only where the cone
    // shaded none: deciding every pixel by its square, hidden boughs and all, split the dense
    // forest's pixels by the far boughs behind its near trees (1280 firs: 93 CPU-s for 55).
    double coarsestQ(const ConeRay& pixel, const ConeRay& square) const;
    // The bough's fragments at `level`, the ray passing its needles at `passage` (base to
    // the cones' end).
    // `branchBetween`: the bough's own branch's fragment composites with these fragments, at
    // its depth between level 3's halves (false within a level blend whose branch this ray
    // drew before, or misses).
    void addBoughAt(const ConeRay& ray, std::size_t index, Level level, const Passage& passage,
                    bool branchBetween = true);
    // Levels 1-2 over [tIn, tOut]; the strip covers `coverage` of the footprint, `w` wide, at
    // signed offset xi from the axis.
    void addCrossings(const ConeRay& ray, std::size_t index, const TracedBough& b, double tIn,
                      double tOut, double coverage, double xi, double w, Level level);
    // A needle of cone `cone` the ray meets at depth t, of which the pixel sees alpha; at
    // level 2, the layer of mLayerHits it stands for.
    struct NeedleHit {
        long cone;
        Vec3 needle;
        double t, alpha;
        std::size_t layer = kNoLayer;
        Vec3 onAxis{0.0};  ///< level 1's: the point of the needle's axis nearest the ray
    };
    static constexpr std::size_t kNoLayer = std::size_t(-1);
    // mLayerHits: bough b's layers along the ray over [tIn, tOut], as the layer model gives them.
    void collectLayers(const ConeRay& ray, const TracedBough& b, double tIn, double tOut);
    // Shades mNeedleHits (levels 1-2): each needle's light through the bough's other layers
    // under the layer model (section 6's self-shadowing, counted, not approximated) and
    // through the scene from where the needles lie.
    // The bough's cones span [tIn, tOut] along the ray.
    void shadeNeedles(const ConeRay& ray, std::size_t index, const TracedBough& b, double tIn,
                      double tOut, int level);
    // Light `light`'s transmittance through the scene to the needles of bough `index` that
    // reflect it, at depths mDepths along the ray with the weight of what each reflects to the
    // pixel: one shadow cone from depth tRef holding them all, each occluder read where each
    // one's shadow line passes it (ShadowSamples), so that an occluding bough is averaged over
    // where the needles lie, not read on one line (the explicit needles send a shadow ray from
    // each). Each point also stands where its needles lie along the light, so that an
    // occluder among them (the bough's own twig) shades only those behind it.
    double shadowOf(const ConeRay& ray, std::size_t index, std::size_t light, double tRef);
    // Level 3's: the needles of each half of the bough that the light reaches lie across the
    // footprint's share of its strip as the law's transfer `litShare` says (most of them along
    // the lit edge of a self-shadowed bough), along the chord [tIn, tOut]. The share is cut
    // into kShadowStrips strips across, each three points per half weighted by what of it is
    // lit (one point in each third of each half of `chord`), each reading the occluders over
    // its own width: one line read over the whole
    // footprint multiplies the occluders' means and samples the strip's middle, where the
    // branch is, not the lit edge. The weights are the lit share, not what it reflects
    // towards the camera (the law's diffuse profile): that alternative, measured, brings
    // neither the paper forest nor the two-bough tests closer to the needles (docs/models.md,
    // "Where along the chord"). `behind` is the opacity the rear half's light lies behind
    // where the law's rear profile does not already hold it (RearComposite::Own: the
    // front's), else null. Returns the mean over all points, and in `byThird` each third's
    // (front half, rear; front to back): its points' weighted mean across the strips.
    double shadowAcross(const ConeRay& ray, std::size_t index, std::size_t light,
                        const FrontRearProfile& litShare, const StripProfile* behind, double xi,
                        double w, const ChordHalves& chord, double (&byThird)[2][3]);

    const TracedScene& mScene;
    const EffectsPlan& mPlan;
    const scenes::RenderSettings& mSettings;
    int mForceLevel;
    const BoughShadows* mBoughShadows;  ///< shadow_origin "bough" with shadows, else null
    RenderStats& mStats;
    SurfaceShading mSurfaces;
    std::vector<Fragment> mFragments;
    std::vector<std::pair<double, std::uint32_t>> mMadeBy;  ///< per fragment: its primitive's
                                                            ///< bound and index
    std::vector<std::size_t> mOrder;  ///< mFragments' indices, composited first
    static constexpr std::uint32_t kGround = std::uint32_t(-1);  ///< in mQueue
    NearestFirstQueue mQueue;  ///< the primitives the ray may yet meet
    std::vector<std::pair<long, long>> mNeedlesSeen;  ///< (cone, needle) found on this ray
    /// The branches this ray met (trace()) and those a bough within a level blend composited
    /// with its own fragments (addBough), which trace() does not draw again.
    std::vector<std::uint32_t> mBranchesMet, mBranchesOfBlends;
    double mTMax = 0.0;  ///< this ray's: where it meets the ground, else infinity
    double mCoarsestQ = 0.0;    ///< this ray's: the largest footprint / dh of a bough it shaded
    bool mShadedBough = false;  ///< this ray's: whether it shaded a bough
    double mOpaqueFrom = 0.0;   ///< this ray's: where it stopped, its composite opaque, or tMax
    std::vector<LayerHit> mLayerHits;                 ///< a bough's layers on this ray
    std::vector<double> mLayerLit;  ///< their (or level 1's needles') self-shadowing, one light
    std::vector<LayerModel::NeedleOnLine> mNeedlesOnRay;  ///< level 1's, for the layer model
    std::vector<NeedleHit> mNeedleHits;               ///< a bough's needles on this ray
    std::vector<std::size_t> mByDepth;                ///< their indices, front to back
    std::vector<double> mSelf;       ///< their self-shadowing, hit-major, one per light
    std::vector<Incident> mLight;    ///< each light at the bough being shaded
    struct Depth {
        double t, weight;  ///< along the ray (cm); of the light reflected to the pixel
    };
    std::vector<Depth> mDepths;  ///< where a bough's lit needles lie: shadowOf
    ShadowSamples mShadowSamples;
    std::vector<double> mPointShadow;  ///< shadowAcross's: each point's transmittance
};

double MultiscaleRayTracer::shadowOf(const ConeRay& ray, std::size_t index, std::size_t light,
                                     double tRef)
{
    const Vec3& L = mLight[light].towards;
    const Vec3 across = ray.direction - glm::dot(ray.direction, L) * L;
    const double stretch = glm::length(across);  // of depth into offset across the light
    const double lift = glm::dot(ray.direction, L);  // of depth into height towards the light
    mShadowSamples.across = stretch > 1e-9 ? across / stretch : Vec3(0.0);
    mShadowSamples.points.clear();
    for (const Depth& d : mDepths) {
        mShadowSamples.points.push_back(
            {(d.t - tRef) * stretch, d.weight, 0.0, (d.t - tRef) * lift});
    }
    mShadowSamples.transmittances = nullptr;
    return mSurfaces.shadow(light, ray.origin + tRef * ray.direction, ray.width(tRef), index,
                            &mShadowSamples);
}

double MultiscaleRayTracer::shadowAcross(const ConeRay& ray, std::size_t index, std::size_t light,
                                         const FrontRearProfile& litShare,
                                         const StripProfile* behind, double xi, double w,
                                         const ChordHalves& chord, double (&byThird)[2][3])
{
    constexpr int kShadowStrips = 4;
    const double tIn = chord.tIn, tMid = chord.tMid, tOut = chord.tOut;
    const TracedBough& b = mScene.bough(index);
    const double R = b.radius_cm;
    const double lo = std::max(xi - 0.5 * w, -R), hi = std::min(xi + 0.5 * w, R);
    const Vec3& L = mLight[light].towards;
    const Vec3 across = ray.direction - glm::dot(ray.direction, L) * L;
    const double stretch = glm::length(across);
    mShadowSamples.across = stretch > 1e-9 ? across / stretch : Vec3(0.0);
    const Vec3 sideways = glm::cross(L, mShadowSamples.across);
    const double side = glm::length(sideways);
    mShadowSamples.sideways = side > 1e-9 ? sideways / side : Vec3(0.0);
    mShadowSamples.points.clear();
    const double strip = (hi - lo) / kShadowStrips;  // cm across each
    for (int k = 0; k < kShadowStrips && strip > 0.0; ++k) {
        const double at = lo + (k + 0.5) * strip;
        // What of each half is lit over this strip (the rear as seen through the front).
        const double front = litShare.front.overFootprint(at, R, strip) * strip;
        double rear = litShare.rear.overFootprint(at, R, strip) * strip;
        if (behind) rear *= 1.0 - behind->overFootprint(at, R, strip);
        // Along the chord, each half's needles at the centres of its thirds.
        for (int j = 0; j < 3; ++j) {
            for (const auto& [t, weight] :
                 {std::pair{chord.third(0, j), front}, std::pair{chord.third(1, j), rear}}) {
                // From the chord's middle to the point: along the ray, then across the strip.
                const Vec3 d = (t - tMid) * ray.direction + (at - xi) * b.across;
                const Vec3 flat = d - glm::dot(d, L) * L;
                mShadowSamples.points.push_back({glm::dot(flat, mShadowSamples.across),
                                                 weight / 3.0,
                                                 glm::dot(flat, mShadowSamples.sideways),
                                                 glm::dot(d, L)});
            }
        }
    }
    if (!(strip > 0.0) || !(tOut > tIn)) {  // a footprint or a chord of no width: its middle
        mDepths.assign(1, {tMid, 1.0});
        const double T = shadowOf(ray, index, light, tMid);
        for (auto& half : byThird) std::fill(std::begin(half), std::end(half), T);
        return T;
    }
    mShadowSamples.transmittances = &mPointShadow;
    const double T =
        mSurfaces.shadow(light, ray.origin + tMid * ray.direction, strip, index, &mShadowSamples);
    // The points went in strip by strip, third by third, front then rear.
    double sum[2][3] = {}, weight[2][3] = {};
    for (std::size_t q = 0; q < mPointShadow.size(); ++q) {
        const std::size_t half = q % 2, third = q / 2 % 3;
        const double wq = mShadowSamples.points[q].weight;
        sum[half][third] += wq * mPointShadow[q];
        weight[half][third] += wq;
    }
    for (int h = 0; h < 2; ++h) {
        for (int j = 0; j < 3; ++j) {
            byThird[h][j] = weight[h][j] > 0.0 ? sum[h][j] / weight[h][j] : T;
        }
    }
    return T;
}

void MultiscaleRayTracer::collectLayers(const ConeRay& ray, const TracedBough& b, double tIn,
                                        double tOut)
{
    mLayerHits.clear();
    mScene.layers->layers(b, ray.origin, ray.direction, tIn, tOut, [&](const LayerHit& hit) {
        mLayerHits.push_back(hit);
        return true;
    });
}

void MultiscaleRayTracer::shadeNeedles(const ConeRay& ray, std::size_t index,
                                       const TracedBough& b, double tIn, double tOut, int level)
{
    if (mNeedleHits.empty()) return;
    const std::size_t lights = mScene.lights.size(), hits = mNeedleHits.size();
    const double tRef = 0.5 * (tIn + tOut);
    mLight.resize(lights);
    for (std::size_t i = 0; i < lights; ++i) {
        mLight[i] = mSurfaces.unshadowed(i, ray.origin + tRef * ray.direction);
    }
    mSelf.assign(hits * lights, 1.0);
    if (mPlan.selfShadowing && level == 2) {
        // Each layer seen through those the ray met in front of it.
        for (std::size_t i = 0; i < lights; ++i) {
            mScene.layers->transmittancesAlong(b, ray.origin, ray.direction, mLayerHits,
                                               mLight[i].towards, mLayerLit);
            for (std::size_t h = 0; h < hits; ++h) {
                ++mStats.selfShadowEvaluations;
                mSelf[h * lights + i] = mLayerLit[mNeedleHits[h].layer];
            }
        }
    } else if (mPlan.selfShadowing) {
        // Level 1's needles, each seen through the layers the ray met before its band.
        collectLayers(ray, b, tIn, tOut);
        mNeedlesOnRay.clear();
        for (const NeedleHit& n : mNeedleHits) {
            mNeedlesOnRay.push_back({n.t, n.cone, n.onAxis});
        }
        for (std::size_t i = 0; i < lights; ++i) {
            mScene.layers->transmittancesAt(b, ray.origin, ray.direction, tIn, tOut, mLayerHits,
                                            mNeedlesOnRay, mLight[i].towards, mLayerLit);
            for (std::size_t h = 0; h < hits; ++h) {
                ++mStats.selfShadowEvaluations;
                mSelf[h * lights + i] = mLayerLit[h];
            }
        }
    }
    if (mBoughShadows && level == 2) {
        for (std::size_t i = 0; i < lights; ++i) {
            mLight[i].irradiance *= mBoughShadows->transmittance(
                index, i, ray.origin + tRef * ray.direction, mStats);
        }
    } else if (mPlan.shadowRays && mScene.shadowOrigin == ShadowOrigin::Axis) {
        for (std::size_t i = 0; i < lights; ++i) {
            mLight[i].irradiance *= mSurfaces.shadow(i, ray.origin + tRef * ray.direction,
                                                     ray.width(tRef), index);
        }
    } else if (mPlan.shadowRays) {
        // The hits front to back; the fragments keep the order they were found in.
        mByDepth.resize(hits);
        for (std::size_t h = 0; h < hits; ++h) mByDepth[h] = h;
        std::sort(mByDepth.begin(), mByDepth.end(), [&](std::size_t x, std::size_t y) {
            return mNeedleHits[x].t < mNeedleHits[y].t;
        });
        for (std::size_t i = 0; i < lights; ++i) {
            mDepths.clear();
            double through = 1.0;  // of the footprint, past this bough's needles in front
            for (const std::size_t h : mByDepth) {
                const NeedleHit& n = mNeedleHits[h];
                mDepths.push_back({n.t, through * n.alpha * mSelf[h * lights + i]});
                through *= 1.0 - n.alpha;
            }
            mLight[i].irradiance *= shadowOf(ray, index, i, tRef);
        }
    }
    const Vec3 V = -ray.direction;
    for (std::size_t h = 0; h < hits; ++h) {
        const NeedleHit& n = mNeedleHits[h];
        Fragment f{n.t, n.alpha, Vec3(0.0), Vec3(0.0), level, true, b.tree};
        for (std::size_t i = 0; i < lights; ++i) {
            const Vec3 E = mLight[i].irradiance * mSelf[h * lights + i];
            const Vec3& L = mLight[i].towards;
            if (mPlan.diffuse) {
                f.diffuse +=
                    n.alpha * b.needleAlbedo / kPi * E * analytic::needleDiffuse(n.needle, L, V);
                ++mStats.diffuseEvaluations;
            }
            if (mPlan.specular) {
                f.specular += n.alpha * b.specularWeight * E *
                              analytic::needleSpecular(n.needle, L, V, b.exponent);
                ++mStats.specularEvaluations;
            }
        }
        mFragments.push_back(f);
    }
}

void MultiscaleRayTracer::addCrossings(const ConeRay& ray, std::size_t index,
                                       const TracedBough& b, double tIn, double tOut,
                                       double coverage, double xi, double w, Level level)
{
    const ApertureTrig trig = apertureTrig(b.geometry.cone.aperture_rad);
    const double cotPhi = trig.oneOverTan, sinPhi = trig.sinPhi, cosPhi = trig.cosPhi;
    mNeedleHits.clear();
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
        collectLayers(ray, b, tIn, tOut);
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
            mNeedleHits.push_back({hit.cone, cosPhi * b.axis + sinPhi * radial, hit.t, alpha,
                                   std::size_t(&hit - mLayerHits.data())});
        }
        // At the strip's edge one line stands for a footprint across which the bough thins:
        // its layers' coverage times the line's opacity is not the footprint's mean, and
        // as the footprint nears the cone spacing it moves with where the pixels fall (up to
        // 3% between neighbouring distances). Where the law is a profile read over the
        // footprint (the exact law's shares), the layers keep their order and shading and
        // take the law's coverage.
        if (coverage < 1.0 && covered > 0.0 && b.rearComposite == RearComposite::Share) {
            const double target =
                bothHalvesOpacity(b.view()->alpha, b.rearComposite, xi, b.radius_cm, w);
            const double k = std::min(target, 0.999) / covered;
            double was = 0.0, before = 0.0;  // covered in front, as composited and as scaled
            for (NeedleHit& h : mNeedleHits) {
                const double share = h.alpha * (1.0 - was);
                was += share;
                h.alpha = before < 1.0 ? k * share / (1.0 - before) : 0.0;
                before += k * share;
            }
        }
        shadeNeedles(ray, index, b, tIn, tOut, 2);
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
            mNeedleHits.push_back({j, needle, p.t, c, kNoLayer, apex + (p.s * l) * needle});
        }
        return true;
    }, /*hiddenInBark=*/false);
    shadeNeedles(ray, index, b, tIn, tOut, 1);
}

// Where a bough's own branch covers the footprint of a cone passing the bough's strip at
// signed offset xi, w wide, where its bark is solid (render.bark "solid"): its coverage and
// depth as the branch's fragment has them (hitBranch, before tMax), and the part of the strip
// it spans there, [from, to]. Zero coverage where the footprint misses it.
struct BarkInFootprint {
    double coverage = 0.0, t = 0.0, from = 0.0, to = 0.0;
};
BarkInFootprint barkInFootprint(const ConeRay& ray, const TracedScene& scene, const TracedBough& b,
                                double xi, double w, double tMax)
{
    if (!(b.barkRadius_cm > 0.0) || b.branch == TracedBough::kNoBranch) return {};
    BranchHit hit;
    if (!hitBranch(ray, scene.branches[b.branch], tMax, hit)) return {};
    // The bark radius is the branch's, capped at the strip's half-width R.
    BarkInFootprint out{std::min(hit.coverage, 0.999), hit.t,
                        std::max(xi - 0.5 * w, -b.barkRadius_cm),
                        std::min(xi + 0.5 * w, b.barkRadius_cm)};
    return out.to > out.from ? out : BarkInFootprint{};
}

void MultiscaleRayTracer::addBough(const ConeRay& ray, std::size_t index)
{
    const TracedBough& b = mScene.bough(index);
    // Where the cone passes the needles: they reach from the base to the cones' end.
    Passage p;
    if (!closestPassage(ray, b.base_cm, b.conesEnd(), p)) return;
    const double w = ray.width(p.t);
    mCoarsestQ = std::max(mCoarsestQ, w / b.geometry.coneSpacing_cm);
    mShadedBough = true;
    if (mForceLevel) return addBoughAt(ray, index, Level(mForceLevel), p);
    const LevelBlend blend = blendLevels(w, b.geometry.coneSpacing_cm, mSettings);
    if (!(blend.upperWeight > 0.0)) return addBoughAt(ray, index, blend.lower, p);
    if (!(blend.upperWeight < 1.0)) return addBoughAt(ray, index, blend.upper, p);
    // Within a band about a threshold: each level's fragments composited alone, the two
    // results mixed, at the bough's front. The bough's own branch is composited with each, at
    // its depth among them, so that it hides what lies behind it as it does outside the band:
    // behind the mixed fragment it had hidden none of its bough, and a fir whose branches
    // are as thick as its boughs' reach covered 1.214 of the needles (0.974 with no band).
    // The mix is two fragments, the needles' and then what shows of the branch, so that the
    // foliage is the needles' alone.
    Fragment branch;
    const bool withBranch =
        b.branch != TracedBough::kNoBranch && !contains(mBranchesMet, b.branch) &&
        !contains(mBranchesOfBlends, b.branch) && mSurfaces.branch(ray, b.branch, mTMax, branch);
    if (withBranch) mBranchesOfBlends.push_back(b.branch);
    const std::size_t from = mFragments.size();
    addBoughAt(ray, index, blend.lower, p, withBranch);
    if (withBranch) mFragments.push_back(branch);
    const std::size_t middle = mFragments.size();
    addBoughAt(ray, index, blend.upper, p, withBranch);
    if (withBranch) mFragments.push_back(branch);
    // What the needles (foliage) and the rest show, composited front to back (FrontToBack).
    struct Shown {
        double alpha = 0.0;
        Vec3 diffuse{0.0}, specular{0.0};
    };
    struct Parts {
        Shown needles, rest;
    };
    const auto composite = [&](std::size_t a, std::size_t z) {
        // Stable: level 3's fragments can share a depth (its thirds held before or behind
        // the branch), and then keep the order they were made in, front to back.
        std::stable_sort(mFragments.begin() + a, mFragments.begin() + z,
                         [](const Fragment& x, const Fragment& y) { return x.t < y.t; });
        Parts parts;
        double alpha = 0.0;
        for (std::size_t i = a; i < z; ++i) {
            const Fragment& f = mFragments[i];
            const double through = 1.0 - alpha;
            Shown& part = f.foliage ? parts.needles : parts.rest;
            part.alpha += through * f.alpha;
            part.diffuse += through * f.diffuse;
            part.specular += through * f.specular;
            alpha += through * f.alpha;
        }
        return parts;
    };
    const Parts lo = composite(from, middle), hi = composite(middle, mFragments.size());
    const double u = blend.upperWeight;
    double t = std::numeric_limits<double>::infinity();
    for (std::size_t i = from; i < mFragments.size(); ++i) t = std::min(t, mFragments[i].t);
    mFragments.resize(from);
    const auto mix = [&](Shown Parts::*part) {
        const Shown &a = lo.*part, &z = hi.*part;
        return Shown{(1.0 - u) * a.alpha + u * z.alpha, (1.0 - u) * a.diffuse + u * z.diffuse,
                     (1.0 - u) * a.specular + u * z.specular};
    };
    const Shown needles = mix(&Parts::needles), rest = mix(&Parts::rest);
    const double covered = std::min(needles.alpha, 1.0);
    if (covered > 0.0) {
        mFragments.push_back(Fragment{t, covered, needles.diffuse, needles.specular,
                                      int(u < 0.5 ? blend.lower : blend.upper), true, b.tree});
    }
    if (withBranch && rest.alpha > 0.0 && covered < 1.0) {
        const double behind = 1.0 - covered;  // what the needles' fragment leaves
        mFragments.push_back(Fragment{t, std::min(rest.alpha / behind, 1.0), rest.diffuse / behind,
                                      rest.specular / behind, branch.level, false, branch.tree});
    }
}

void MultiscaleRayTracer::addBoughAt(const ConeRay& ray, std::size_t index, Level level,
                                     const Passage& passage, bool branchBetween)
{
    const TracedBough& b = mScene.bough(index);
    Passage p = passage;
    const double w = ray.width(p.t);
    const double c = stripCoverage(p.gap, b.radius_cm, w);
    if (c <= 0.0) return;
    // The chord's signed offset from the axis, across the strip (bough_law.h).
    const double xi =
        std::copysign(p.gap, glm::dot(ray.origin + p.t * ray.direction - b.base_cm, b.across));
    double tIn, tOut;
    if (level != Level::Bough) {
        // Cones and needles are found along the cone's axis; where the axis misses them the
        // footprint only grazes the bough: shade the volume.
        if (layeredInterval(b, ray.origin, ray.direction, tIn, tOut)) {
            addCrossings(ray, index, b, tIn, tOut, c, xi, w, level);
            return;
        }
    }
    // The volume spans base to the law's strip end: the tip (the cones' region sheared into a
    // cylinder of equal volume) or the cones' end (the exact law, whose chords cover them).
    if (!closestPassage(ray, b.base_cm, b.stripEnd(), p)) return;
    if (!intersectCylinder(ray, b.base_cm, b.stripEnd(), b.radius_cm, tIn, tOut)) {
        tIn = tOut = p.t;
    }

    // Level 3: section 6 per light under the bough law, front half at the entry and rear
    // half at the middle (or just behind the bough's own branch where that lies as deep), so
    // that the branch inside sorts between them; with shadow_origin "needles", each half as
    // three fragments along its chord (below). Each profile is read over the footprint at the
    // chord's signed offset from the axis.
    ++mStats.boughHits;
    const double R = b.radius_cm;
    const std::shared_ptr<const BoughView> kept = b.view();
    const BoughView& view = *kept;
    const double frontAlpha = view.alpha.front.overFootprint(xi, R, w);
    // What the rear's share is divided by to composite behind the front (bough_law.h).
    const double behindFront =
        b.rearComposite == RearComposite::Share ? 1.0 - frontAlpha : 1.0;
    // The bough's own branch lies between the halves and hides the rear's needles behind it,
    // where it lies across the strip: the rear's share there, not its mean over the footprint
    // (the rear's chords are longest over the axis, and more of it lies there). A footprint
    // composited as if even across it had hidden too little of the rear: level 3 covered 1.049
    // of the needles on thin twigs (FaithfulModels.ABranchHidesItsNeedlesRoots), now 1.018.
    const BarkInFootprint bark = b.rearComposite == RearComposite::Share
                                     ? barkInFootprint(ray, mScene, b, xi, w, mTMax)
                                     : BarkInFootprint{};
    const double behindBark = branchBetween ? 1.0 - bark.coverage : 1.0;
    const auto rearShare = [&](const StripProfile& profile) {
        double share = profile.overFootprint(xi, R, w);
        if (bark.coverage > 0.0) {
            share -= bark.coverage *
                     profile.overFootprint(0.5 * (bark.from + bark.to), R, bark.to - bark.from);
        }
        const double through = behindFront * behindBark;
        return through > 1e-9 ? std::max(0.0, share) / through : 0.0;
    };
    // The composite takes the front and the branch as even across the footprint, where the
    // front is densest over the branch: what it leaves behind them may hold less than the rear
    // beside the branch. The rear then covers all of it, each of its profiles scaled alike,
    // so that it reflects what it did per unit of coverage.
    const double rearAlpha = rearShare(view.alpha.rear);
    const double rearScale = rearAlpha > 1.0 ? 1.0 / rearAlpha : 1.0;
    const auto rearPart = [&](const StripProfile& profile) {
        return rearScale * rearShare(profile);
    };
    const ChordHalves chord = chordHalves(ray, b, p, tIn, tOut);
    const double tMid = chord.tMid;
    Fragment front{tIn, frontAlpha, Vec3(0.0), Vec3(0.0), 3, true, b.tree};
    // Behind the branch's fragment, which may lie as deep where the ray misses the branch.
    const double tRear =
        bark.coverage > 0.0 && branchBetween
            ? std::max(tMid, std::nextafter(bark.t, std::numeric_limits<double>::infinity()))
            : tMid;
    Fragment rear{tRear, rearScale * rearAlpha, Vec3(0.0), Vec3(0.0), 3, true, b.tree};
    // With shadow_origin "needles" each half is composited as three fragments, one at the
    // middle of each third of its needles' chord (`chord`), each lit through its own shadow
    // lines: shadowAcross places the needles that reflect each half's light evenly in its
    // thirds, and the fragments hold them so. A neighbour whose needles lie among this
    // bough's, as a twig or the next bough of a chain does, then hides and shades the thirds
    // behind its own fragments alone: with one fragment a half it hid the whole half or none
    // of it, and the half's light was its thirds' mean, while the thirds the neighbour hides
    // are the ones it shades when the light comes from the camera's side. Forced level 3 on
    // the paper forest, against level 1 at an eighth of its footprints, per tree: -4.0% as two
    // fragments lit by one mean, -3.1% as two each lit by its own thirds, -3.7% as six lit
    // by one mean, -2.5% as six each lit by its own (docs/models.md, "Whole scenes").
    // Without shadows the thirds are lit alike and still composited apart, so that what a
    // pixel shows of the foliage does not change with the shadows switch.
    const bool byThirds = mScene.shadowOrigin == ShadowOrigin::Needles;
    struct Thirds {
        Vec3 diffuse[3], specular[3];  ///< what each third reflects, as the half's share
    } thirds[2];                       ///< front, rear
    for (Thirds& half : thirds) {
        for (int j = 0; j < 3; ++j) half.diffuse[j] = half.specular[j] = Vec3(0.0);
    }
    // The light at the chord's middle, or with shadow_origin "axis" where the ray passes the
    // axis.
    const double tLight = mScene.shadowOrigin == ShadowOrigin::Axis ? p.t : tMid;
    mLight.resize(mScene.lights.size());
    for (std::size_t i = 0; i < mLight.size(); ++i) {
        const BoughLighting& lit = view.lighting[i];
        mLight[i] = mSurfaces.unshadowed(i, ray.origin + tLight * ray.direction);
        const Vec3 unshadowed = mLight[i].irradiance;
        double thirdShadow[2][3] = {{1.0, 1.0, 1.0}, {1.0, 1.0, 1.0}};  // shadowAcross's
        // Without self-shadowing the whole opacity reflects; with it, the law's transfer.
        const FrontRearProfile& transfer = mPlan.selfShadowing ? lit.transfer : view.alpha;
        const double tf = transfer.front.overFootprint(xi, R, w);
        const double tr = rearPart(transfer.rear);
        mStats.selfShadowEvaluations += mPlan.selfShadowing ? 2 : 0;
        if (mBoughShadows) {
            mLight[i].irradiance *=
                mBoughShadows->transmittance(index, i, ray.origin + tMid * ray.direction, mStats);
        } else if (mPlan.shadowRays && mScene.shadowOrigin == ShadowOrigin::Axis) {
            mLight[i].irradiance *= mSurfaces.shadow(i, ray.origin + p.t * ray.direction, w, index);
        } else if (mPlan.shadowRays) {
            // Each half's needles that reflect the light lie along its half of the chord, and
            // across the strip as the law's transfer says.
            mLight[i].irradiance *=
                shadowAcross(ray, index, i, transfer,
                             b.rearComposite == RearComposite::Share ? nullptr : &view.alpha.front,
                             xi, w, chord, thirdShadow);
        }
        const Vec3& E = mLight[i].irradiance;
        // What each half reflects: the law's sum over its needles, or (the paper's laws) the
        // transfer times the face's mean reflectance I^cyl (section 6.6).
        const auto reflected = [&](const FrontRearProfile& perNeedle, double frontFace,
                                   double rearFace, double& f, double& r) {
            f = b.shadesNeedles ? perNeedle.front.overFootprint(xi, R, w) : tf * frontFace;
            r = b.shadesNeedles ? rearPart(perNeedle.rear) : tr * rearFace;
        };
        // What each half reflects, `f` and `r` per unit irradiance, added to its fragment's
        // `part` or, by thirds, to each third's, lit through its own shadow lines.
        const auto add = [&](Vec3 Fragment::*part, Vec3(Thirds::*third)[3], const Vec3& f,
                             const Vec3& r) {
            if (!byThirds) {
                front.*part += f * E;
                rear.*part += r * E;
                return;
            }
            for (int j = 0; j < 3; ++j) {
                (thirds[0].*third)[j] += f / 3.0 * thirdShadow[0][j] * unshadowed;
                (thirds[1].*third)[j] += r / 3.0 * thirdShadow[1][j] * unshadowed;
            }
        };
        double f, r;
        if (mPlan.diffuse) {
            reflected(lit.diffuse, lit.front.diffuse, lit.rear.diffuse, f, r);
            add(&Fragment::diffuse, &Thirds::diffuse, f * b.needleAlbedo / kPi,
                r * b.needleAlbedo / kPi);
            mStats.diffuseEvaluations += 2;
        }
        if (mPlan.specular) {
            reflected(lit.specular, lit.front.specular, lit.rear.specular, f, r);
            add(&Fragment::specular, &Thirds::specular, Vec3(f * b.specularWeight),
                Vec3(r * b.specularWeight));
            mStats.specularEvaluations += 2;
        }
    }
    if (!byThirds) {
        mFragments.push_back(front);
        mFragments.push_back(rear);
        return;
    }
    // Each third shows a third of its half's opacity and light: composited alone, the three
    // give the half's alpha and, lit alike, its light.
    const auto addThirds = [&](const Fragment& half, const Thirds& light,
                               const std::array<double, 3>& depths) {
        const double A = half.alpha;
        for (int j = 0; j < 3; ++j) {
            const double through = 1.0 - j * A / 3.0;  // what the thirds in front leave
            Fragment third = half;
            third.t = depths[j];
            third.alpha = std::min(1.0, A / 3.0 / through);
            third.diffuse = light.diffuse[j] / through;
            third.specular = light.specular[j] / through;
            mFragments.push_back(third);
        }
    };
    // The front's thirds in front of the bough's own branch where it lies in the footprint,
    // as the front was; the rear's behind it.
    const double branchEntry =
        bark.coverage > 0.0 ? std::nextafter(bark.t, -std::numeric_limits<double>::infinity())
                            : std::numeric_limits<double>::infinity();
    std::array<double, 3> frontDepths, rearDepths;
    for (int j = 0; j < 3; ++j) {
        frontDepths[j] = std::max(tIn, std::min(chord.third(0, j), branchEntry));
        rearDepths[j] = std::max(chord.third(1, j), tRear);
    }
    addThirds(front, thirds[0], frontDepths);
    addThirds(rear, thirds[1], rearDepths);
}

// primitiveEntry of the primitive of cylinder `c` and ball `ball` (cylinderSphere of it).
// Tighter than the ball's bound for a primitive seen side-on: a bough's needles lie within
// its cones' reach R of the axis, base to the cones' end (and level 3's strip within that),
// grown by a needle's radius; a branch's cylinder is itself; each fragment lies within half
// the footprint of them (its width at the ball's far side, beyond any fragment).
double entryInto(const ConeRay& ray, const PrimitiveCylinder& c, const Sphere& ball)
{
    const Vec3 toCentre = ball.centre - ray.origin;
    const double along = glm::dot(toCentre, ray.direction);
    const double far = (along + ball.radius) / std::max(1e-9, 1.0 - 0.5 * ray.spread);
    const double grown = c.radius_cm + 0.5 * ray.width(far);
    // The grown cylinder lies within the ball grown as much: a line that misses that ball
    // (by more than rounding) misses it, and most of what the BVH yields is missed so. The
    // tracer skips a primitive missed here (trace): a camera cone's positive spread grows
    // the cylinder past its fragments' reach by far more than rounding.
    const Vec3 off = toCentre - along * ray.direction;
    const double reach = (ball.radius + 0.5 * ray.width(far)) * (1.0 + 1e-9) + 1e-9;
    if (glm::dot(off, off) > reach * reach) return -std::numeric_limits<double>::infinity();
    double tIn, tOut;
    if (!intersectCylinder(ray, c.base, c.end, grown, tIn, tOut)) {
        return -std::numeric_limits<double>::infinity();
    }
    return tIn - 1e-9 * (1.0 + std::abs(tIn));  // below rounding
}

// No fragment of a primitive lies nearer along the ray than its ball's bound: a bough's
// fragments lie within its cones' reach R plus the needles' radius of its axis (base to the
// cones' end), a branch's within its radius, and each of them within half the footprint of
// that (nearestAlong).
double nearestFragment(const ConeRay& ray, const TracedScene& scene, std::uint32_t index)
{
    return nearestAlong(ray, primitiveBall(scene, index));
}

void MultiscaleRayTracer::trace(const ConeRay& ray, FrontToBack& composite)
{
    // Front to back: each primitive's fragments are made (and lit, shadow cones and all) only
    // if the composite is not yet opaque at the nearest depth they can lie at, so that what
    // lies behind opaque layers costs nothing; the BVH yields the primitives in that order,
    // so that it is not walked behind them either. The composite receives the same fragments
    // in the same order as if all were made and sorted.
    double tGround;
    Vec3 normal;
    const bool hasGround = hitGround(mScene.scene->ground, ray, tGround, normal);
    const double tMax = hasGround ? tGround : std::numeric_limits<double>::infinity();
    mTMax = tMax;
    mCoarsestQ = 0.0;
    mShadedBough = false;
    mOpaqueFrom = tMax;
    mBranchesMet.clear();
    mBranchesOfBlends.clear();
    mQueue.clear();
    if (hasGround) mQueue.add(tGround, kGround);
    mFragments.clear();
    mMadeBy.clear();
    mOrder.clear();
    // Fragments at one depth (a grazing bough's halves and the branch inside it meet the ray
    // at one closest passage) composite in the order of their primitives' bounds, then as
    // made: the order of the primitives sorted by their bounds, whenever each was shaded.
    const auto before = [&](std::size_t i, std::size_t j) {
        if (mFragments[i].t != mFragments[j].t) return mFragments[i].t < mFragments[j].t;
        if (mMadeBy[i] != mMadeBy[j]) return mMadeBy[i] < mMadeBy[j];
        return i < j;
    };
    std::size_t done = 0;  // of mOrder: composited
    // Composites the fragments made so far that lie before `depth`: none made later can.
    const auto compositeBefore = [&](double depth) {
        if (mOrder.size() != mFragments.size()) {
            for (std::size_t i = mOrder.size(); i < mFragments.size(); ++i) mOrder.push_back(i);
            std::sort(mOrder.begin() + long(done), mOrder.end(), before);
        }
        while (done < mOrder.size() && mFragments[mOrder[done]].t <= depth &&
               !composite.opaque()) {
            composite.add(mFragments[mOrder[done++]]);
        }
    };
    // Those made since, by primitive `index` of bound `nearest`.
    const auto madeBy = [&](double nearest, std::uint32_t index) {
        mMadeBy.resize(mFragments.size(), {nearest, index});
    };
    // A primitive is visited where its fragments can begin (primitiveEntry, where tighter
    // than its ball's bound) and shaded (a bough's law's profiles, every shadow cone) only if
    // the pixel is not opaque there: the fragments of those nearer it may hide it whole. One
    // the cone misses (most of those the BVH's boxes yield) is not visited at all.
    mScene.bvh.nearestFirst(
        ray, tMax, mQueue,
        [&](std::uint32_t index) {
            // The cylinder and its ball once for both bounds (nearestFragment's is the ball's).
            const PrimitiveCylinder c = primitiveCylinder(mScene, index);
            const Sphere ball = cylinderSphere(c.base, c.end, c.radius_cm);
            const double entry = entryInto(ray, c, ball);
            if (entry == -std::numeric_limits<double>::infinity()) {
                return std::numeric_limits<double>::infinity();
            }
            return std::max(nearestAlong(ray, ball), entry);
        },
        [&](std::uint32_t index, double from) {
            compositeBefore(from);
            if (composite.opaque()) {
                mOpaqueFrom = from;
                return false;
            }
            if (index == kGround) {
                mFragments.push_back(mSurfaces.groundAt(ray, tGround, normal));
                madeBy(from, index);
                return true;
            }
            if (!mScene.isBranch(index)) {
                addBough(ray, index);
            } else if (!contains(mBranchesOfBlends, index)) {
                mBranchesMet.push_back(index);
                Fragment f;
                if (mSurfaces.branch(ray, index, tMax, f)) mFragments.push_back(f);
            }
            madeBy(nearestFragment(ray, mScene, index), index);
            return true;
        });
    compositeBefore(std::numeric_limits<double>::infinity());
}

double MultiscaleRayTracer::coarsestQ(const ConeRay& pixel, const ConeRay& square) const
{
    const Vec3 &o = pixel.origin, &d = pixel.direction;
    double q = 0.0;
    mScene.bvh.query(square, mOpaqueFrom, [&](std::uint32_t index) {
        if (mScene.isBranch(index)) return;
        // The capsule about the segment holding its needles, not the capped cylinder that
        // entryInto grows: a narrower cone in the corner may pass beyond the segment's end
        // and still meet it, where the pixel's axis passes it beyond that end.
        const PrimitiveCylinder c = primitiveCylinder(mScene, index);
        const Vec3 axis = c.end - c.base;
        const double length = glm::length(axis);
        const Vec3 u = length > 0.0 ? axis / length : Vec3(0.0);
        const double du = glm::dot(d, u), denom = 1.0 - du * du;
        const double dw = glm::dot(d, o - c.base), uw = glm::dot(u, o - c.base);
        const double s = denom > 1e-12 ? std::clamp((uw - du * dw) / denom, 0.0, length) : 0.0;
        const Vec3 nearest = c.base + s * u;  // the segment's point nearest the pixel's axis
        const double t = glm::dot(nearest - o, d);
        const double tBase = glm::dot(c.base - o, d), tEnd = glm::dot(c.end - o, d);
        if (!(std::min(tBase, tEnd) - c.radius_cm < mOpaqueFrom)) return;
        const double tFar = std::max(tBase, tEnd) + c.radius_cm;
        const double reach = c.radius_cm + 0.5 * square.width(std::max(tFar, 0.0));
        if (glm::length(nearest - (o + t * d)) > reach) return;
        q = std::max(q,
                     pixel.width(std::max(t, 0.0)) / mScene.bough(index).geometry.coneSpacing_cm);
    });
    return q;
}

class Multiscale final : public ShadingMethod {
public:
    Multiscale(const TracedScene& scene, const MultiscaleOptions& options)
        : mScene(scene), mPlan(EffectsPlan::from(scene.scene->effects)), mOptions(options)
    {
        if (mPlan.shadowRays && scene.shadowOrigin == ShadowOrigin::Bough) {
            mBoughShadows = std::make_unique<BoughShadows>(scene, mPlan.selfShadowing);
        }
    }
    int samplesPerPixel() const override { return 1; }
    /// Forced levels are compared at the pixel's own footprint, as asked.
    bool splitsPixels() const override
    {
        return mScene.scene->render.model.pixelSplitQ > 0.0 && mOptions.forceLevel == 0;
    }
    ConeRay sample(const ConeCamera& camera, int x, int y, int) const override
    {
        return camera.cone(x, y);
    }
    std::unique_ptr<RayTracer> rayTracer(RenderStats& stats) const override
    {
        return std::make_unique<MultiscaleRayTracer>(mScene, mPlan, mOptions.forceLevel,
                                                     mBoughShadows.get(), stats);
    }

private:
    const TracedScene& mScene;
    EffectsPlan mPlan;
    MultiscaleOptions mOptions;
    std::unique_ptr<BoughShadows> mBoughShadows;  ///< this frame's, when the scene asks
};

}  // namespace

double primitiveEntry(const ConeRay& ray, const TracedScene& scene, std::uint32_t index)
{
    const PrimitiveCylinder c = primitiveCylinder(scene, index);
    return entryInto(ray, c, cylinderSphere(c.base, c.end, c.radius_cm));
}

LevelBlend blendLevels(double footprint_cm, double coneSpacing_cm,
                       const scenes::RenderSettings& s)
{
    const double q = footprint_cm / coneSpacing_cm;
    const Level level = chooseLevel(footprint_cm, coneSpacing_cm, s);
    LevelBlend out{level, level, 0.0};
    // Never wider than keeps the two bands apart: the scene parser and the tool refuse or
    // narrow a wider one, but compare's error budget moves cone_level_max to the paper's with
    // the scene's band kept, and a scene may be built in code.
    const double coneLevelMax = s.model.coneLevelMax;
    const double band = std::min(s.model.levelBlend, s.widestLevelBlend());
    if (!(band > 1.0)) return out;
    for (const auto& [threshold, lower] :
         {std::pair{s.needleLevelMax, Level::Needle}, std::pair{coneLevelMax, Level::Cone}}) {
        const double u = std::log(q / threshold) / std::log(band);  // -1 to 1 across the band
        if (std::abs(u) >= 1.0) continue;
        const double x = 0.5 * (u + 1.0);
        out = {lower, Level(int(lower) + 1), x * x * (3.0 - 2.0 * x)};
    }
    return out;
}

Level chooseLevel(double footprint_cm, double coneSpacing_cm, const scenes::RenderSettings& s)
{
    const double q = footprint_cm / coneSpacing_cm;
    if (q < s.needleLevelMax) return Level::Needle;
    if (q < s.model.coneLevelMax) return Level::Cone;
    return Level::Bough;
}

RenderResult renderMultiscale(const TracedScene& scene, const MultiscaleOptions& method,
                              const RenderOptions& options)
{
    return renderImage(scene, Multiscale(scene, method), options);
}

}  // namespace pine::vdbtrace
