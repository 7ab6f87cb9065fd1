#include "pine/vdbtrace/surface_shading.h"

#include "pine/analytic/needle_shader.h"
#include "pine/vdbtrace/ground_hit.h"

#include <glm/geometric.hpp>

#include <algorithm>

namespace pine::vdbtrace {

double shadowConeTransmittance(const TracedScene& scene, const Vec3& x, std::size_t light,
                               double footprint_cm, std::size_t self, bool throughBoughs)
{
    double tMax;
    const ConeRay ray = scene.lights[light].shadowCone(x, footprint_cm, tMax);
    double transmittance = 1.0;
    scene.bvh.query(ray, tMax, [&](std::uint32_t index) {
        if (index == self || transmittance < 1e-4) return;
        const bool branch = scene.isBranch(index);
        if (!branch && !throughBoughs) return;
        Passage p;
        if (branch) {
            const TracedBranch& br = scene.branches[index];
            if (closestPassage(ray, br.base_cm, br.tip_cm, p) && p.t < tMax) {
                transmittance *= 1.0 - stripCoverage(p.gap, br.radius_cm, ray.width(p.t));
            }
        } else {
            const TracedBough& b = scene.bough(index);
            if (closestPassage(ray, b.base_cm, b.stripEnd_cm, p) && p.t < tMax) {
                transmittance *= 1.0 - b.lighting[light].opacityFromLight.overFootprint(
                                           p.gap, b.radius_cm, ray.width(p.t));
            }
        }
    });
    return transmittance;
}

const std::vector<Incident>& SurfaceShading::lightAt(const Vec3& x, double footprint_cm,
                                                     std::size_t self)
{
    mIncident.resize(mScene.lights.size());
    for (std::size_t i = 0; i < mScene.lights.size(); ++i) {
        double distance;
        mScene.lights[i].at(x, mIncident[i].towards, distance, mIncident[i].irradiance);
        if (!mPlan.shadowRays) continue;
        ++mStats.shadowRays;
        mIncident[i].irradiance *= mTransport.transmittance(x, i, footprint_cm, self);
    }
    return mIncident;
}

bool SurfaceShading::branch(const ConeRay& ray, std::size_t index, double tMax, Fragment& out)
{
    const TracedBranch& br = mScene.branches[index];
    Passage p;
    if (!closestPassage(ray, br.base_cm, br.tip_cm, p)) return false;
    const double w = ray.width(p.t);
    const double c = stripCoverage(p.gap, br.radius_cm, w);
    if (c <= 0.0) return false;
    double tIn = p.t, tOut;
    intersectCylinder(ray, br.base_cm, br.tip_cm, br.radius_cm, tIn, tOut);
    if (tIn > tMax) return false;  // behind the ground: hidden, not worth its shadow rays
    ++mStats.branchHits;
    out = Fragment{tIn, c, Vec3(0.0), Vec3(0.0), 0, false};
    if (!mPlan.diffuse) return true;
    const Vec3 axis = glm::normalize(br.tip_cm - br.base_cm);
    for (const Incident& light : lightAt(ray.origin + p.t * ray.direction, w, index)) {
        const double R = analytic::needleDiffuse(axis, light.towards, -ray.direction);
        out.diffuse += c * br.albedo / analytic::kPi * light.irradiance * R;
        ++mStats.diffuseEvaluations;
    }
    return true;
}

bool SurfaceShading::ground(const ConeRay& ray, Fragment& out)
{
    double t;
    Vec3 normal;
    if (!hitGround(mScene.scene->ground, ray, t, normal)) return false;
    ++mStats.groundHits;
    out = Fragment{t, 1.0, Vec3(0.0), Vec3(0.0), 0, false};
    if (!mPlan.diffuse) return true;
    for (const Incident& light : lightAt(ray.origin + t * ray.direction, ray.width(t),
                                         kNoPrimitive)) {
        out.diffuse += mScene.scene->ground.albedo / analytic::kPi * light.irradiance *
                       std::max(0.0, glm::dot(normal, light.towards));
        ++mStats.diffuseEvaluations;
    }
    return true;
}

}  // namespace pine::vdbtrace
