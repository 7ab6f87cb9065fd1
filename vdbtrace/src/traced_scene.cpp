#include "pine/vdbtrace/traced_scene.h"

#include "pine/analytic/cone_shader.h"
#include "pine/analytic/direction.h"
#include "pine/bake/resource_estimate.h"
#include "pine/bake/tree_boughs.h"
#include "pine/scenes/colours.h"
#include "pine/support/input_error.h"
#include "pine/support/registry.h"
#include "pine/vdbtrace/effects_plan.h"
#include "pine/vdbtrace/layer_model.h"
#include "pine/vdbtrace/light_columns.h"

#include <glm/geometric.hpp>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <deque>
#include <limits>
#include <map>
#include <memory>
#include <mutex>
#include <new>
#include <shared_mutex>
#include <stdexcept>
#include <utility>

namespace pine::vdbtrace {
namespace {

std::vector<Light> unifiedLights(const scenes::Scene& scene)
{
    std::vector<Light> lights;
    for (const auto& p : scene.pointLights) {
        Light l;
        l.position_cm = p.position_cm;
        l.power = p.colour * p.intensity;
        lights.push_back(l);
    }
    for (const auto& d : scene.directionalLights) {
        Light l;
        l.directional = true;
        l.towardsLight = glm::normalize(d.towardsLight);
        l.power = d.colour * d.irradiance;
        lights.push_back(l);
    }
    return lights;
}

}  // namespace

void Light::at(const Vec3& p, Vec3& direction, double& distance, Vec3& irradiance) const
{
    if (directional) {
        direction = towardsLight;
        distance = std::numeric_limits<double>::infinity();
        irradiance = power;
        return;
    }
    const Vec3 d = position_cm - p;
    distance = std::max(glm::length(d), 1e-9);
    direction = d / distance;
    irradiance = power / (distance * distance);
}

ConeRay Light::shadowCone(const Vec3& x, double footprint_cm, double& tMax) const
{
    ConeRay ray;
    if (directional) {
        constexpr double far = 1e7;  // cm
        ray.origin = x + far * towardsLight;
        ray.direction = -towardsLight;
        ray.spread = footprint_cm / far;
        tMax = far - 1e-3;
    } else {
        const Vec3 d = x - position_cm;
        const double distance = glm::length(d);
        ray.origin = position_cm;
        ray.direction = d / distance;
        ray.spread = footprint_cm / distance;
        tMax = distance - 1e-3;
    }
    return ray;
}

Vec3 stripAcross(const Vec3& axis, const Vec3& towards)
{
    const Vec3 c = glm::cross(axis, towards);
    const double n = glm::length(c);
    return n > 1e-9 ? c / n : analytic::anyPerpendicular(axis);
}

// The law profiles a scene's boughs keep (TracedBough::view and opacityFromLight), oldest
// first, within a budget: a landscape's 1.3 million views and 1.6 million profiles seen from
// the light would keep 1.3 GB, though each is read by the few neighbouring pixels (and their
// shadow cones) that meet its bough, which are rendered together. A bough points to its
// profiles weakly; the cache holds them, and whoever reads them.
class LawProfileCache {
public:
    explicit LawProfileCache(std::size_t budget_bytes) : mBudget(budget_bytes) {}
    enum Kind { kView, kFromLight };
    // A profile of `bytes` just computed: kept, and the oldest dropped while over the budget.
    void keep(std::shared_ptr<const void> profile, std::size_t bytes, Kind kind)
    {
        ++mCounts[kind].computed;
        mCounts[kind].bytes += bytes;
        const std::lock_guard<std::mutex> lock(mMutex);
        mKept.push_back({std::move(profile), bytes, kind});
        mBytes += bytes;
        mPeak = std::max(mPeak, mBytes);
        while (mBytes > mBudget && mKept.size() > 1) {
            mBytes -= mKept.front().bytes;
            ++mCounts[mKept.front().kind].dropped;
            mKept.pop_front();
        }
    }
    // Nothing is ever dropped: a profile once kept can be read without a lock.
    bool keepsAll() const { return mBudget == std::numeric_limits<std::size_t>::max(); }
    ProfileCounts counts(Kind kind) const
    {
        return {mCounts[kind].computed.load(), mCounts[kind].dropped.load(),
                mCounts[kind].bytes.load()};
    }
    std::size_t peakBytes() const
    {
        const std::lock_guard<std::mutex> lock(mMutex);
        return mPeak;
    }
    // Held shared while a bough's profile is read, alone while it is computed: one asked by
    // two threads at once is computed once.
    std::shared_mutex& guarding(const void* slot)
    {
        return mGuards[(reinterpret_cast<std::uintptr_t>(slot) / 64) % kGuards].mutex;
    }

private:
    struct Kept {
        std::shared_ptr<const void> profile;
        std::size_t bytes;
        Kind kind;
    };
    struct Counts {
        std::atomic<std::uint64_t> computed{0}, dropped{0}, bytes{0};
    };
    mutable std::mutex mMutex;
    std::deque<Kept> mKept;  ///< oldest first
    std::size_t mBytes = 0, mPeak = 0;
    const std::size_t mBudget;
    Counts mCounts[2];
    struct alignas(64) Guard {  // one a cache line: threads reading apart do not share one
        std::shared_mutex mutex;
    };
    static constexpr std::size_t kGuards = 256;
    Guard mGuards[kGuards];
};

// What every bough of a scene evaluates its law with: one, shared, for all of them.
struct BoughLawContext {
    explicit BoughLawContext(std::size_t profileBudget_bytes) : profiles(profileBudget_bytes) {}
    const BoughLaw* law = nullptr;
    const LayerModel* layers = nullptr;
    BoughLawNeeds needs;
    Vec3 eye_cm{0.0};
    std::vector<Light> lights;
    mutable LawProfileCache profiles;
};

// A bough's own: where its profiles are, while kept. The directions they are computed for
// are derived again from the bough and the context, not kept: a landscape has 3.3 million
// boughs, of which only those a cone or a shadow cone meets ever compute one.
struct BoughLawEvaluation {
    explicit BoughLawEvaluation(std::size_t lights)
        : moreLights(lights > 1 ? std::make_unique<Slot<StripProfile>[]>(lights - 1) : nullptr)
    {
    }
    // Where a profile is while the cache keeps it: read and set under
    // LawProfileCache::guarding(this); where the cache keeps all, also published once made.
    template <class T>
    struct Slot {
        std::weak_ptr<const T> weak;
        std::atomic<const T*> published{nullptr};
    };
    Slot<BoughView> view;
    Slot<StripProfile> firstLight;                 ///< from light 0
    std::unique_ptr<Slot<StripProfile>[]> moreLights;  ///< from lights 1, 2, ...
    Slot<StripProfile>& fromLight(std::size_t light)
    {
        return light ? moreLights[light - 1] : firstLight;
    }
};

// `slot`'s profile, or `compute()`'s kept in the cache as `kind`, `bytes(profile)` large.
template <class T, class Compute, class Bytes>
std::shared_ptr<const T> kept(BoughLawEvaluation::Slot<T>& slot, LawProfileCache& cache,
                              LawProfileCache::Kind kind, Compute&& compute, Bytes&& bytes)
{
    // Where the cache keeps all, it owns the profile as long as the scene: the pointer
    // returned owns nothing, and the read costs no lock (a forest's shadow cones read their
    // occluders' profiles millions of times).
    if (const T* published = slot.published.load(std::memory_order_acquire)) {
        return std::shared_ptr<const T>(std::shared_ptr<const T>(), published);
    }
    std::shared_mutex& guard = cache.guarding(&slot);
    {
        const std::shared_lock<std::shared_mutex> reading(guard);
        if (std::shared_ptr<const T> held = slot.weak.lock()) return held;
    }
    const std::lock_guard<std::shared_mutex> computing(guard);
    if (std::shared_ptr<const T> held = slot.weak.lock()) return held;
    // Only whole: a throw keeps nothing, to try again.
    auto made = std::make_shared<const T>(compute());
    slot.weak = made;
    cache.keep(made, bytes(*made), kind);
    if (cache.keepsAll()) slot.published.store(made.get(), std::memory_order_release);
    return made;
}

BoughLawSlot::BoughLawSlot(std::shared_ptr<const BoughLawContext> context)
    : mContext(std::move(context))
{
}

BoughLawSlot::BoughLawSlot(BoughLawSlot&& other) noexcept
    : mContext(std::move(other.mContext)), mEvaluation(other.mEvaluation.exchange(nullptr))
{
}

BoughLawSlot& BoughLawSlot::operator=(BoughLawSlot other) noexcept
{
    std::swap(mContext, other.mContext);
    BoughLawEvaluation* mine = mEvaluation.exchange(other.mEvaluation.load());
    other.mEvaluation.store(mine);
    return *this;
}

BoughLawSlot::~BoughLawSlot() { delete mEvaluation.load(); }

const BoughLawContext& BoughLawSlot::context() const
{
    if (!mContext) throw std::logic_error("a bough made without makeTracedBough has no law");
    return *mContext;
}

BoughLawEvaluation& BoughLawSlot::evaluation() const
{
    BoughLawEvaluation* e = mEvaluation.load(std::memory_order_acquire);
    if (e) return *e;
    auto made = std::make_unique<BoughLawEvaluation>(context().lights.size());
    if (mEvaluation.compare_exchange_strong(e, made.get(), std::memory_order_acq_rel)) {
        return *made.release();
    }
    return *e;  // another thread's, made meanwhile
}

LawProfileCounts lawProfileCounts(const TracedScene& scene)
{
    if (!scene.lawContext) return {};
    const LawProfileCache& cache = scene.lawContext->profiles;
    return {cache.counts(LawProfileCache::kView), cache.counts(LawProfileCache::kFromLight),
            cache.peakBytes()};
}

namespace {

// A bough's law sees the camera (V) and each light (L) from its centre.
Vec3 boughCentre(const TracedBough& b) { return 0.5 * (b.base_cm + b.tip_cm); }

Vec3 towardsLight(const Light& light, const Vec3& centre)
{
    Vec3 L, irradiance;
    double distance;
    light.at(centre, L, distance, irradiance);
    return L;
}

// A kept profile's shared pointer's count and its entry in the cache.
constexpr std::size_t kKeptOverhead_bytes = 64;

std::size_t heapBytes(const FrontRearProfile& p)
{
    return p.front.heapBytes() + p.rear.heapBytes();
}

// What a view holds, for the cache's budget.
std::size_t viewBytes(const BoughView& view)
{
    std::size_t bytes = kKeptOverhead_bytes + sizeof(BoughView) + heapBytes(view.alpha) +
                        view.lighting.capacity() * sizeof(BoughLighting);
    for (const BoughLighting& lit : view.lighting) {
        bytes += heapBytes(lit.transfer) + heapBytes(lit.diffuse) + heapBytes(lit.specular);
    }
    return bytes;
}

BoughView computeView(const TracedBough& b, const BoughLawContext& c)
{
    const Vec3 centre = boughCentre(b);
    const Vec3 V = glm::normalize(c.eye_cm - centre);
    std::vector<Vec3> towards;
    for (const Light& light : c.lights) towards.push_back(towardsLight(light, centre));
    BoughShading shading = c.law->shade(b, V, towards, *c.layers, c.needs);
    if (shading.lights.size() != towards.size()) {
        throw std::logic_error("a bough law shaded another number of lights");
    }
    BoughView view;
    view.alpha = std::move(shading.alpha);
    const analytic::ConeGeometry& cone = b.geometry.cone;
    view.lighting.reserve(towards.size());
    for (std::size_t i = 0; i < towards.size(); ++i) {
        BoughLighting lit;
        // A law that shades the needles does not read the faces' mean I^cyl.
        if (!b.shadesNeedles) {
            const auto sums = analytic::coneSums(
                cone, analytic::coneIntegrals(cone.aperture_rad, b.axis, towards[i], V, b.exponent),
                b.exponent);
            lit.front = analytic::meanReflectance(sums.front);
            lit.rear = analytic::meanReflectance(sums.rear);
        }
        // What the render's effects do not read is not kept (half a landscape's views).
        BoughLightTransfer& shaded = shading.lights[i];
        if (c.needs.transfer) lit.transfer = std::move(shaded.transfer);
        if (c.needs.diffuse) lit.diffuse = std::move(shaded.diffuse);
        if (c.needs.specular) lit.specular = std::move(shaded.specular);
        view.lighting.push_back(lit);
    }
    return view;
}

}  // namespace

std::shared_ptr<const BoughView> TracedBough::view() const
{
    const BoughLawContext& c = law.context();
    return kept(law.evaluation().view, c.profiles, LawProfileCache::kView,
                [&] { return computeView(*this, c); }, viewBytes);
}

std::shared_ptr<const StripProfile> TracedBough::opacityFromLight(std::size_t light) const
{
    const BoughLawContext& c = law.context();
    return kept(
        law.evaluation().fromLight(light), c.profiles, LawProfileCache::kFromLight,
        [&] {
            return c.law->opacityFromLight(
                *this, towardsLight(c.lights[light], boughCentre(*this)), *c.layers);
        },
        [](const StripProfile& p) { return kKeptOverhead_bytes + sizeof(p) + p.heapBytes(); });
}

namespace {

// Why the tracer cannot hold a grown tree placed by `place` (its points, scene coordinates),
// or empty: a point past kMaxCoordinate_cm (its primitives' bounds are floats), or a bough
// of more than kMaxConesPerBough cones.
template <class Place>
std::string whyUntraceable(const scenes::Tree& tree, const std::vector<bake::BoughSpec>& boughs,
                           const Place& place)
{
    char text[240];
    for (const scenes::Segment& s : tree.segments) {
        for (const Vec3& p : {place(s.base_cm), place(s.tip_cm)}) {
            const double far = std::max({std::abs(p.x), std::abs(p.y), std::abs(p.z)});
            if (!(far <= kMaxCoordinate_cm)) {
                std::snprintf(text, sizeof text,
                              "a branch reaches (%.3g, %.3g, %.3g) cm, more than %.0f cm from "
                              "the origin along an axis (its placement, height or species)",
                              p.x, p.y, p.z, kMaxCoordinate_cm);
                return text;
            }
        }
    }
    for (const bake::BoughSpec& b : boughs) {
        const double length = glm::length(b.tip_cm - b.base_cm);
        const double dh = b.needles.coneSpacing_cm;
        const double cones = length / dh;
        if (!(cones <= kMaxConesPerBough)) {
            std::snprintf(text, sizeof text,
                          "a bough %.4g cm long bears %s cones %.3g cm apart, more than %.0f (its "
                          "species' lsystem.segment, length_decay or cone_spacing, or the tree's "
                          "height)",
                          length, bake::formatCount(cones).c_str(), dh, kMaxConesPerBough);
            return text;
        }
    }
    return {};
}

// `evaluated`: the bough gets its law evaluation (else view() throws).
TracedBough makeTracedBough(const BoughDescription& d,
                            const std::shared_ptr<const BoughLawContext>& context, bool evaluated)
{
    const BoughLaw& law = *context->law;
    TracedBough b;
    b.base_cm = d.spec.base_cm;
    b.tip_cm = d.spec.tip_cm;
    b.length_cm = glm::length(b.tip_cm - b.base_cm);
    if (!(b.length_cm > 0.0)) throw std::invalid_argument("a bough of zero length");
    b.axis = (b.tip_cm - b.base_cm) / b.length_cm;
    b.geometry = d.spec.needles;
    const analytic::ConeGeometry& cone = b.geometry.cone;
    b.radius_cm = analytic::boughRadius(cone);
    b.layerOpacity = analytic::layerOpacity(cone);
    b.barkRadius_cm = std::clamp(d.barkRadius_cm, 0.0, b.radius_cm);
    b.conesReach_cm = cone.needleLength_cm * std::cos(cone.aperture_rad);
    b.needleAlbedo = d.spec.needleAlbedo;
    b.specularWeight = d.specularWeight;
    b.tree = d.tree;
    b.exponent = d.exponent;
    b.seed = d.seed;
    const BoughLawTraits traits = law.traits();
    b.rearComposite = traits.rear;
    b.stripToConesEnd = traits.stripToConesEnd;
    b.shadesNeedles = traits.shadesNeedles;

    b.across = stripAcross(b.axis, glm::normalize(context->eye_cm - boughCentre(b)));
    if (evaluated) b.law = BoughLawSlot(context);
    return b;
}

std::shared_ptr<const BoughLawContext> lawContext(const Vec3& eye_cm,
                                                  const std::vector<Light>& lights,
                                                  const BoughLaw& law, const LayerModel& layers,
                                                  const BoughLawNeeds& needs,
                                                  std::size_t profileBudget_bytes)
{
    auto c = std::make_shared<BoughLawContext>(profileBudget_bytes);
    c->law = &law;
    c->layers = &layers;
    c->needs = needs;
    c->eye_cm = eye_cm;
    c->lights = lights;
    return c;
}

}  // namespace

TracedBough makeTracedBough(const BoughDescription& d, const Vec3& eye_cm,
                            const std::vector<Light>& lights, const BoughLaw& law,
                            const LayerModel& layers, const BoughLawNeeds& needs)
{
    return makeTracedBough(
        d, lawContext(eye_cm, lights, law, layers, needs, std::numeric_limits<std::size_t>::max()),
        true);
}

void computeLawProfiles(const TracedScene& scene)
{
    tbb::parallel_for(std::size_t(0), scene.boughs.size(), [&](std::size_t k) {
        const TracedBough& b = scene.boughs[k];
        b.view();
        for (std::size_t i = 0; i < scene.lights.size(); ++i) b.opacityFromLight(i);
    });
}

namespace {

const Registry<const ShadowOrigin>& shadowOrigins()
{
    static const Registry<const ShadowOrigin> origins = [] {
        Registry<const ShadowOrigin> r("shadow origin");
        r.add("needles", std::make_unique<const ShadowOrigin>(ShadowOrigin::Needles));
        r.add("axis", std::make_unique<const ShadowOrigin>(ShadowOrigin::Axis));
        r.add("bough", std::make_unique<const ShadowOrigin>(ShadowOrigin::Bough));
        return r;
    }();
    return origins;
}

// render.bark: whether a bough's needles have their roots in a solid branch.
const Registry<const bool>& barks()
{
    static const Registry<const bool> solid = namedSwitch("bark", "solid", "line");
    return solid;
}

// render.needle_ends: whether the explicit needles' ends are open (the needle its side alone).
const Registry<const bool>& needleEnds()
{
    static const Registry<const bool> open = namedSwitch("needle ends", "open", "flat");
    return open;
}

// render.occluder_profile: whether a bough seen from a light is read where its cones reach.
const Registry<const bool>& occluderProfiles()
{
    static const Registry<const bool> cones = namedSwitch("occluder profile", "cones", "even");
    return cones;
}

}  // namespace

std::vector<std::string> shadowOriginNames() { return shadowOrigins().names(); }

std::vector<std::string> occluderProfileNames()
{
    return occluderProfiles().names();
}

std::vector<std::string> barkNames() { return barks().names(); }

std::vector<std::string> needleEndNames()
{
    return needleEnds().names();
}

PrimitiveCylinder primitiveCylinder(const TracedScene& scene, std::size_t primitive)
{
    if (scene.isBranch(primitive)) {
        const TracedBranch& b = scene.branches[primitive];
        return {b.base_cm, b.tip_cm, b.radius_cm};
    }
    const TracedBough& b = scene.bough(primitive);
    return {b.base_cm, b.conesEnd(), b.radius_cm + b.geometry.cone.needleRadius_cm};
}

Sphere primitiveBall(const TracedScene& scene, std::size_t primitive)
{
    const PrimitiveCylinder c = primitiveCylinder(scene, primitive);
    return cylinderSphere(c.base, c.end, c.radius_cm);
}

struct LightColumnsSet {
    LightColumnsSet(std::size_t lights, std::size_t indexed)
        : once(lights), columns(lights), primitives(indexed)
    {
    }
    std::vector<std::once_flag> once;
    std::vector<std::unique_ptr<LightColumns>> columns;
    std::size_t primitives;  ///< what the BVH indexed when the set was made
};

const LightColumns* TracedScene::columns(std::size_t light) const
{
    // Primitives or lights changed since indexPrimitives: none (the BVH is stale too).
    const std::size_t count = branches.size() + boughs.size();
    if (!lightColumns || light >= lightColumns->once.size() || light >= lights.size() ||
        !lights[light].directional || lightColumns->primitives != count) {
        return nullptr;
    }
    LightColumnsSet& set = *lightColumns;
    std::call_once(set.once[light], [&] {
        try {
            set.columns[light] = LightColumns::build(
                count,
                [&](std::size_t i) {
                    const PrimitiveCylinder c = primitiveCylinder(*this, i);
                    return LightColumns::Primitive{c.base, c.end, c.radius_cm};
                },
                bvh.queryOrder(), lights[light].towardsLight, bake::kShadowColumnsMax_bytes);
        } catch (const std::bad_alloc&) {
            set.columns[light].reset();  // the cones walk the BVH, to the same result
        }
    });
    return set.columns[light].get();
}

std::size_t lightColumnsBytes(const TracedScene& scene)
{
    std::size_t bytes = 0;
    if (!scene.lightColumns) return bytes;
    for (const auto& columns : scene.lightColumns->columns) bytes += columns ? columns->bytes() : 0;
    return bytes;
}

void indexPrimitives(TracedScene& scene)
{
    // Indices are 32 bits, the last of them the multiscale tracer's ground (kGround).
    if (scene.branches.size() + scene.boughs.size() >= (std::size_t(1) << 31)) {
        throw std::length_error("more than 2^31 branches and boughs to index");
    }
    const std::size_t count = scene.branches.size() + scene.boughs.size();
    scene.bvh = Bvh(count, [&](std::size_t i, Aabb& box, Sphere& ball) {
        const PrimitiveCylinder c = primitiveCylinder(scene, i);
        box = cylinderBounds(c.base, c.end, c.radius_cm);
        ball = cylinderSphere(c.base, c.end, c.radius_cm);
    });
    scene.lightColumns = std::make_shared<LightColumnsSet>(scene.lights.size(), count);
}

TracedScene buildTracedScene(const scenes::Scene& scene, const TracedSceneParts& parts)
{
    const scenes::ModelChoices& model = scene.render.model;
    const auto chosen = [&](const char* key, auto&& lookUp) -> decltype(auto) {
        try {
            return lookUp();
        } catch (const InputError& e) {
            throw InputError(scene.source.string() + ": render." + key + ": " + e.what());
        }
    };
    const std::shared_ptr<const BoughLaw> law =
        chosen("bough_law", [&] { return boughLaw(model.boughLaw).fresh(); });
    const bool correlated =
        chosen("layer_correlation", [&] { return layerCorrelated(model.layerCorrelation); });
    const LayerModel& layers = chosen("layer_model", [&]() -> const LayerModel& {
        return layerModel(model.layerModel, correlated);
    });
    const ShadowOrigin origin =
        chosen("shadow_origin", [&] { return shadowOrigins().get(model.shadowOrigin); });
    const bool solidBark = chosen("bark", [&] { return barks().get(model.bark); });
    const bool openNeedleEnds =
        chosen("needle_ends", [&] { return needleEnds().get(model.needleEnds); });
    const bool occludersByCones =
        chosen("occluder_profile", [&] { return occluderProfiles().get(model.occluderProfile); });
    const BoughLawNeeds needs = BoughLawNeeds::from(EffectsPlan::from(scene.effects));
    TracedScene out;
    out.scene = &scene;
    out.layers = &layers;
    out.boughLaw = law;
    out.shadowOrigin = origin;
    out.openNeedleEnds = openNeedleEnds;
    out.occludersByCones = occludersByCones;
    out.lights = unifiedLights(scene);
    out.trees.resize(scene.trees.size());
    // A scatter's variant is grown once, at its first tree. A copy's boughs and branches are
    // its first tree's moved to its base (scenes::movedBy's sums, so the same numbers); the
    // copy itself is made only where the grown trees are kept: a landscape's are about
    // 500 MB, all alive at once until its boughs are made.
    const auto firstOf = [&](std::size_t i) {
        const long long p = scene.trees[i].variantOf;
        return p < 0 ? i : std::size_t(p);
    };
    const auto offsetOf = [&](std::size_t i) {
        return scene.trees[i].base_cm - scene.trees[firstOf(i)].base_cm;
    };
    tbb::parallel_for(std::size_t(0), scene.trees.size(), [&](std::size_t i) {
        const scenes::TreePlacement& placement = scene.trees[i];
        if (placement.variantOf >= 0) return;
        out.trees[i] = scenes::growTree(scene.species.at(placement.species), placement);
    });
    if (parts.grownTrees) {
        tbb::parallel_for(std::size_t(0), scene.trees.size(), [&](std::size_t i) {
            const std::size_t first = firstOf(i);
            if (first != i) out.trees[i] = scenes::movedBy(out.trees[first], offsetOf(i));
        });
    }
    // The grown tree that tree i's boughs and branches are made from: its own, or its first
    // tree's, whose points placed(i) moves by offsetOf(i).
    const auto grown = [&](std::size_t i) -> const scenes::Tree& {
        return out.trees[parts.grownTrees ? i : firstOf(i)];
    };
    const auto placed = [&](std::size_t i) {
        const bool moved = &grown(i) != &out.trees[i];
        const Vec3 offset = moved ? offsetOf(i) : Vec3(0.0);
        return [moved, offset](const Vec3& p) { return moved ? p + offset : p; };
    };

    // Each tree's boughs described in parallel, then made in place, tree by tree, in the
    // trees' order (the primitive indices do not depend on the threads).
    std::vector<std::vector<BoughDescription>> described(out.trees.size());
    std::vector<std::string> untraceable(out.trees.size());  // per tree: why, or empty
    tbb::parallel_for(std::size_t(0), out.trees.size(), [&](std::size_t i) {
        const scenes::Tree& tree = grown(i);
        const auto place = placed(i);
        const scenes::Species& species = *tree.species;
        const std::vector<bake::BoughSpec> specs = bake::treeBoughs(tree);
        untraceable[i] = whyUntraceable(tree, specs, place);
        for (std::size_t j = 0; j < specs.size() && untraceable[i].empty(); ++j) {
            if (!(glm::length(specs[j].tip_cm - specs[j].base_cm) > 0.0)) continue;
            BoughDescription d;
            d.spec = specs[j];
            d.spec.base_cm = place(d.spec.base_cm);
            d.spec.tip_cm = place(d.spec.tip_cm);
            d.specularWeight = species.needleSpecular;
            d.exponent = species.specularExponent;
            // A variant's copies bear its first tree's needles (geometry instances them).
            d.seed = unsigned(firstOf(i) * 7919u + j * 104729u + scene.trees[i].seed);
            d.tree = int(i);
            d.segment = long(tree.boughs[j].segment);
            if (solidBark) d.barkRadius_cm = tree.segments[d.segment].radius_cm;
            described[i].push_back(d);
        }
    });
    // The first tree that cannot be traced, whichever thread found it.
    for (std::size_t i = 0; i < out.trees.size(); ++i) {
        if (!untraceable[i].empty()) {
            throw InputError(scene.source.string() + ": tree " + std::to_string(i) + ": " +
                             untraceable[i]);
        }
    }
    std::vector<std::size_t> firstBough(out.trees.size() + 1, 0);
    std::vector<std::size_t> firstBranch(out.trees.size() + 1, 0);
    for (std::size_t i = 0; i < out.trees.size(); ++i) {
        firstBough[i + 1] = firstBough[i] + described[i].size();
        firstBranch[i + 1] = firstBranch[i] + grown(i).segments.size();
    }
    out.branches.resize(firstBranch.back());
    out.boughs.resize(firstBough.back());
    // One bark albedo a species.
    std::vector<std::uint32_t> barkOf(out.trees.size());
    std::map<const scenes::Species*, std::uint32_t> barks;
    for (std::size_t i = 0; i < out.trees.size(); ++i) {
        const scenes::Species* species = grown(i).species;
        const auto [at, fresh] = barks.emplace(species, std::uint32_t(out.barks.size()));
        if (fresh) out.barks.push_back(scenes::barkColour(*species));
        barkOf[i] = at->second;
    }
    const auto context = lawContext(scene.camera.position_cm, out.lights, *law, layers, needs,
                                    parts.lawProfileBudget_bytes);
    if (parts.boughLaws) out.lawContext = context;
    tbb::parallel_for(std::size_t(0), out.trees.size(), [&](std::size_t i) {
        const scenes::Tree& tree = grown(i);
        const auto place = placed(i);
        for (std::size_t k = 0; k < tree.segments.size(); ++k) {
            const scenes::Segment& s = tree.segments[k];
            out.branches[firstBranch[i] + k] = {place(s.base_cm), place(s.tip_cm), s.radius_cm,
                                                barkOf[i], int(i)};
        }
        for (std::size_t k = 0; k < described[i].size(); ++k) {
            TracedBough& b = out.boughs[firstBough[i] + k];
            b = makeTracedBough(described[i][k], context, parts.boughLaws);
            if (described[i][k].segment >= 0) {
                b.branch = std::uint32_t(firstBranch[i] + std::size_t(described[i][k].segment));
            }
        }
        std::vector<BoughDescription>().swap(described[i]);
    });

    out.treeCounts.reserve(out.trees.size());
    for (std::size_t i = 0; i < out.trees.size(); ++i) {
        out.treeCounts.push_back(grown(i).counts());
    }
    if (!parts.grownTrees) std::vector<scenes::Tree>().swap(out.trees);
    if (parts.primitiveIndex) indexPrimitives(out);
    return out;
}

}  // namespace pine::vdbtrace
