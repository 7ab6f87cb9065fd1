#include "pine/vdbtrace/reference_tracer.h"

#include "pine/analytic/needle_shader.h"
#include "pine/vdbtrace/cone_camera.h"
#include "pine/vdbtrace/ground_hit.h"
#include "pine/vdbtrace/tiled_render.h"

#include <glm/geometric.hpp>
#include <openvdb/tools/RayIntersector.h>
#include <openvdb/tree/LeafManager.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <vector>

namespace pine::vdbtrace {
namespace {

constexpr double kPi = analytic::kPi;
constexpr double kOpaque = 0.999;
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

// The grids as one thread reads them.
struct FieldReader {
    openvdb::Vec3SGrid::ConstAccessor gradient, needle, albedo;
    openvdb::FloatGrid::ConstAccessor opacity;
    explicit FieldReader(const bake::TreeGrids& g)
        : gradient(g.layerGradient->getConstAccessor()),
          needle(g.needleDirection->getConstAccessor()),
          albedo(g.needleAlbedo->getConstAccessor()),
          opacity(g.layerOpacity->getConstAccessor())
    {
    }
    /// -ln(1 - A) |d . G| at voxel ijk, per cm; 0 outside the boughs.
    double extinction(const openvdb::Coord& ijk, const Vec3& d)
    {
        float A;
        if (!opacity.probeValue(ijk, A) || !(A > 0.0f)) return 0.0;
        const double mu = A >= 1.0f ? 1e30 : -std::log1p(-double(A));
        return mu * std::abs(glm::dot(d, toGlm(gradient.getValue(ijk))));
    }
};

class ReferenceTracer {
public:
    ReferenceTracer(const TracedScene& scene, const bake::TreeGrids& grids, const EffectsPlan& plan)
        : mScene(scene), mGrids(grids), mPlan(plan),
          mHasVolume(grids.layerOpacity && grids.layerOpacity->activeVoxelCount() > 0),
          mH(grids.voxelSize_cm)
    {
        if (mHasVolume) mIntersector = std::make_unique<Intersector>(*grids.layerOpacity);
        for (const TracedBough& b : scene.boughs) {  // specular parameters are not baked
            mSpecularWeight = b.specularWeight;
            mExponent = b.exponent;
            break;
        }
        if (mHasVolume && (plan.shadowRays || plan.selfShadowing)) computeLightTransmittance();
    }

    /// Optical depth along o + t d for t in [0, tMax] through the grids.
    double opticalDepth(Intersector& intersector, FieldReader& field, const Vec3& o,
                        const Vec3& d, double tMax, std::uint64_t& spans) const
    {
        double tau = 0.0;
        march(intersector, o, d, tMax, [&](const openvdb::Coord& ijk, double ta, double tb) {
            ++spans;
            tau += field.extinction(ijk, d) * (tb - ta);
        });
        return tau;
    }

    void tracePixel(const ConeCamera& camera, int x, int y, int subpixels, float* rgba,
                    float& depth, float& diffuseOut, float& specularOut, float& foliageOut,
                    RenderStats& stats);

private:
    template <class Visit>
    void march(Intersector& intersector, const Vec3& o, const Vec3& d, double tMax,
               Visit&& visit) const
    {
        if (!mHasVolume) return;
        using RayT = openvdb::math::Ray<double>;
        const RayT ray(openvdb::Vec3d(o.x, o.y, o.z), openvdb::Vec3d(d.x, d.y, d.z), 0.0, tMax);
        if (!intersector.setWorldRay(ray)) return;
        double i0, i1;
        while (intersector.march(i0, i1)) {
            const double w0 = std::max(0.0, intersector.getWorldTime(i0));
            const double w1 = std::min(tMax, intersector.getWorldTime(i1));
            walkVoxels(o, d, mH, w0, w1, visit);
        }
    }

    double branchTransmittance(const Vec3& x, const Light& light, double footprint,
                               std::size_t self) const;
    void computeLightTransmittance();
    // Irradiance at x from each light, attenuated as the plan asks.
    void surfaceLight(Intersector& intersector, FieldReader& field, const Vec3& x,
                      double footprint, std::size_t self, std::vector<Vec3>& irradiance,
                      std::vector<Vec3>& towards, RenderStats& stats) const;

    const TracedScene& mScene;
    const bake::TreeGrids& mGrids;
    const EffectsPlan& mPlan;
    bool mHasVolume;
    double mH;
    std::unique_ptr<Intersector> mIntersector;
    std::vector<openvdb::FloatGrid::Ptr> mLightTransmittance;  // per light, per voxel centre
    double mSpecularWeight = 0.0, mExponent = 100.0;

public:
    std::unique_ptr<Intersector> intersector() const
    {
        return mHasVolume ? std::make_unique<Intersector>(*mIntersector) : nullptr;
    }
};

double ReferenceTracer::branchTransmittance(const Vec3& x, const Light& light, double footprint,
                                            std::size_t self) const
{
    double tMax;
    const ConeRay ray = light.shadowCone(x, footprint, tMax);
    double transmittance = 1.0;
    mScene.bvh.query(ray, tMax, [&](std::uint32_t index) {
        if (index == self || !mScene.isBranch(index)) return;
        const TracedBranch& br = mScene.branches[index];
        Passage p;
        if (closestPassage(ray, br.base_cm, br.tip_cm, p) && p.t < tMax) {
            transmittance *= 1.0 - stripCoverage(p.gap, br.radius_cm, ray.width(p.t));
        }
    });
    return transmittance;
}

void ReferenceTracer::computeLightTransmittance()
{
    // The light reaching each voxel's centre depends on the voxel, not on the view: once per
    // voxel and light, through every bough's layers (and branches, with shadows).
    for (std::size_t li = 0; li < mScene.lights.size(); ++li) {
        const Light& light = mScene.lights[li];
        auto grid = openvdb::FloatGrid::create(1.0f);
        grid->setTransform(mGrids.layerOpacity->transform().copy());
        grid->tree().topologyUnion(mGrids.layerOpacity->tree());
        openvdb::tree::LeafManager<openvdb::FloatTree> leaves(grid->tree());
        leaves.foreach([&](openvdb::FloatTree::LeafNodeType& leaf, std::size_t) {
            const std::unique_ptr<Intersector> intersector = this->intersector();
            FieldReader field(mGrids);
            std::uint64_t spans = 0;
            for (auto it = leaf.beginValueOn(); it; ++it) {
                const openvdb::Vec3d c = grid->transform().indexToWorld(it.getCoord());
                const Vec3 x(c.x(), c.y(), c.z());
                Vec3 L, irradiance;
                double distance;
                light.at(x, L, distance, irradiance);
                const double tMax = std::isfinite(distance) ? distance : 1e7;
                double T = std::exp(-opticalDepth(*intersector, field, x, L, tMax, spans));
                if (mPlan.shadowRays) T *= branchTransmittance(x, light, mH, std::size_t(-1));
                it.setValue(float(T));
            }
        });
        mLightTransmittance.push_back(grid);
    }
}

void ReferenceTracer::surfaceLight(Intersector& intersector, FieldReader& field, const Vec3& x,
                                   double footprint, std::size_t self,
                                   std::vector<Vec3>& irradiance, std::vector<Vec3>& towards,
                                   RenderStats& stats) const
{
    irradiance.resize(mScene.lights.size());
    towards.resize(mScene.lights.size());
    for (std::size_t i = 0; i < mScene.lights.size(); ++i) {
        double distance;
        mScene.lights[i].at(x, towards[i], distance, irradiance[i]);
        if (!mPlan.shadowRays) continue;
        ++stats.shadowRays;
        const double tMax = std::isfinite(distance) ? distance : 1e7;
        std::uint64_t spans = 0;
        irradiance[i] *= std::exp(-opticalDepth(intersector, field, x, towards[i], tMax, spans)) *
                         branchTransmittance(x, mScene.lights[i], footprint, self);
    }
}

struct Surface {
    double t = 0.0, alpha = 0.0;
    Vec3 diffuse{0.0};  // premultiplied
};

void ReferenceTracer::tracePixel(const ConeCamera& camera, int x, int y, int subpixels,
                                 float* rgba, float& depthOut, float& diffuseOut,
                                 float& specularOut, float& foliageOut, RenderStats& stats)
{
    const std::unique_ptr<Intersector> intersector = this->intersector();
    FieldReader field(mGrids);
    std::vector<openvdb::FloatGrid::ConstAccessor> lightT;
    for (const auto& g : mLightTransmittance) lightT.push_back(g->getConstAccessor());
    std::vector<Vec3> irradiance, towards;
    std::vector<Surface> surfaces;

    Vec3 sumDiffuse(0.0), sumSpecular(0.0);
    double sumAlpha = 0.0, sumFoliage = 0.0, sumDepth = 0.0;
    const int n = std::max(1, subpixels);
    for (int sy = 0; sy < n; ++sy) {
        for (int sx = 0; sx < n; ++sx) {
            const ConeRay ray = camera.coneAt(x + (sx + 0.5) / n, y + (sy + 0.5) / n, 1.0 / n);
            ++stats.coneRays;
            const Vec3 V = -ray.direction;
            // Surfaces: branches (strip coverage of the sub-ray's footprint) and the ground.
            surfaces.clear();
            double tEnd = 1e7, tGround;
            Vec3 normal;
            const bool ground = hitGround(mScene.scene->ground, ray, tGround, normal);
            if (ground) tEnd = tGround;
            mScene.bvh.query(ray, tEnd, [&](std::uint32_t index) {
                if (!mScene.isBranch(index)) return;
                const TracedBranch& br = mScene.branches[index];
                Passage p;
                if (!closestPassage(ray, br.base_cm, br.tip_cm, p) || p.t > tEnd) return;
                const double w = ray.width(p.t), c = stripCoverage(p.gap, br.radius_cm, w);
                if (c <= 0.0) return;
                ++stats.branchHits;
                double tIn = p.t, tOut;
                intersectCylinder(ray, br.base_cm, br.tip_cm, br.radius_cm, tIn, tOut);
                Surface s{tIn, c, Vec3(0.0)};
                if (mPlan.diffuse) {
                    const Vec3 at = ray.origin + p.t * ray.direction;
                    surfaceLight(*intersector, field, at, w, index, irradiance, towards, stats);
                    const Vec3 axis = glm::normalize(br.tip_cm - br.base_cm);
                    for (std::size_t i = 0; i < irradiance.size(); ++i) {
                        s.diffuse += c * br.albedo / kPi * irradiance[i] *
                                     analytic::needleDiffuse(axis, towards[i], V);
                        ++stats.diffuseEvaluations;
                    }
                }
                surfaces.push_back(s);
            });
            if (ground) {
                ++stats.groundHits;
                Surface s{tGround, 1.0, Vec3(0.0)};
                if (mPlan.diffuse) {
                    const Vec3 at = ray.origin + tGround * ray.direction;
                    surfaceLight(*intersector, field, at, ray.width(tGround), std::size_t(-1),
                                 irradiance, towards, stats);
                    for (std::size_t i = 0; i < irradiance.size(); ++i) {
                        s.diffuse += mScene.scene->ground.albedo / kPi * irradiance[i] *
                                     std::max(0.0, glm::dot(normal, towards[i]));
                        ++stats.diffuseEvaluations;
                    }
                }
                surfaces.push_back(s);
            }
            std::sort(surfaces.begin(), surfaces.end(),
                      [](const Surface& a, const Surface& b) { return a.t < b.t; });

            // Front to back: volume spans, with the surfaces composited where they lie.
            double A = 0.0, foliage = 0.0, depth = 0.0;
            Vec3 diffuse(0.0), specular(0.0);
            std::size_t next = 0;
            const auto addSurface = [&](const Surface& s) {
                if (A < 0.5 && A + (1.0 - A) * s.alpha >= 0.5) depth = s.t;
                diffuse += (1.0 - A) * s.diffuse;
                A += (1.0 - A) * s.alpha;
            };
            const auto addVolume = [&](double sigma, double dt, const Vec3& jd, const Vec3& js,
                                       double tAt) {
                const double alpha = 1.0 - std::exp(-sigma * dt);
                if (A < 0.5 && A + (1.0 - A) * alpha >= 0.5) depth = tAt;
                diffuse += (1.0 - A) * alpha * jd;
                specular += (1.0 - A) * alpha * js;
                foliage += (1.0 - A) * alpha;
                A += (1.0 - A) * alpha;
            };
            march(*intersector, ray.origin, ray.direction, tEnd,
                  [&](const openvdb::Coord& ijk, double ta, double tb) {
                      if (A > kOpaque) return;
                      ++stats.voxelSpans;
                      const double sigma = field.extinction(ijk, ray.direction);
                      Vec3 jd(0.0), js(0.0);
                      if (sigma > 0.0) {
                          const Vec3 needle = toGlm(field.needle.getValue(ijk));
                          const Vec3 albedo = toGlm(field.albedo.getValue(ijk));
                          const openvdb::Vec3d c =
                              mGrids.layerOpacity->transform().indexToWorld(ijk);
                          const Vec3 centre(c.x(), c.y(), c.z());
                          for (std::size_t i = 0; i < mScene.lights.size(); ++i) {
                              Vec3 L, E;
                              double distance;
                              mScene.lights[i].at(centre, L, distance, E);
                              if (!lightT.empty()) E *= double(lightT[i].getValue(ijk));
                              if (mPlan.diffuse) {
                                  jd += albedo / kPi * E * analytic::needleDiffuse(needle, L, V);
                                  ++stats.diffuseEvaluations;
                              }
                              if (mPlan.specular) {
                                  js += mSpecularWeight * E *
                                        analytic::needleSpecular(needle, L, V, mExponent);
                                  ++stats.specularEvaluations;
                              }
                          }
                      }
                      while (next < surfaces.size() && surfaces[next].t <= tb) {
                          const double ts = std::max(ta, surfaces[next].t);
                          if (sigma > 0.0) addVolume(sigma, ts - ta, jd, js, ta);
                          addSurface(surfaces[next++]);
                          ta = ts;
                      }
                      if (sigma > 0.0) addVolume(sigma, tb - ta, jd, js, ta);
                  });
            while (next < surfaces.size() && A <= kOpaque) addSurface(surfaces[next++]);

            sumDiffuse += diffuse;
            sumSpecular += specular;
            sumAlpha += std::min(1.0, A);
            sumFoliage += foliage;
            sumDepth += depth;
        }
    }
    const double w = 1.0 / (n * n);
    const Vec3 colour = (sumDiffuse + sumSpecular) * w;
    rgba[0] = float(colour.x);
    rgba[1] = float(colour.y);
    rgba[2] = float(colour.z);
    rgba[3] = float(sumAlpha * w);
    depthOut = float(sumDepth * w);
    diffuseOut =
        float(0.2126 * sumDiffuse.x * w + 0.7152 * sumDiffuse.y * w + 0.0722 * sumDiffuse.z * w);
    specularOut =
        float(0.2126 * sumSpecular.x * w + 0.7152 * sumSpecular.y * w + 0.0722 * sumSpecular.z * w);
    foliageOut = float(sumFoliage * w);
}

}  // namespace

bake::TreeGrids bakeScene(const TracedScene& scene, double voxelSize_cm)
{
    std::vector<bake::BoughSpec> specs;
    specs.reserve(scene.boughs.size());
    for (const TracedBough& b : scene.boughs) {
        bake::BoughSpec s;
        s.base_cm = b.base_cm;
        s.tip_cm = b.tip_cm;
        s.aperture_rad = b.geometry.cone.aperture_rad;
        s.needleLength_cm = b.geometry.cone.needleLength_cm;
        s.needleRadius_cm = b.geometry.cone.needleRadius_cm;
        s.needlesPerCone = b.geometry.cone.needlesPerCone;
        s.coneSpacing_cm = b.geometry.coneSpacing_cm;
        s.needleAlbedo = b.needleAlbedo;
        specs.push_back(s);
    }
    bake::BakeSettings settings;
    settings.voxelSize_cm = voxelSize_cm;
    settings.pyramidLevels = 1;  // the reference reads the full-resolution fields only
    return bake::bakeBoughs(specs, settings);
}

RenderResult renderReference(const TracedScene& scene, const bake::TreeGrids& grids,
                             const ReferenceOptions& options)
{
    using Clock = std::chrono::steady_clock;
    const auto start = Clock::now();
    const ConeCamera camera(scene.scene->camera);
    const EffectsPlan plan = EffectsPlan::from(scene.scene->effects);
    ReferenceTracer tracer(scene, grids, plan);
    RenderResult result;
    result.image = Image(camera.width(), camera.height());
    Image& image = result.image;
    for (const char* name : {"level", "depth", "diffuse", "specular", "foliage"}) image.aov(name);

    forEachTile(camera.width(), camera.height(), 16, options.progress, result.stats,
                [&](int x0, int y0, int x1, int y1, RenderStats& stats) {
        for (int y = y0; y < y1; ++y) {
            for (int x = x0; x < x1; ++x) {
                const std::size_t i = std::size_t(y) * camera.width() + x;
                tracer.tracePixel(camera, x, y, options.subpixels, image.pixel(x, y),
                                  image.aovs["depth"][i], image.aovs["diffuse"][i],
                                  image.aovs["specular"][i], image.aovs["foliage"][i], stats);
            }
        }
    });
    result.seconds = std::chrono::duration<double>(Clock::now() - start).count();
    return result;
}

}  // namespace pine::vdbtrace
