#include "pine/vdbtrace/surface_shading.h"

#include "pine/analytic/needle_shader.h"
#include "pine/vdbtrace/ground_hit.h"
#include "pine/vdbtrace/light_columns.h"
#include "pine/vdbtrace/occluder_profile.h"

#include <glm/geometric.hpp>

#include <algorithm>
#include <cmath>

namespace pine::vdbtrace {

double shadowConeTransmittance(const TracedScene& scene, const Vec3& x, std::size_t light,
                               double footprint_cm, std::size_t self, bool throughBoughs,
                               const ShadowSamples* samples)
{
    // One point at x when no samples are given.
    static const ShadowSamples kOrigin{Vec3(0.0), Vec3(0.0), {{0.0, 1.0}}};
    const ShadowSamples& at = samples && !samples->points.empty() ? *samples : kOrigin;
    double reach = 0.0;   // of the points from x, across the light
    double behind = 0.0;  // of the farthest point from the light beyond x
    for (const ShadowSamples::Point& q : at.points) {
        reach = std::max(reach, std::hypot(q.offset_cm, q.sideways_cm));
        behind = std::max(behind, -q.towardsLight_cm);
    }
    double tMax;
    const ConeRay ray =
        scene.lights[light].shadowCone(x, footprint_cm + 2.0 * reach, tMax);
    // Each point reads the occluders with the footprint's own width.
    const double pointWidth = reach > 0.0 ? footprint_cm / (footprint_cm + 2.0 * reach) : 1.0;
    // Each point's transmittance so far.
    thread_local std::vector<double> T;
    T.assign(at.points.size(), 1.0);
    const auto occluder = [&](std::uint32_t index) {
        if (index == self) return true;
        const bool branch = scene.isBranch(index);
        if (!branch && !throughBoughs) return true;
        const Vec3 a = branch ? scene.branches[index].base_cm : scene.bough(index).base_cm;
        const Vec3 b = branch ? scene.branches[index].tip_cm : scene.bough(index).stripEnd();
        Passage p;
        if (!closestPassage(ray, a, b, p) || !(p.t < tMax + behind)) return true;
        // The points' lines pass the occluder shifted across its strip and along its axis by
        // their offsets (scaled towards a point light), each read with the footprint's own
        // width; along the axis where its cones reach (render.occluder_profile "cones").
        const Vec3 u = glm::normalize(b - a);
        const Vec3 n = stripAcross(u, ray.direction);
        const Vec3 c = ray.origin + p.t * ray.direction;
        const double gap = reach > 0.0 ? glm::dot(c - (a + p.s * (b - a)), n) : p.gap;
        const double scale = scene.lights[light].directional ? 1.0 : p.t / tMax;
        const double along = glm::dot(at.across, n) * scale;
        const double aside = glm::dot(at.sideways, n) * scale;
        // A shift d across the light moves a line's passage along the axis by (d . u) / (1 -
        // (L . u)^2), L the light's direction. A light within 0.06 degrees of the axis has no
        // passage to speak of: the line runs along the whole bough, which it reads even.
        const double lu = glm::dot(ray.direction, u), sin2 = 1.0 - lu * lu;
        const bool profiled =
            !branch && scene.occludersByCones && scene.bough(index).stripToConesEnd && sin2 > 1e-6;
        const AxialCones cones = profiled ? AxialCones::of(scene.bough(index)) : AxialCones{};
        const double perShift = profiled ? scale / sin2 : 0.0;
        const double hAcross = glm::dot(at.across, u) * perShift;
        const double hSideways = glm::dot(at.sideways, u) * perShift;
        const double w = pointWidth * ray.width(p.t);
        const double R = branch ? scene.branches[index].radius_cm : scene.bough(index).radius_cm;
        // A line farther than this from the axis misses the strip over its footprint: it
        // reads 0 (stripCoverage, StripProfile::overFootprint), kept a hair wide of rounding.
        const double misses = (R + 0.5 * std::max(w, 0.0)) * (1.0 + 1e-12);
        std::shared_ptr<const StripProfile> fromLight;  // the bough's, once a point meets it
        bool dark = true;  // every point: nothing further shows
        for (std::size_t k = 0; k < T.size(); ++k) {
            const ShadowSamples::Point& q = at.points[k];
            if (p.t < tMax - q.towardsLight_cm) {  // else the occluder lies beyond this point
                const double g = gap + along * q.offset_cm + aside * q.sideways_cm;
                if (std::abs(g) < misses) {
                    if (!branch && !fromLight) {
                        fromLight = scene.bough(index).opacityFromLight(light);
                    }
                    double alpha =
                        branch ? stripCoverage(g, R, w) : fromLight->overFootprint(g, R, w);
                    if (profiled) {
                        const double h = p.s * cones.length() + hAcross * q.offset_cm +
                                         hSideways * q.sideways_cm;
                        alpha = cones.opacityAt(alpha, h);
                    }
                    T[k] *= 1.0 - alpha;
                }
            }
            dark = dark && T[k] < 1e-4;
        }
        return !dark;
    };
    if (const LightColumns* columns = scene.columns(light)) {
        // Every occluder that can shade a point lies within this of x's line (its strip's
        // half-width more): a point's line at most `reach` off it, read over at most the
        // cone's width.
        // A centimetre deeper than the visitor reads: where an occluder runs nearly along the
        // light, closestPassage places it along the cone less precisely.
        columns->query(x, 0.5 * ray.width(tMax + behind) + reach, behind + 1.0, occluder);
    } else {
        scene.bvh.query(ray, tMax + behind, occluder);
    }
    if (at.transmittances) *at.transmittances = T;
    double sum = 0.0, weight = 0.0;
    for (std::size_t k = 0; k < T.size(); ++k) {
        sum += at.points[k].weight * T[k];
        weight += at.points[k].weight;
    }
    return weight > 0.0 ? sum / weight : 1.0;
}

Incident SurfaceShading::unshadowed(std::size_t light, const Vec3& x) const
{
    Incident in;
    double distance;
    mScene.lights[light].at(x, in.towards, distance, in.irradiance);
    return in;
}

double SurfaceShading::shadow(std::size_t light, const Vec3& x, double footprint_cm,
                              std::size_t self, const ShadowSamples* samples)
{
    if (!mPlan.shadowRays) return 1.0;
    ++mStats.shadowRays;
    return mTransport.transmittance(x, light, footprint_cm, self, samples);
}

const std::vector<Incident>& SurfaceShading::lightAt(const Vec3& x, double footprint_cm,
                                                     std::size_t self)
{
    mIncident.resize(mScene.lights.size());
    for (std::size_t i = 0; i < mScene.lights.size(); ++i) {
        mIncident[i] = unshadowed(i, x);
        mIncident[i].irradiance *= shadow(i, x, footprint_cm, self, nullptr);
    }
    return mIncident;
}

bool hitBranch(const ConeRay& ray, const TracedBranch& branch, double tMax, BranchHit& out)
{
    Passage& p = out.passage;
    if (!closestPassage(ray, branch.base_cm, branch.tip_cm, p)) return false;
    out.coverage = stripCoverage(p.gap, branch.radius_cm, ray.width(p.t));
    if (out.coverage <= 0.0) return false;
    double tOut;
    out.t = p.t;
    intersectCylinder(ray, branch.base_cm, branch.tip_cm, branch.radius_cm, out.t, tOut);
    return !(out.t > tMax);  // behind the ground: hidden, not worth its shadow rays
}

bool SurfaceShading::branch(const ConeRay& ray, std::size_t index, double tMax, Fragment& out)
{
    const TracedBranch& br = mScene.branches[index];
    BranchHit hit;
    if (!hitBranch(ray, br, tMax, hit)) return false;
    const Passage& p = hit.passage;
    const double w = ray.width(p.t), c = hit.coverage;
    ++mStats.branchHits;
    out = Fragment{hit.t, c, Vec3(0.0), Vec3(0.0), 0, false, br.tree};
    if (!mPlan.diffuse) return true;
    const Vec3 axis = glm::normalize(br.tip_cm - br.base_cm);
    for (const Incident& light : lightAt(ray.origin + p.t * ray.direction, w, index)) {
        const double R = analytic::needleDiffuse(axis, light.towards, -ray.direction);
        out.diffuse += c * mScene.barks[br.bark] / analytic::kPi * light.irradiance * R;
        ++mStats.diffuseEvaluations;
    }
    return true;
}

bool SurfaceShading::ground(const ConeRay& ray, Fragment& out)
{
    double t;
    Vec3 normal;
    if (!hitGround(mScene.scene->ground, ray, t, normal)) return false;
    out = groundAt(ray, t, normal);
    return true;
}

Fragment SurfaceShading::groundAt(const ConeRay& ray, double t, const Vec3& normal)
{
    ++mStats.groundHits;
    Fragment out;
    out = Fragment{t, 1.0, Vec3(0.0), Vec3(0.0), 0, false};
    if (!mPlan.diffuse) return out;
    for (const Incident& light : lightAt(ray.origin + t * ray.direction, ray.width(t),
                                         kNoPrimitive)) {
        out.diffuse += mScene.scene->ground.albedo / analytic::kPi * light.irradiance *
                       std::max(0.0, glm::dot(normal, light.towards));
        ++mStats.diffuseEvaluations;
    }
    return out;
}

}  // namespace pine::vdbtrace
