#include "pine/vdbtrace/multiscale_tracer.h"

#include "pine/analytic/needle_shader.h"
#include "pine/vdbtrace/cone_camera.h"
#include "pine/vdbtrace/ground_hit.h"
#include "pine/vdbtrace/needle_layout.h"
#include "pine/vdbtrace/tiled_render.h"

#include <glm/geometric.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <vector>

namespace pine::vdbtrace {
namespace {

constexpr double kPi = analytic::kPi;
constexpr double kOpaque = 0.999;  // accumulated alpha beyond which the rest cannot show

// A partial coverage along the cone: premultiplied radiance, split by effect for the AOVs.
struct Layer {
    double t = 0.0;
    double alpha = 0.0;
    Vec3 diffuse{0.0}, specular{0.0};  // premultiplied by alpha
    int level = 0;                     // 1-3 for foliage, 0 for branches and ground
};

double luminance(const Vec3& c) { return 0.2126 * c.x + 0.7152 * c.y + 0.0722 * c.z; }

class PixelTracer {
public:
    PixelTracer(const TracedScene& scene, const EffectsPlan& plan, int forceLevel,
                RenderStats& stats)
        : mScene(scene),
          mPlan(plan),
          mSettings(scene.scene->render),
          mForceLevel(forceLevel),
          mStats(stats)
    {
    }

    /// Traces one pixel's cone into `rgba` and the AOV values.
    void trace(const ConeRay& ray, float* rgba, float& level, float& depth, float& diffuse,
               float& specular, float& foliage);
    /// The level that covered most of the last pixel (0: no foliage).
    int dominantLevel() const { return mDominant; }

private:
    // Transmittance from `x` to light `light` through everything but primitive `self`, by a
    // cone whose apex is at the light and whose width at x is the pixel's footprint there.
    double shadow(const Vec3& x, std::size_t light, double footprint, std::size_t self);
    // Light reaching x from each light (irradiance x shadow), with its direction.
    void lightAt(const Vec3& x, double footprint, std::size_t self, std::vector<Vec3>& irradiance,
                 std::vector<Vec3>& towards);
    void addBranch(const ConeRay& ray, std::size_t index);
    void addBough(const ConeRay& ray, std::size_t index);
    void addCrossings(const ConeRay& ray, std::size_t index, const TracedBough& b, double tIn,
                      double tOut, double coverage, Level level);
    // Layers of a bough's own cones crossed from x towards the light (section 6's self-shadowing
    // at levels 1-2, counted, not approximated): (1 - A)^count.
    double selfShadow(const TracedBough& b, const Vec3& x, const Vec3& towardsLight);
    void shadeNeedle(const TracedBough& b, const Vec3& needle, const Vec3& x, const Vec3& V,
                     double alpha, double t, int level, const std::vector<Vec3>& irradiance,
                     const std::vector<Vec3>& towards);

    const TracedScene& mScene;
    const EffectsPlan& mPlan;
    const scenes::RenderSettings& mSettings;
    int mForceLevel;
    RenderStats& mStats;
    std::vector<Layer> mLayers;
    int mDominant = 0;
};

double PixelTracer::shadow(const Vec3& x, std::size_t light, double footprint, std::size_t self)
{
    ++mStats.shadowRays;
    double tMax;
    const ConeRay ray = mScene.lights[light].shadowCone(x, footprint, tMax);
    double transmittance = 1.0;
    mScene.bvh.query(ray, tMax, [&](std::uint32_t index) {
        if (index == self || transmittance < 1e-4) return;
        if (mScene.isBranch(index)) {
            const TracedBranch& br = mScene.branches[index];
            Passage p;
            if (closestPassage(ray, br.base_cm, br.tip_cm, p) && p.t < tMax) {
                transmittance *= 1.0 - stripCoverage(p.gap, br.radius_cm, ray.width(p.t));
            }
        } else {
            const TracedBough& b = mScene.bough(index);
            Passage p;
            if (closestPassage(ray, b.base_cm, b.tip_cm, p) && p.t < tMax) {
                const double c = stripCoverage(p.gap, b.radius_cm, ray.width(p.t));
                transmittance *= 1.0 - c * b.lighting[light].opacityFromLight;
            }
        }
    });
    return transmittance;
}

void PixelTracer::lightAt(const Vec3& x, double footprint, std::size_t self,
                          std::vector<Vec3>& irradiance, std::vector<Vec3>& towards)
{
    irradiance.resize(mScene.lights.size());
    towards.resize(mScene.lights.size());
    for (std::size_t i = 0; i < mScene.lights.size(); ++i) {
        double distance;
        mScene.lights[i].at(x, towards[i], distance, irradiance[i]);
        if (mPlan.shadowRays) irradiance[i] *= shadow(x, i, footprint, self);
    }
}

void PixelTracer::addBranch(const ConeRay& ray, std::size_t index)
{
    const TracedBranch& br = mScene.branches[index];
    Passage p;
    if (!closestPassage(ray, br.base_cm, br.tip_cm, p)) return;
    const double w = ray.width(p.t);
    const double c = stripCoverage(p.gap, br.radius_cm, w);
    if (c <= 0.0) return;
    double tIn = p.t, tOut;
    intersectCylinder(ray, br.base_cm, br.tip_cm, br.radius_cm, tIn, tOut);
    ++mStats.branchHits;
    Layer layer{tIn, c, Vec3(0.0), Vec3(0.0), 0};
    if (mPlan.diffuse) {
        const Vec3 x = ray.origin + p.t * ray.direction;
        const Vec3 axis = glm::normalize(br.tip_cm - br.base_cm);
        std::vector<Vec3> irradiance, towards;
        lightAt(x, w, index, irradiance, towards);
        for (std::size_t i = 0; i < irradiance.size(); ++i) {
            // Eq. (1) is the Lambertian cylinder's reflectance: bark is such a cylinder.
            const double R = analytic::needleDiffuse(axis, towards[i], -ray.direction);
            layer.diffuse += c * br.albedo / kPi * irradiance[i] * R;
            ++mStats.diffuseEvaluations;
        }
    }
    mLayers.push_back(layer);
}

double PixelTracer::selfShadow(const TracedBough& b, const Vec3& x, const Vec3& towardsLight)
{
    ++mStats.selfShadowEvaluations;
    ConeRay ray{x, towardsLight, 0.0};
    double tIn, tOut;
    if (!intersectCylinder(ray, b.base_cm, b.conesEnd_cm, b.radius_cm, tIn, tOut)) return 1.0;
    const double dh = b.geometry.coneSpacing_cm,
                 cotPhi = 1.0 / std::tan(b.geometry.cone.aperture_rad);
    const auto g = [&](double t) {
        const Vec3 r = ray.origin + t * ray.direction - b.base_cm;
        const double h = glm::dot(r, b.axis);
        return h - glm::length(r - h * b.axis) * cotPhi;
    };
    const double dt = dh / (4.0 * (1.0 + cotPhi));
    int count = 0;
    double t0 = std::max(tIn, 1e-6), g0 = g(t0);
    const long jMax = long(std::floor(b.length_cm / dh));
    for (double t1 = t0 + dt; t0 < tOut; t0 = t1, t1 += dt) {
        t1 = std::min(t1, tOut);
        const double g1 = g(t1);
        const long j0 = long(std::floor(g0 / dh)), j1 = long(std::floor(g1 / dh));
        for (long j = std::min(j0, j1) + 1; j <= std::max(j0, j1); ++j)
            count += (j >= 0 && j <= jMax);
        g0 = g1;
        if (t1 >= tOut) break;
    }
    return std::pow(1.0 - b.layerOpacity, count);
}

void PixelTracer::shadeNeedle(const TracedBough& b, const Vec3& needle, const Vec3& x,
                              const Vec3& V, double alpha, double t, int level,
                              const std::vector<Vec3>& irradiance, const std::vector<Vec3>& towards)
{
    Layer layer{t, alpha, Vec3(0.0), Vec3(0.0), level};
    for (std::size_t i = 0; i < irradiance.size(); ++i) {
        const double self = mPlan.selfShadowing ? selfShadow(b, x, towards[i]) : 1.0;
        const Vec3 E = irradiance[i] * self;
        if (mPlan.diffuse) {
            layer.diffuse +=
                alpha * b.needleAlbedo / kPi * E * analytic::needleDiffuse(needle, towards[i], V);
            ++mStats.diffuseEvaluations;
        }
        if (mPlan.specular) {
            layer.specular += alpha * b.specularWeight * E *
                              analytic::needleSpecular(needle, towards[i], V, b.exponent);
            ++mStats.specularEvaluations;
        }
    }
    mLayers.push_back(layer);
}

void PixelTracer::addCrossings(const ConeRay& ray, std::size_t index, const TracedBough& b,
                               double tIn, double tOut, double coverage, Level level)
{
    // The ray crosses cone j where g = h - rho cot(phi) = j dh (h along the branch, rho from
    // it): march g in steps that move it by at most dh/4.
    const double phi = b.geometry.cone.aperture_rad, dh = b.geometry.coneSpacing_cm;
    const double cotPhi = 1.0 / std::tan(phi), sinPhi = std::sin(phi), cosPhi = std::cos(phi);
    const auto g = [&](double t, double* rho = nullptr, Vec3* radial = nullptr) {
        const Vec3 r = ray.origin + t * ray.direction - b.base_cm;
        const double h = glm::dot(r, b.axis);
        const Vec3 across = r - h * b.axis;
        const double d = glm::length(across);
        if (rho) *rho = d;
        if (radial) *radial = d > 0.0 ? across / d : Vec3(0.0);
        return h - d * cotPhi;
    };
    const Vec3 V = -ray.direction;
    const Vec3 mid = ray.origin + 0.5 * (tIn + tOut) * ray.direction;
    std::vector<Vec3> irradiance, towards;
    lightAt(mid, ray.width(0.5 * (tIn + tOut)), index, irradiance, towards);
    // The same needles as the explicit-needle ground truth (needle_layout.h).
    const NeedleLayout layout(b);
    const Vec3 e1 = layout.e1(), e2 = layout.e2();
    const long jMax = layout.lastCone();
    const int needles = layout.needlesPerCone();
    const double r = layout.radius(), l = layout.length();

    const double dt = dh / (4.0 * (1.0 + cotPhi));
    double t0 = tIn, g0 = g(t0);
    int steps = 0;
    while (t0 < tOut && steps++ < 100000) {
        const double t1 = std::min(t0 + dt, tOut), g1 = g(t1);
        const long j0 = long(std::floor(g0 / dh)), j1 = long(std::floor(g1 / dh));
        for (long j = std::min(j0, j1) + 1; j <= std::max(j0, j1); ++j) {
            if (j < 0 || j > jMax) continue;
            const double tc = t0 + (double(j) * dh - g0) / (g1 - g0) * (t1 - t0);
            double rho;
            Vec3 radial;
            g(tc, &rho, &radial);
            if (!(rho > 1e-9)) continue;
            if (level == Level::Cone) {
                ++mStats.coneHits;
                const Vec3 needle = cosPhi * b.axis + sinPhi * radial;
                shadeNeedle(b, needle, ray.origin + tc * ray.direction, V,
                            coverage * b.layerOpacity, tc, 2, irradiance, towards);
                continue;
            }
            // Level 1: the cone's needles nearest the crossing's azimuth, as cylinders.
            const double theta = std::atan2(glm::dot(radial, e2), glm::dot(radial, e1));
            const double roll = layout.roll(j);
            const long nearest = std::lround((theta - roll) * needles / (2 * kPi));
            const Vec3 apex = layout.apex(j);
            // The nearest needle and its two neighbours, each once: with fewer than three
            // needles per cone the neighbours wrap onto the same needles.
            const long from = needles >= 3 ? nearest - 1 : 0;
            const long to = needles >= 3 ? nearest + 1 : needles - 1;
            for (long i = from; i <= to; ++i) {
                const Vec3 needle = layout.direction(layout.azimuth(j, i));
                Passage p;
                if (!closestPassage(ray, apex, apex + l * needle, p)) continue;
                const double c = stripCoverage(p.gap, r, ray.width(p.t));
                if (c <= 0.0) continue;
                ++mStats.needleHits;
                shadeNeedle(b, needle, ray.origin + p.t * ray.direction, V, c, p.t, 1, irradiance,
                            towards);
            }
        }
        t0 = t1;
        g0 = g1;
    }
}

void PixelTracer::addBough(const ConeRay& ray, std::size_t index)
{
    const TracedBough& b = mScene.bough(index);
    // Where the cone passes the needles: they reach from the base to the cones' end.
    Passage p;
    if (!closestPassage(ray, b.base_cm, b.conesEnd_cm, p)) return;
    const double w = ray.width(p.t);
    const double c = stripCoverage(p.gap, b.radius_cm, w);
    if (c <= 0.0) return;
    Level level = mForceLevel ? Level(mForceLevel)
                              : chooseLevel(w, b.geometry.coneSpacing_cm, mSettings);
    double tIn, tOut;
    if (level != Level::Bough) {
        // Cones and needles are found along the cone's axis; where the axis misses them the
        // footprint only grazes the bough: shade the volume.
        if (intersectCylinder(ray, b.base_cm, b.conesEnd_cm, b.radius_cm, tIn, tOut)) {
            addCrossings(ray, index, b, tIn, tOut, c, level);
            return;
        }
    }
    // The volume spans base to tip (the cones' region sheared into a cylinder of equal volume).
    if (!closestPassage(ray, b.base_cm, b.tip_cm, p)) return;
    if (!intersectCylinder(ray, b.base_cm, b.tip_cm, b.radius_cm, tIn, tOut)) tIn = tOut = p.t;

    // Level 3: section 6.6 per light, front half at the entry and rear half at the middle,
    // so that the branch inside sorts between them.
    ++mStats.boughHits;
    const Vec3 x = ray.origin + p.t * ray.direction;
    std::vector<Vec3> irradiance, towards;
    lightAt(x, w, index, irradiance, towards);
    Layer front{tIn, c * b.alpha.front, Vec3(0.0), Vec3(0.0), 3};
    Layer rear{0.5 * (tIn + tOut), c * b.alpha.rear, Vec3(0.0), Vec3(0.0), 3};
    for (std::size_t i = 0; i < irradiance.size(); ++i) {
        const BoughLighting& lit = b.lighting[i];
        // Without self-shadowing the whole opacity reflects; with it, section 6.6's brackets.
        const double tf = mPlan.selfShadowing ? lit.law.transfer.front : b.alpha.front;
        const double tr = mPlan.selfShadowing ? lit.law.transfer.rear : b.alpha.rear;
        mStats.selfShadowEvaluations += mPlan.selfShadowing ? 2 : 0;
        if (mPlan.diffuse) {
            front.diffuse += c * tf * lit.front.diffuse * b.needleAlbedo / kPi * irradiance[i];
            rear.diffuse += c * tr * lit.rear.diffuse * b.needleAlbedo / kPi * irradiance[i];
            mStats.diffuseEvaluations += 2;
        }
        if (mPlan.specular) {
            front.specular += c * tf * lit.front.specular * b.specularWeight * irradiance[i];
            rear.specular += c * tr * lit.rear.specular * b.specularWeight * irradiance[i];
            mStats.specularEvaluations += 2;
        }
    }
    mLayers.push_back(front);
    mLayers.push_back(rear);
}

void PixelTracer::trace(const ConeRay& ray, float* rgba, float& level, float& depth,
                        float& diffuseOut, float& specularOut, float& foliageOut)
{
    ++mStats.coneRays;
    mLayers.clear();
    double tMax = std::numeric_limits<double>::infinity();
    double tGround;
    Vec3 normal;
    const bool ground = hitGround(mScene.scene->ground, ray, tGround, normal);
    if (ground) tMax = tGround;

    mScene.bvh.query(ray, tMax, [&](std::uint32_t index) {
        if (mScene.isBranch(index)) {
            addBranch(ray, index);
        } else {
            addBough(ray, index);
        }
    });
    if (ground) {
        ++mStats.groundHits;
        Layer layer{tGround, 1.0, Vec3(0.0), Vec3(0.0), 0};
        if (mPlan.diffuse) {
            const Vec3 x = ray.origin + tGround * ray.direction;
            std::vector<Vec3> irradiance, towards;
            lightAt(x, ray.width(tGround), std::size_t(-1), irradiance, towards);
            for (std::size_t i = 0; i < irradiance.size(); ++i) {
                layer.diffuse += mScene.scene->ground.albedo / kPi * irradiance[i] *
                                 std::max(0.0, glm::dot(normal, towards[i]));
                ++mStats.diffuseEvaluations;
            }
        }
        mLayers.push_back(layer);
    }

    std::sort(mLayers.begin(), mLayers.end(),
              [](const Layer& a, const Layer& b) { return a.t < b.t; });
    double A = 0.0, levelSum = 0.0, foliage = 0.0, levelWeight[4] = {0, 0, 0, 0};
    Vec3 diffuse(0.0), specular(0.0);
    depth = 0.0f;
    for (const Layer& layer : mLayers) {
        if (A > kOpaque) break;
        const double weight = (1.0 - A) * layer.alpha;
        diffuse += (1.0 - A) * layer.diffuse;
        specular += (1.0 - A) * layer.specular;
        if (layer.level > 0) {
            levelSum += weight * layer.level;
            foliage += weight;
            levelWeight[layer.level] += weight;
        }
        if (A < 0.5 && A + weight >= 0.5) depth = float(layer.t);
        A += weight;
    }
    const Vec3 colour = diffuse + specular;
    rgba[0] = float(colour.x);
    rgba[1] = float(colour.y);
    rgba[2] = float(colour.z);
    rgba[3] = float(std::min(1.0, A));
    level = foliage > 0.0 ? float(levelSum / foliage) : 0.0f;
    foliageOut = float(foliage);
    diffuseOut = float(luminance(diffuse));
    specularOut = float(luminance(specular));
    int dominant = 0;
    for (int k = 1; k <= 3; ++k) {
        if (levelWeight[k] > 1e-6 && levelWeight[k] > levelWeight[dominant]) dominant = k;
    }
    mDominant = dominant;
}

}  // namespace

Level chooseLevel(double footprint_cm, double coneSpacing_cm, const scenes::RenderSettings& s)
{
    const double q = footprint_cm / coneSpacing_cm;
    if (q < s.needleLevelMax) return Level::Needle;
    if (q < s.coneLevelMax) return Level::Cone;
    return Level::Bough;
}

RenderStats& RenderStats::operator+=(const RenderStats& o)
{
    coneRays += o.coneRays;
    shadowRays += o.shadowRays;
    selfShadowEvaluations += o.selfShadowEvaluations;
    needleHits += o.needleHits;
    coneHits += o.coneHits;
    boughHits += o.boughHits;
    branchHits += o.branchHits;
    groundHits += o.groundHits;
    voxelSpans += o.voxelSpans;
    diffuseEvaluations += o.diffuseEvaluations;
    specularEvaluations += o.specularEvaluations;
    for (int k = 0; k < 4; ++k) {
        pixelsPerLevel[k] += o.pixelsPerLevel[k];
        nanosecondsPerLevel[k] += o.nanosecondsPerLevel[k];
    }
    return *this;
}

RenderResult renderMultiscale(const TracedScene& scene, const RenderOptions& options)
{
    using Clock = std::chrono::steady_clock;
    const auto start = Clock::now();
    const ConeCamera camera(scene.scene->camera);
    const EffectsPlan plan = EffectsPlan::from(scene.scene->effects);
    RenderResult result;
    result.image = Image(camera.width(), camera.height());
    Image& image = result.image;
    for (const char* name : {"level", "depth", "diffuse", "specular", "foliage"}) image.aov(name);

    forEachTile(camera.width(), camera.height(), options.tileSize, options.progress, result.stats,
                [&](int x0, int y0, int x1, int y1, RenderStats& stats) {
        PixelTracer tracer(scene, plan, options.forceLevel, stats);
        for (int y = y0; y < y1; ++y) {
            for (int x = x0; x < x1; ++x) {
                const auto t0 = Clock::now();
                const std::size_t i = std::size_t(y) * camera.width() + x;
                tracer.trace(camera.cone(x, y), image.pixel(x, y), image.aovs["level"][i],
                             image.aovs["depth"][i], image.aovs["diffuse"][i],
                             image.aovs["specular"][i], image.aovs["foliage"][i]);
                const int dominant = tracer.dominantLevel();
                ++stats.pixelsPerLevel[dominant];
                stats.nanosecondsPerLevel[dominant] += std::uint64_t(
                    std::chrono::duration_cast<std::chrono::nanoseconds>(Clock::now() - t0)
                        .count());
            }
        }
    });
    result.seconds = std::chrono::duration<double>(Clock::now() - start).count();
    return result;
}

}  // namespace pine::vdbtrace
