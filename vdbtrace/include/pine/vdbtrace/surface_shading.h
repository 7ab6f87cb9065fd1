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

/// Where the needles lie that one shadow stands for (a bough's needles on a camera ray): points
/// offset from the shadow's origin along `across` and `sideways` (unit, perpendicular to the
/// light and to each other), and towards the light, each with the weight of the light it
/// reflects to the pixel. The shadow is their weighted mean transmittance, each occluder read
/// where each point's own shadow line passes it, if it passes before the point: what the
/// explicit needles' shadow rays, one from each needle, average to.
struct ShadowSamples {
    struct Point {
        double offset_cm, weight;
        double sideways_cm = 0.0, towardsLight_cm = 0.0;
    };
    Vec3 across{0.0}, sideways{0.0};
    std::vector<Point> points;
    /// Where shadowConeTransmittance writes each point's own transmittance (one per point, in
    /// their order) besides returning their weighted mean, for samples with points; null:
    /// nowhere.
    std::vector<double>* transmittances = nullptr;
};

/// How light reaches a point through a method's model of the scene: its shadows.
class LightTransport {
public:
    virtual ~LightTransport() = default;
    /// Transmittance from x to light `light` through everything but primitive `self`, for a
    /// footprint `footprint_cm` wide at x; with `samples`, their weighted mean (ShadowSamples).
    virtual double transmittance(const Vec3& x, std::size_t light, double footprint_cm,
                                 std::size_t self, const ShadowSamples* samples) = 0;
};

/// Light arriving at a point from one light.
struct Incident {
    Vec3 towards{0.0};     ///< unit, towards the light
    Vec3 irradiance{0.0};  ///< on a surface facing it, after the transmittance
};

/// The shadow cone from x to light `light` (Light::shadowCone) through the branches (strip
/// coverage of the cone's footprint) and, with `throughBoughs`, the boughs (that coverage times
/// the bough law's opacity seen from the light), all but primitive `self`; with `samples`
/// their weighted mean, the cone widened to hold them all. Stops multiplying below 1e-4.
double shadowConeTransmittance(const TracedScene& scene, const Vec3& x, std::size_t light,
                               double footprint_cm, std::size_t self, bool throughBoughs,
                               const ShadowSamples* samples = nullptr);

/// Where a cone ray meets a branch: its axis's closest passage, what of the footprint the
/// branch's strip covers there (stripCoverage) and the depth at which the axis enters the
/// branch (the passage's where it misses it). False where the strip covers none of the
/// footprint or the branch begins beyond tMax.
struct BranchHit {
    Passage passage;
    double coverage = 0.0, t = 0.0;
};
bool hitBranch(const ConeRay& ray, const TracedBranch& branch, double tMax, BranchHit& out);

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
    /// Light `light` at x before any shadow.
    Incident unshadowed(std::size_t light, const Vec3& x) const;
    /// The transmittance from x to light `light` through the transport for a footprint
    /// `footprint_cm` wide at x (counted as a shadow ray), the mean over `samples` if given;
    /// 1 when the plan has no shadow rays.
    double shadow(std::size_t light, const Vec3& x, double footprint_cm, std::size_t self,
                  const ShadowSamples* samples = nullptr);

    /// Branch `index` (a primitive of the BVH) as the cone ray meets it before tMax: false
    /// when its strip covers none of the footprint.
    bool branch(const ConeRay& ray, std::size_t index, double tMax, Fragment& out);
    /// The ground, when the ray's axis meets it: false otherwise. `out.t` is the distance.
    bool ground(const ConeRay& ray, Fragment& out);
    /// The ground where hitGround found the ray's axis meets it, at t with `normal`.
    Fragment groundAt(const ConeRay& ray, double t, const Vec3& normal);

private:
    const TracedScene& mScene;
    const EffectsPlan& mPlan;
    LightTransport& mTransport;
    RenderStats& mStats;
    std::vector<Incident> mIncident;
};

}  // namespace pine::vdbtrace
