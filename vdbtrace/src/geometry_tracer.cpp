// The explicit-needle ground truth: solid cylinders in an Embree 3 BVH, point samples, shadow
// rays, and the per-point integrands of the paper's eqs. (1) and (2).
//
// A needle is what section 4 integrates over: a cylinder's side. Its ends are open by default
// (render.needle_ends "open"): a line meets a needle where it enters through the side, and
// passes through its ends, so that a needle covers 2 r l |sin| of the view and reflects from
// its side alone, as every level models it. With "flat" a needle is the solid flat-capped
// cylinder (not RTC_GEOMETRY_TYPE_ROUND_LINEAR_CURVE's capsule, whose hemispheres add pi r^2
// to the projected area 2 r l, +1.8% for the paper's needle): its end discs, r / 2l of its
// area, face along the bough, and on a fir's lit side they carry 4% of its light
// (docs/models.md, "Needle ends"). Branches are always solid.
// Embree's RTC_GEOMETRY_TYPE_CONE_LINEAR_CURVE with equal radii at both ends and no
// neighbours is that cylinder, intersected natively in single precision (NeedlePrimitive::
// Curve, the default); its hit is intersected again here in double precision to be shaded.
// NeedlePrimitive::Cylinder makes cylinders Embree *user* geometry: Embree only builds and
// walks the BVH, and each candidate is intersected exactly, in double precision, with the ray
// the sample really is (carried in the intersection context).
#include "pine/vdbtrace/geometry_tracer.h"

#include "pine/vdbtrace/effects_plan.h"
#include "pine/vdbtrace/ground_hit.h"
#include "pine/vdbtrace/needle_layout.h"
#include "pine/vdbtrace/render_driver.h"

#include <embree3/rtcore.h>
#include <glm/geometric.hpp>
#include <glm/vec3.hpp>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

namespace pine::vdbtrace {
namespace {

constexpr double kPi = analytic::kPi;
constexpr double kInf = std::numeric_limits<double>::infinity();

// One solid cylinder: a needle or a branch. The axis is stored in float (tip error l * 6e-8),
// the base in double so that a forest kilometres wide keeps its needles' 0.05 cm radius exact.
struct Cylinder {
    Vec3 base;
    glm::vec3 axis;  // unit
    float length = 0.0f, radius = 0.0f;
    std::uint32_t owner = 0;  // index of the bough (needles) or the branch
};

struct CylinderSet {
    std::vector<Cylinder> cylinders;
    double pad = 0.0;  // cm added to every box: the float ray Embree walks vs our double ray
    unsigned geomID = RTC_INVALID_GEOMETRY_ID;
    bool openEnds = false;  // met only through the side (render.needle_ends "open")
};

// A scatter's variant (scenes::TreePlacement::variantOf) whose trees are instanced: its first
// tree's needles, laid out once, in world coordinates about `origin` (that tree's base).
struct Variant {
    CylinderSet needles;
    Vec3 origin{0.0};
};

// An instance of a variant's needles at one of its trees.
struct Placed {
    std::size_t variant = 0;
    int tree = -1;
    Vec3 offset{0.0};  // the tree's base less the variant's origin
};

struct Instancing {
    std::vector<Variant> variants;
    std::vector<Placed> byGeomID;  // indexed by the instance's geometry ID in the scene
    std::size_t trees = 0;         // trees drawn as instances
};

// The ray as the sample really is, in double, after Embree's own context (which Embree hands
// back to the callbacks): the closest hit is found here, not in Embree's float fields.
struct RayContext {
    RTCIntersectContext embree;
    Vec3 origin{0.0}, direction{0.0};
    double tMin = 0.0, tMax = kInf;
    double t = kInf;  // closest hit so far
    unsigned geomID = RTC_INVALID_GEOMETRY_ID, primID = 0;
    unsigned instID = RTC_INVALID_GEOMETRY_ID;  // the instance hit, if the hit is instanced
    bool cap = false;
    // Shadow rays: the surface itself (in its instance, if any).
    unsigned skipGeom = RTC_INVALID_GEOMETRY_ID, skipPrim = 0, skipInst = RTC_INVALID_GEOMETRY_ID;
};

// The ray's interval inside the solid cylinder: the infinite cylinder's chord intersected with
// the slab 0 <= (p - base).axis <= l. The chord comes from the closest approach (no
// cancellation between two large squares when the ray passes far away). `cap`: entered
// through an end. With `openEnds` only a ray entering through the side meets it (tIn is then
// where it enters; one through an end passes).
bool intersectCylinder(const Vec3& o, const Vec3& d, const Cylinder& c, bool openEnds, double& tIn,
                       double& tOut, bool& cap)
{
    const Vec3 u(c.axis);
    const double r = c.radius, l = c.length;
    const Vec3 w = o - c.base;
    const double wu = glm::dot(w, u), du = glm::dot(d, u);
    double s0 = -kInf, s1 = kInf;
    if (du != 0.0) {
        s0 = -wu / du;
        s1 = (l - wu) / du;
        if (s0 > s1) std::swap(s0, s1);
    } else if (wu < 0.0 || wu > l) {
        return false;
    }
    const Vec3 ww = w - wu * u, dd = d - du * u;
    const double a = glm::dot(dd, dd);
    double c0 = -kInf, c1 = kInf;
    if (a > 0.0) {
        const double tc = -glm::dot(ww, dd) / a;
        const Vec3 p = ww + tc * dd;
        const double h2 = glm::dot(p, p);
        if (h2 > r * r) return false;
        const double half = std::sqrt((r * r - h2) / a);
        c0 = tc - half;
        c1 = tc + half;
    } else if (glm::dot(ww, ww) > r * r) {
        return false;
    }
    tIn = std::max(c0, s0);
    tOut = std::min(c1, s1);
    cap = s0 > c0;
    if (openEnds && (cap || !(c0 > -kInf))) return false;  // through an end, or along the axis
    return tIn < tOut;
}

Vec3 cylinderNormal(const Cylinder& c, const Vec3& x, const Vec3& d, bool cap)
{
    const Vec3 u(c.axis);
    if (cap) return glm::dot(d, u) > 0.0 ? -u : u;
    const Vec3 w = x - c.base;
    const Vec3 radial = w - glm::dot(w, u) * u;
    const double len = glm::length(radial);
    return len > 0.0 ? radial / len : analytic::anyPerpendicular(u);
}

void cylinderBoundsFn(const RTCBoundsFunctionArguments* args)
{
    const auto* set = static_cast<const CylinderSet*>(args->geometryUserPtr);
    const Cylinder& c = set->cylinders[args->primID];
    const Vec3 u(c.axis), tip = c.base + double(c.length) * u;
    float lo[3], hi[3];
    for (int k = 0; k < 3; ++k) {
        // A disc of radius r across u reaches r sqrt(1 - u_k^2) along axis k.
        const double e = c.radius * std::sqrt(std::max(0.0, 1.0 - u[k] * u[k])) + set->pad;
        lo[k] = std::nextafter(float(std::min(c.base[k], tip[k]) - e), -INFINITY);
        hi[k] = std::nextafter(float(std::max(c.base[k], tip[k]) + e), INFINITY);
    }
    RTCBounds* b = args->bounds_o;
    b->lower_x = lo[0], b->lower_y = lo[1], b->lower_z = lo[2];
    b->upper_x = hi[0], b->upper_y = hi[1], b->upper_z = hi[2];
}

void cylinderIntersectFn(const RTCIntersectFunctionNArguments* args)
{
    if (args->N != 1 || !args->valid[0]) return;
    auto* ctx = reinterpret_cast<RayContext*>(args->context);
    const auto* set = static_cast<const CylinderSet*>(args->geometryUserPtr);
    double tIn, tOut;
    bool cap;
    if (!intersectCylinder(ctx->origin, ctx->direction, set->cylinders[args->primID], set->openEnds,
                           tIn, tOut, cap)) {
        return;
    }
    if (!(tIn > ctx->tMin) || tIn > ctx->tMax || tIn > ctx->t) return;
    // Equal distances: the lower (geometry, primitive) wins, whatever order Embree visits in.
    if (tIn == ctx->t && (args->geomID > ctx->geomID ||
                          (args->geomID == ctx->geomID && args->primID > ctx->primID))) {
        return;
    }
    ctx->t = tIn;
    ctx->geomID = args->geomID;
    ctx->primID = args->primID;
    ctx->cap = cap;
    // Embree culls boxes beyond tfar: round up so that an equal-distance candidate survives.
    auto* rayhit = reinterpret_cast<RTCRayHit*>(args->rayhit);
    rayhit->ray.tfar = std::nextafter(float(tIn), INFINITY);
    rayhit->hit.geomID = args->geomID;
    rayhit->hit.primID = args->primID;
}

void cylinderOccludedFn(const RTCOccludedFunctionNArguments* args)
{
    if (args->N != 1 || !args->valid[0]) return;
    auto* ctx = reinterpret_cast<RayContext*>(args->context);
    if (args->geomID == ctx->skipGeom && args->primID == ctx->skipPrim) return;
    const auto* set = static_cast<const CylinderSet*>(args->geometryUserPtr);
    double tIn, tOut;
    bool cap;
    if (!intersectCylinder(ctx->origin, ctx->direction, set->cylinders[args->primID], set->openEnds,
                           tIn, tOut, cap)) {
        return;
    }
    // A solid stops a ray that starts inside it; an open needle one that enters its side.
    if ((set->openEnds ? tIn : tOut) > ctx->tMin && tIn < ctx->tMax) {
        reinterpret_cast<RTCRay*>(args->ray)->tfar = -INFINITY;
    }
}

// Whether Embree's hit i on a native curve is one an open needle has: through its side, from
// outside (Embree also reports an end disc, and where a ray leaves, when asked again). Its Ng
// is the solid's outward normal, along the axis on an end; instances only translate.
bool entersTheSide(const RTCFilterFunctionNArguments* args, unsigned i)
{
    const auto* set = static_cast<const CylinderSet*>(args->geometryUserPtr);
    const glm::vec3 ng(RTCHitN_Ng_x(args->hit, args->N, i), RTCHitN_Ng_y(args->hit, args->N, i),
                       RTCHitN_Ng_z(args->hit, args->N, i));
    const glm::vec3 d(RTCRayN_dir_x(args->ray, args->N, i), RTCRayN_dir_y(args->ray, args->N, i),
                      RTCRayN_dir_z(args->ray, args->N, i));
    const glm::vec3 axis = set->cylinders[RTCHitN_primID(args->hit, args->N, i)].axis;
    return std::abs(glm::dot(ng, axis)) < 0.5f * glm::length(ng) && glm::dot(ng, d) < 0.0f;
}

// Open needles as native curves: a ray passes their ends.
void curveIntersectFilterFn(const RTCFilterFunctionNArguments* args)
{
    for (unsigned i = 0; i < args->N; ++i) {
        if (args->valid[i] && !entersTheSide(args, i)) args->valid[i] = 0;
    }
}

// A shadow ray does not stop at the surface it leaves (a convex cylinder never shadows its own
// lit side), nor, on open needles, at an end: Embree's native curves ask here.
void curveOccludedFilterFn(const RTCFilterFunctionNArguments* args)
{
    const auto* ctx = reinterpret_cast<const RayContext*>(args->context);
    const bool open = static_cast<const CylinderSet*>(args->geometryUserPtr)->openEnds;
    for (unsigned i = 0; i < args->N; ++i) {
        if (!args->valid[i]) continue;
        if ((RTCHitN_geomID(args->hit, args->N, i) == ctx->skipGeom &&
             RTCHitN_primID(args->hit, args->N, i) == ctx->skipPrim &&
             RTCHitN_instID(args->hit, args->N, i, 0) == ctx->skipInst) ||
            (open && !entersTheSide(args, i))) {
            args->valid[i] = 0;
        }
    }
}

// Embree's device and scene, released whatever happens; Embree's allocations counted.
class EmbreeScene {
public:
    EmbreeScene()
    {
        mDevice = rtcNewDevice(nullptr);
        if (!mDevice) throw std::runtime_error("Embree: cannot create a device");
        rtcSetDeviceErrorFunction(
            mDevice,
            [](void* self, RTCError, const char* message) {
                auto* s = static_cast<EmbreeScene*>(self);
                if (s->mError.empty()) s->mError = message ? message : "unknown error";
            },
            this);
        rtcSetDeviceMemoryMonitorFunction(
            mDevice,
            [](void* self, ssize_t bytes, bool) {
                auto* s = static_cast<EmbreeScene*>(self);
                const std::int64_t now = s->mBytes.fetch_add(bytes) + bytes;
                std::int64_t peak = s->mPeak.load();
                while (now > peak && !s->mPeak.compare_exchange_weak(peak, now)) {
                }
                return true;
            },
            this);
        mScene = rtcNewScene(mDevice);
        // Robust traversal: no box is skipped for rounding when a ray grazes it. Compact:
        // 11% less BVH memory on the paper's forest (2.45 M needles), no slower.
        rtcSetSceneFlags(mScene, RTC_SCENE_FLAG_ROBUST | RTC_SCENE_FLAG_COMPACT);
    }
    ~EmbreeScene()
    {
        if (mScene) rtcReleaseScene(mScene);
        for (RTCScene child : mChildren) rtcReleaseScene(child);
        if (mDevice) rtcReleaseDevice(mDevice);
    }
    EmbreeScene(const EmbreeScene&) = delete;
    EmbreeScene& operator=(const EmbreeScene&) = delete;

    void attach(CylinderSet& set, NeedlePrimitive primitive)
    {
        if (set.cylinders.empty()) return;
        if (primitive == NeedlePrimitive::Curve) {
            attachCurves(set);
            return;
        }
        RTCGeometry g = rtcNewGeometry(mDevice, RTC_GEOMETRY_TYPE_USER);
        rtcSetGeometryUserPrimitiveCount(g, unsigned(set.cylinders.size()));
        rtcSetGeometryUserData(g, &set);
        rtcSetGeometryBoundsFunction(g, cylinderBoundsFn, nullptr);
        rtcSetGeometryIntersectFunction(g, cylinderIntersectFn);
        rtcSetGeometryOccludedFunction(g, cylinderOccludedFn);
        rtcCommitGeometry(g);
        set.geomID = rtcAttachGeometry(mScene, g);
        rtcReleaseGeometry(g);
        check();
    }
    void attachCurves(CylinderSet& set) { set.geomID = attachCurvesTo(mScene, set, Vec3(0.0)); }

    /// A scene of its own holding `set` less `origin` (a variant's needles about its first
    /// tree's base), for instance(): float vertices near 0, whatever the forest's extent.
    RTCScene prototype(const CylinderSet& set, const Vec3& origin)
    {
        RTCScene child = rtcNewScene(mDevice);
        mChildren.push_back(child);
        rtcSetSceneFlags(child, RTC_SCENE_FLAG_ROBUST | RTC_SCENE_FLAG_COMPACT);
        if (!set.cylinders.empty()) attachCurvesTo(child, set, origin);
        rtcCommitScene(child);
        check();
        return child;
    }
    /// `child` placed with its origin at `at`: the instance's geometry ID in the scene.
    unsigned instance(RTCScene child, const Vec3& at)
    {
        RTCGeometry g = rtcNewGeometry(mDevice, RTC_GEOMETRY_TYPE_INSTANCE);
        rtcSetGeometryInstancedScene(g, child);
        const float xfm[12] = {1, 0, 0, 0, 1, 0, 0, 0, 1, float(at.x), float(at.y), float(at.z)};
        rtcSetGeometryTransform(g, 0, RTC_FORMAT_FLOAT3X4_COLUMN_MAJOR, xfm);
        rtcCommitGeometry(g);
        const unsigned id = rtcAttachGeometry(mScene, g);
        rtcReleaseGeometry(g);
        check();
        return id;
    }

    void commit()
    {
        rtcCommitScene(mScene);
        check();
    }
    RTCScene scene() const { return mScene; }
    std::size_t peakBytes() const { return std::size_t(std::max<std::int64_t>(0, mPeak.load())); }

private:
    void check() const
    {
        if (!mError.empty()) throw std::runtime_error("Embree: " + mError);
    }
    // Each cylinder a segment of its own: two vertices (x, y, z, r), no flags (no neighbour,
    // so both ends are capped flat); the vertices less `origin`.
    unsigned attachCurvesTo(RTCScene scene, const CylinderSet& set, const Vec3& origin)
    {
        RTCGeometry g = rtcNewGeometry(mDevice, RTC_GEOMETRY_TYPE_CONE_LINEAR_CURVE);
        const std::size_t n = set.cylinders.size();
        auto* vertices = static_cast<float*>(rtcSetNewGeometryBuffer(
            g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT4, 4 * sizeof(float), 2 * n));
        auto* indices = static_cast<unsigned*>(rtcSetNewGeometryBuffer(
            g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT, sizeof(unsigned), n));
        check();
        for (std::size_t i = 0; i < n; ++i) {
            const Cylinder& c = set.cylinders[i];
            const Vec3 tip = c.base + double(c.length) * Vec3(c.axis);
            float* v = vertices + 8 * i;
            for (int k = 0; k < 3; ++k) {
                v[k] = float(c.base[k] - origin[k]);
                v[4 + k] = float(tip[k] - origin[k]);
            }
            v[3] = v[7] = c.radius;
            indices[i] = unsigned(2 * i);
        }
        rtcSetGeometryUserData(g, const_cast<CylinderSet*>(&set));
        rtcSetGeometryOccludedFilterFunction(g, curveOccludedFilterFn);
        if (set.openEnds) rtcSetGeometryIntersectFilterFunction(g, curveIntersectFilterFn);
        rtcCommitGeometry(g);
        const unsigned id = rtcAttachGeometry(scene, g);
        rtcReleaseGeometry(g);
        check();
        return id;
    }

    RTCDevice mDevice = nullptr;
    RTCScene mScene = nullptr;
    std::vector<RTCScene> mChildren;  // the variants' needles, instanced
    std::string mError;
    std::atomic<std::int64_t> mBytes{0}, mPeak{0};
};

// The sample pattern: Sobol' dimensions 1 and 2, a (0,2)-sequence (Kollig & Keller 2002),
// each digitally shifted by a hash of the pixel so that neighbouring pixels do not share an
// error pattern. A digital shift keeps every elementary interval stratified and makes each
// point uniform in the pixel: the estimator is unbiased.
std::uint32_t sobol1(std::uint32_t i)
{
    std::uint32_t r = 0;
    for (std::uint32_t v = 1u << 31; i; i >>= 1, v >>= 1) {
        if (i & 1u) r ^= v;
    }
    return r;
}

std::uint32_t sobol2(std::uint32_t i)
{
    std::uint32_t r = 0;
    for (std::uint32_t v = 1u << 31; i; i >>= 1, v ^= v >> 1) {
        if (i & 1u) r ^= v;
    }
    return r;
}

std::uint64_t mix(std::uint64_t z)
{
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    return z ^ (z >> 31);
}

class GeometryRayTracer final : public ShadingMethod::RayTracer {
public:
    GeometryRayTracer(const TracedScene& scene, const EffectsPlan& plan,
                      const EmbreeScene& embree, const CylinderSet& branches,
                      const CylinderSet& needles, const Instancing& instancing,
                      RenderStats& stats)
        : mScene(scene), mPlan(plan), mEmbree(embree), mBranches(branches), mNeedles(needles),
          mInstancing(instancing), mStats(stats), mShadows(plan.shadowRays || plan.selfShadowing)
    {
    }

    /// One point sample: the closest hit, shaded, as one opaque fragment (foliage if a needle).
    void trace(const ConeRay& ray, FrontToBack& composite) override;

private:
    bool occluded(const Vec3& x, const Vec3& towards, double distance, const RayContext& hit);
    // The cylinder hit, in world coordinates; `tree` the tree of an instance hit.
    Cylinder hitCylinder(const RayContext& hit, int& tree) const;

    const TracedScene& mScene;
    const EffectsPlan& mPlan;
    const EmbreeScene& mEmbree;
    const CylinderSet& mBranches;
    const CylinderSet& mNeedles;
    const Instancing& mInstancing;
    RenderStats& mStats;
    bool mShadows;
};

Cylinder GeometryRayTracer::hitCylinder(const RayContext& hit, int& tree) const
{
    if (hit.instID != RTC_INVALID_GEOMETRY_ID) {
        const Placed& at = mInstancing.byGeomID[hit.instID];
        Cylinder c = mInstancing.variants[at.variant].needles.cylinders[hit.primID];
        c.base += at.offset;
        tree = at.tree;
        return c;
    }
    return (hit.geomID == mNeedles.geomID ? mNeedles : mBranches).cylinders[hit.primID];
}

bool GeometryRayTracer::occluded(const Vec3& x, const Vec3& towards, double distance,
                                 const RayContext& hit)
{
    ++mStats.shadowRays;
    RayContext ctx;
    rtcInitIntersectContext(&ctx.embree);
    ctx.origin = x;
    ctx.direction = towards;
    ctx.tMin = 0.0;
    ctx.tMax = distance;
    // A convex cylinder never shadows its own lit side: skip it instead of offsetting x.
    ctx.skipGeom = hit.geomID;
    ctx.skipPrim = hit.primID;
    ctx.skipInst = hit.instID;
    RTCRay ray{};
    ray.org_x = float(x.x), ray.org_y = float(x.y), ray.org_z = float(x.z);
    ray.dir_x = float(towards.x), ray.dir_y = float(towards.y), ray.dir_z = float(towards.z);
    ray.tnear = 0.0f;
    ray.tfar = std::isfinite(distance) ? std::nextafter(float(distance), INFINITY) : INFINITY;
    ray.mask = ~0u;
    rtcOccluded1(mEmbree.scene(), &ctx.embree, &ray);
    return ray.tfar < 0.0f;
}

void GeometryRayTracer::trace(const ConeRay& ray, FrontToBack& composite)
{
    double tGround = kInf;
    Vec3 groundNormal(0.0);
    if (!hitGround(mScene.scene->ground, ray, tGround, groundNormal)) tGround = kInf;

    RayContext ctx;
    rtcInitIntersectContext(&ctx.embree);
    ctx.origin = ray.origin;
    ctx.direction = ray.direction;
    ctx.tMax = tGround;
    RTCRayHit rh{};
    rh.ray.org_x = float(ray.origin.x), rh.ray.org_y = float(ray.origin.y);
    rh.ray.org_z = float(ray.origin.z);
    rh.ray.dir_x = float(ray.direction.x), rh.ray.dir_y = float(ray.direction.y);
    rh.ray.dir_z = float(ray.direction.z);
    rh.ray.tnear = 0.0f;
    rh.ray.tfar = std::isfinite(tGround) ? std::nextafter(float(tGround), INFINITY) : INFINITY;
    rh.ray.mask = ~0u;
    rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    rtcIntersect1(mEmbree.scene(), &ctx.embree, &rh);
    const bool curve =
        ctx.geomID == RTC_INVALID_GEOMETRY_ID && rh.hit.geomID != RTC_INVALID_GEOMETRY_ID;
    if (curve) {
        ctx.geomID = rh.hit.geomID;
        ctx.primID = rh.hit.primID;
        ctx.instID = rh.hit.instID[0];
    }
    const bool cylinder = ctx.geomID != RTC_INVALID_GEOMETRY_ID;
    int tree = -1;  // an instance's; else the hit's own, below
    const Cylinder c = cylinder ? hitCylinder(ctx, tree) : Cylinder{};
    const bool instanced = cylinder && ctx.instID != RTC_INVALID_GEOMETRY_ID;
    const bool isNeedle = cylinder && (instanced || ctx.geomID == mNeedles.geomID);
    if (curve) {
        // A native curve's hit: where the double ray enters that cylinder, or where Embree
        // found it if the double ray only grazes it.
        double tIn, tOut;
        if (intersectCylinder(ray.origin, ray.direction, c, isNeedle && mScene.openNeedleEnds, tIn,
                              tOut, ctx.cap) &&
            tIn > 0.0) {
            ctx.t = tIn;
        } else {
            ctx.t = rh.ray.tfar;
            ctx.cap = false;
        }
    }
    if (!cylinder && !std::isfinite(tGround)) return;
    const double t = cylinder ? ctx.t : tGround;
    const Vec3 x = ray.origin + t * ray.direction, V = -ray.direction;

    // What the hit is and how it reflects.
    Vec3 N = groundNormal, albedo = mScene.scene->ground.albedo;
    double weight = 0.0, exponent = 1.0;
    if (cylinder) {
        N = cylinderNormal(c, x, ray.direction, ctx.cap);
        if (isNeedle) {
            // An instance's bough is its variant's first tree's: the same needles, elsewhere.
            const TracedBough& b = mScene.boughs[c.owner];
            if (!instanced) tree = b.tree;
            albedo = b.needleAlbedo;
            weight = b.specularWeight;
            exponent = b.exponent;
            ++mStats.needleHits;
        } else {
            albedo = mScene.barks[mScene.branches[c.owner].bark];
            tree = mScene.branches[c.owner].tree;
            ++mStats.branchHits;
        }
    } else {
        ++mStats.groundHits;
    }
    Fragment f{t, 1.0, Vec3(0.0), Vec3(0.0), 0, isNeedle, tree};
    const bool shadeSpecular = mPlan.specular && isNeedle;

    for (const Light& light : mScene.lights) {
        Vec3 L, E;
        double distance;
        light.at(x, L, distance, E);
        // The integrands of section 4: eq. (1)'s (N.L) 1(N.L > 0) and eq. (2)'s
        // (N.H)^n 1(N.H > 0), per unit of visible surface; the (N.V) weight of both is the
        // sampling itself (a pixel sample lands on the surface with density N.V).
        const double cosL = std::max(0.0, glm::dot(N, L));
        double lobe = 0.0;
        if (shadeSpecular) {
            const Vec3 h = L + V;
            const double len = glm::length(h);
            const double cosH = len > 0.0 ? std::max(0.0, glm::dot(N, h / len)) : 0.0;
            lobe = cosH > 0.0 ? std::pow(cosH, exponent) : 0.0;
        }
        const bool lit = (mPlan.diffuse && cosL > 0.0) || lobe > 0.0;
        if (lit && mShadows && occluded(x, L, distance, ctx)) {
            E = Vec3(0.0);
        }
        if (mPlan.diffuse) {
            f.diffuse += albedo / kPi * E * cosL;
            ++mStats.diffuseEvaluations;
        }
        if (shadeSpecular) {
            f.specular += weight * E * lobe;
            ++mStats.specularEvaluations;
        }
    }
    composite.add(f);
}

// Which trees are drawn as instances of their variant (scenes::TreePlacement::variantOf): with
// Embree's curves, those of every variant that has copies. Fills `instancing.variants` (their
// origins; needles laid out by layOut) and returns, per tree, its variant's index or -1.
std::vector<long long> variantsOf(const TracedScene& scene, NeedlePrimitive primitive,
                                  Instancing& instancing)
{
    const std::vector<scenes::TreePlacement>& trees = scene.scene->trees;
    std::vector<long long> variant(trees.size(), -1);
    // A scene built without its trees' counts (by hand, in tests) says nothing of variants.
    if (primitive != NeedlePrimitive::Curve || trees.size() != scene.treeCounts.size()) {
        return variant;
    }
    std::vector<long long> index(trees.size(), -1);  // of a first tree's variant
    for (std::size_t i = 0; i < trees.size(); ++i) {
        const long long first = trees[i].variantOf;
        if (first < 0) continue;
        auto& v = index[std::size_t(first)];
        if (v < 0) {
            v = static_cast<long long>(instancing.variants.size());
            instancing.variants.emplace_back();
            instancing.variants.back().origin = trees[std::size_t(first)].base_cm;
            instancing.variants.back().needles.openEnds = scene.openNeedleEnds;
            variant[std::size_t(first)] = v;
        }
        variant[i] = v;
    }
    for (long long v : variant) instancing.trees += v >= 0;
    return variant;
}

// Every needle of every bough (needle_layout.h) and every branch, as cylinders; the box pad
// covers the float rounding of rays within the scene's extent. The needles of an instanced
// tree (`variant` >= 0) go to its variant's set, once, from the variant's first tree.
void layOut(const TracedScene& scene, const std::vector<long long>& variant,
            Instancing& instancing, CylinderSet& branches, CylinderSet& needles)
{
    Aabb box;
    box.grow(scene.scene->camera.position_cm);
    for (const Light& l : scene.lights) {
        if (!l.directional) box.grow(l.position_cm);
    }
    branches.cylinders.reserve(scene.branches.size());
    for (std::size_t i = 0; i < scene.branches.size(); ++i) {
        const TracedBranch& br = scene.branches[i];
        const Vec3 d = br.tip_cm - br.base_cm;
        const double length = glm::length(d);
        if (!(length > 0.0)) continue;
        branches.cylinders.push_back({br.base_cm, glm::vec3(d / length), float(length),
                                      float(br.radius_cm), std::uint32_t(i)});
        box.grow(cylinderBounds(br.base_cm, br.tip_cm, br.radius_cm));
    }
    std::size_t count = 0;  // of the needles laid out one by one
    for (const TracedBough& b : scene.boughs) {
        if (b.tree >= 0 && variant[std::size_t(b.tree)] >= 0) continue;
        const NeedleLayout layout(b);
        count += std::size_t(layout.lastCone() + 1) * layout.needlesPerCone();
    }
    needles.cylinders.reserve(count);
    needles.openEnds = scene.openNeedleEnds;
    for (std::size_t k = 0; k < scene.boughs.size(); ++k) {
        const TracedBough& b = scene.boughs[k];
        const NeedleLayout layout(b);
        if (!(layout.length() > 0.0 && layout.radius() > 0.0)) continue;
        box.grow(cylinderBounds(b.base_cm, b.conesEnd(), b.radius_cm));
        const long long v = b.tree >= 0 ? variant[std::size_t(b.tree)] : -1;
        if (v >= 0 && scene.scene->trees[std::size_t(b.tree)].variantOf >= 0) continue;
        CylinderSet& set = v >= 0 ? instancing.variants[std::size_t(v)].needles : needles;
        layout.forEach([&](const Vec3& apex, const Vec3& dir) {
            set.cylinders.push_back({apex, glm::vec3(dir), float(layout.length()),
                                     float(layout.radius()), std::uint32_t(k)});
        });
    }
    // A float ray differs from the double one by ~6e-8 of its coordinates and of the distance
    // travelled, both bounded by the scene's extent: pad by 1e-6 of it, eight times that.
    const double pad = box.valid() ? 1e-6 * glm::length(box.hi - box.lo) + 1e-6 : 1e-6;
    branches.pad = needles.pad = pad;
}

// Embree's scene of every needle and branch, and the sample pattern.
class Geometry final : public ShadingMethod {
public:
    Geometry(const TracedScene& scene, const GeometryOptions& options)
        : mScene(scene), mPlan(EffectsPlan::from(scene.scene->effects)),
          mSamples(std::max(1, options.samples)), mSampleSeed(options.sampleSeed),
          mSampleWidth(1.0 / std::sqrt(double(mSamples)))
    {
        const std::vector<long long> variant = variantsOf(scene, options.primitive, mInstancing);
        layOut(scene, variant, mInstancing, mBranchSet, mNeedleSet);
        mEmbree.attach(mBranchSet, options.primitive);
        mEmbree.attach(mNeedleSet, options.primitive);
        std::vector<RTCScene> prototypes;
        for (const Variant& v : mInstancing.variants) {
            prototypes.push_back(mEmbree.prototype(v.needles, v.origin));
        }
        const std::vector<scenes::TreePlacement>& trees = scene.scene->trees;
        for (std::size_t i = 0; i < variant.size(); ++i) {
            if (variant[i] < 0) continue;
            const std::size_t v = std::size_t(variant[i]);
            const unsigned id = mEmbree.instance(prototypes[v], trees[i].base_cm);
            if (mInstancing.byGeomID.size() <= id) mInstancing.byGeomID.resize(id + 1);
            mInstancing.byGeomID[id] = {v, int(i), trees[i].base_cm - mInstancing.variants[v].origin};
        }
        mEmbree.commit();
    }

    GeometryBuild build(double seconds) const
    {
        GeometryBuild b;
        b.needles = mNeedleSet.cylinders.size();
        b.branches = mBranchSet.cylinders.size();
        b.seconds = seconds;
        b.primitiveBytes = (mNeedleSet.cylinders.capacity() + mBranchSet.cylinders.capacity()) *
                           sizeof(Cylinder);
        for (const Variant& v : mInstancing.variants) {
            b.variantNeedles += v.needles.cylinders.size();
            b.primitiveBytes += v.needles.cylinders.capacity() * sizeof(Cylinder);
        }
        b.variants = mInstancing.variants.size();
        b.instancedTrees = mInstancing.trees;
        b.embreePeakBytes = mEmbree.peakBytes();
        return b;
    }

    int samplesPerPixel() const override { return mSamples; }
    /// A sample is a point: its cone is as narrow as a sample's share of the pixel (only the
    /// ground test reads the ray, and only its axis).
    ConeRay sample(const ConeCamera& camera, int x, int y, int s) const override
    {
        const std::uint64_t key = mix((std::uint64_t(mSampleSeed) << 48) ^
                                      (std::uint64_t(std::uint32_t(y)) << 24) ^
                                      std::uint64_t(std::uint32_t(x)));
        const std::uint32_t shiftX = std::uint32_t(key), shiftY = std::uint32_t(key >> 32);
        const double u = double(sobol1(std::uint32_t(s)) ^ shiftX) * 0x1.0p-32;
        const double v = double(sobol2(std::uint32_t(s)) ^ shiftY) * 0x1.0p-32;
        return camera.coneAt(x + u, y + v, mSampleWidth);
    }
    std::unique_ptr<RayTracer> rayTracer(RenderStats& stats) const override
    {
        return std::make_unique<GeometryRayTracer>(mScene, mPlan, mEmbree, mBranchSet,
                                                   mNeedleSet, mInstancing, stats);
    }

private:
    const TracedScene& mScene;
    EffectsPlan mPlan;
    int mSamples;
    unsigned mSampleSeed;
    double mSampleWidth;
    CylinderSet mBranchSet, mNeedleSet;
    Instancing mInstancing;
    EmbreeScene mEmbree;
};

}  // namespace

RenderResult renderGeometry(const TracedScene& scene, const GeometryOptions& method,
                            const RenderOptions& options)
{
    using Clock = std::chrono::steady_clock;
    const auto start = Clock::now();
    const Geometry geometry(scene, method);
    const double buildSeconds = std::chrono::duration<double>(Clock::now() - start).count();
    if (method.built) method.built(geometry.build(buildSeconds));
    RenderResult result = renderImage(scene, geometry, options);
    result.seconds += buildSeconds;
    result.prepSeconds += buildSeconds;
    return result;
}

}  // namespace pine::vdbtrace
