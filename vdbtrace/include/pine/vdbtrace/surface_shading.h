// Branches and the ground as the cone-traced methods (multiscale and reference) shade them:
// one implementation, so that the two methods differ only in how they shade needles and how
// light reaches a point through them (their LightTransport).
#pragma once

#include "pine/vdbtrace/effects_plan.h"
#include "pine/vdbtrace/fragment.h"
#include "pine/vdbtrace/render_stats.h"
#include "pine/vdbtrace/traced_scene.h"

#include <cstddef>
#include <vector>

namespace pine::vdbtrace {

/// Marks a point that belongs to no primitive of the BVH (the ground, a voxel centre).
inline constexpr std::size_t kNoPrimitive = std::size_t(-1);

/// How light reaches a point through a method's model of the scene: its shadows.
class LightTransport {
public:
    virtual ~LightTransport() = default;
    /// Transmittance from x to light `light` through everything but primitive `self`, for a
    /// footprint `footprint_cm` wide at x.
    virtual double transmittance(const Vec3& x, std::size_t light, double footprint_cm,
                                 std::size_t self) = 0;
};

/// Light arriving at a point from one light.
struct Incident {
    Vec3 towards{0.0};     ///< unit, towards the light
    Vec3 irradiance{0.0};  ///< on a surface facing it, after the transmittance
};

/// The shadow cone from x to light `light` (Light::shadowCone) through the branches (strip
/// coverage of the cone's footprint) and, with `throughBoughs`, the boughs (that coverage times
/// the bough law's opacity seen from the light), all but primitive `self`. Stops multiplying
/// below 1e-4.
double shadowConeTransmittance(const TracedScene& scene, const Vec3& x, std::size_t light,
                               double footprint_cm, std::size_t self, bool throughBoughs);

/// Per-thread shading of surfaces: branches as Lambertian cylinders (eq. 1 is the diffuse
/// cylinder's reflectance, so bark is one), the ground as a Lambertian surface, both lit
/// through `transport` when the plan has shadows.
class SurfaceShading {
public:
    SurfaceShading(const TracedScene& scene, const EffectsPlan& plan, LightTransport& transport,
                   RenderStats& stats)
        : mScene(scene), mPlan(plan), mTransport(transport), mStats(stats)
    {
    }

    /// Irradiance at x from each light, through the transport when the plan has shadow rays
    /// (each counted). Valid until the next call.
    const std::vector<Incident>& lightAt(const Vec3& x, double footprint_cm, std::size_t self);

    /// Branch `index` (a primitive of the BVH) as the cone ray meets it before tMax: false
    /// when its strip covers none of the footprint.
    bool branch(const ConeRay& ray, std::size_t index, double tMax, Fragment& out);
    /// The ground, when the ray's axis meets it: false otherwise. `out.t` is the distance.
    bool ground(const ConeRay& ray, Fragment& out);

private:
    const TracedScene& mScene;
    const EffectsPlan& mPlan;
    LightTransport& mTransport;
    RenderStats& mStats;
    std::vector<Incident> mIncident;
};

}  // namespace pine::vdbtrace
