#include "pine/vdbtrace/traced_scene.h"

#include "pine/analytic/cone_shader.h"
#include "pine/analytic/direction.h"
#include "pine/bake/tree_boughs.h"
#include "pine/scenes/colours.h"
#include "pine/support/input_error.h"
#include "pine/support/registry.h"
#include "pine/vdbtrace/effects_plan.h"
#include "pine/vdbtrace/layer_model.h"

#include <glm/geometric.hpp>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <mutex>
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

// What every bough of a scene evaluates its law with: one, shared, for all of them.
struct BoughLawContext {
    const BoughLaw* law = nullptr;
    const LayerModel* layers = nullptr;
    BoughLawNeeds needs;
    Vec3 eye_cm{0.0};
    std::vector<Light> lights;
};

// A bough's own: its profiles once computed. The directions they are computed for are derived
// again from the bough and the context, not kept: a landscape has 3.3 million boughs, of which
// only those a cone meets at level 3 ever compute a view.
struct BoughLawEvaluation {
    std::shared_ptr<const BoughLawContext> context;
    std::once_flag viewOnce;
    std::unique_ptr<const BoughView> view;
    struct FromLight {
        std::once_flag once;
        StripProfile profile;
    };
    std::unique_ptr<FromLight[]> fromLight;  ///< one per light
};

namespace {

// A bough not made by makeTracedBough has no law to ask.
BoughLawEvaluation& evaluation(const std::shared_ptr<BoughLawEvaluation>& law)
{
    if (!law) throw std::logic_error("a bough made without makeTracedBough has no law");
    return *law;
}

// A bough's law sees the camera (V) and each light (L) from its centre.
Vec3 boughCentre(const TracedBough& b) { return 0.5 * (b.base_cm + b.tip_cm); }

Vec3 towardsLight(const Light& light, const Vec3& centre)
{
    Vec3 L, irradiance;
    double distance;
    light.at(centre, L, distance, irradiance);
    return L;
}

}  // namespace

const BoughView& TracedBough::view() const
{
    BoughLawEvaluation& e = evaluation(law);
    std::call_once(e.viewOnce, [&] {
        const BoughLawContext& c = *e.context;
        const Vec3 centre = boughCentre(*this);
        const Vec3 V = glm::normalize(c.eye_cm - centre);
        std::vector<Vec3> towards;
        for (const Light& light : c.lights) towards.push_back(towardsLight(light, centre));
        BoughShading shading = c.law->shade(*this, V, towards, *c.layers, c.needs);
        if (shading.lights.size() != towards.size()) {
            throw std::logic_error("a bough law shaded another number of lights");
        }
        auto view = std::make_unique<BoughView>();
        view->alpha = std::move(shading.alpha);
        const analytic::ConeGeometry& cone = geometry.cone;
        for (std::size_t i = 0; i < towards.size(); ++i) {
            BoughLighting lit;
            // A law that shades the needles does not read the faces' mean I^cyl.
            if (!shadesNeedles) {
                const auto sums = analytic::coneSums(
                    cone,
                    analytic::coneIntegrals(cone.aperture_rad, axis, towards[i], V, exponent),
                    exponent);
                lit.front = analytic::meanReflectance(sums.front);
                lit.rear = analytic::meanReflectance(sums.rear);
            }
            // What the render's effects do not read is not kept (half a landscape's views).
            BoughLightTransfer& shaded = shading.lights[i];
            if (c.needs.transfer) lit.transfer = std::move(shaded.transfer);
            if (c.needs.diffuse) lit.diffuse = std::move(shaded.diffuse);
            if (c.needs.specular) lit.specular = std::move(shaded.specular);
            view->lighting.push_back(lit);
        }
        e.view = std::move(view);  // only whole: a throw leaves the flag unset to try again
    });
    return *e.view;
}

const StripProfile& TracedBough::opacityFromLight(std::size_t light) const
{
    BoughLawEvaluation& e = evaluation(law);
    BoughLawEvaluation::FromLight& slot = e.fromLight[light];
    std::call_once(slot.once, [&] {
        const BoughLawContext& c = *e.context;
        slot.profile = c.law->opacityFromLight(
            *this, towardsLight(c.lights[light], boughCentre(*this)), *c.layers);
    });
    return slot.profile;
}

namespace {

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
    b.conesEnd_cm = b.tip_cm + cone.needleLength_cm * std::cos(cone.aperture_rad) * b.axis;
    b.needleAlbedo = d.spec.needleAlbedo;
    b.specularWeight = d.specularWeight;
    b.tree = d.tree;
    b.exponent = d.exponent;
    b.seed = d.seed;
    const BoughLawTraits traits = law.traits();
    b.rearComposite = traits.rear;
    b.stripEnd_cm = traits.stripToConesEnd ? b.conesEnd_cm : b.tip_cm;
    b.shadesNeedles = traits.shadesNeedles;

    b.across = stripAcross(b.axis, glm::normalize(context->eye_cm - boughCentre(b)));
    if (evaluated) {
        auto e = std::make_shared<BoughLawEvaluation>();
        e->context = context;
        e->fromLight = std::make_unique<BoughLawEvaluation::FromLight[]>(context->lights.size());
        b.law = std::move(e);
    }
    return b;
}

std::shared_ptr<const BoughLawContext> lawContext(const Vec3& eye_cm,
                                                  const std::vector<Light>& lights,
                                                  const BoughLaw& law, const LayerModel& layers,
                                                  const BoughLawNeeds& needs)
{
    auto c = std::make_shared<BoughLawContext>();
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
    return makeTracedBough(d, lawContext(eye_cm, lights, law, layers, needs), true);
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

}  // namespace

std::vector<std::string> shadowOriginNames() { return shadowOrigins().names(); }

std::vector<std::string> barkNames() { return barks().names(); }

PrimitiveCylinder primitiveCylinder(const TracedScene& scene, std::size_t primitive)
{
    if (scene.isBranch(primitive)) {
        const TracedBranch& b = scene.branches[primitive];
        return {b.base_cm, b.tip_cm, b.radius_cm};
    }
    const TracedBough& b = scene.bough(primitive);
    return {b.base_cm, b.conesEnd_cm, b.radius_cm + b.geometry.cone.needleRadius_cm};
}

Sphere primitiveBall(const TracedScene& scene, std::size_t primitive)
{
    const PrimitiveCylinder c = primitiveCylinder(scene, primitive);
    return cylinderSphere(c.base, c.end, c.radius_cm);
}

void indexPrimitives(TracedScene& scene)
{
    // The multiscale tracer flags a primitive's index with the top bit of 32 (kAtEntry).
    if (scene.branches.size() + scene.boughs.size() >= (std::size_t(1) << 31)) {
        throw std::length_error("more than 2^31 branches and boughs to index");
    }
    const std::size_t count = scene.branches.size() + scene.boughs.size();
    scene.bvh = Bvh(count, [&](std::size_t i, Aabb& box, Sphere& ball) {
        const PrimitiveCylinder c = primitiveCylinder(scene, i);
        box = cylinderBounds(c.base, c.end, c.radius_cm);
        ball = cylinderSphere(c.base, c.end, c.radius_cm);
    });
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
    const BoughLawNeeds needs = BoughLawNeeds::from(EffectsPlan::from(scene.effects));
    TracedScene out;
    out.scene = &scene;
    out.layers = &layers;
    out.boughLaw = law;
    out.shadowOrigin = origin;
    out.lights = unifiedLights(scene);
    out.trees.resize(scene.trees.size());
    // A scatter's variant is grown once, at its first tree, and moved to the others' bases.
    tbb::parallel_for(std::size_t(0), scene.trees.size(), [&](std::size_t i) {
        const scenes::TreePlacement& placement = scene.trees[i];
        if (placement.variantOf >= 0) return;
        out.trees[i] = scenes::growTree(scene.species.at(placement.species), placement);
    });
    tbb::parallel_for(std::size_t(0), scene.trees.size(), [&](std::size_t i) {
        const long long p = scene.trees[i].variantOf;
        if (p < 0) return;
        out.trees[i] = scenes::movedBy(out.trees[std::size_t(p)],
                                       scene.trees[i].base_cm - scene.trees[std::size_t(p)].base_cm);
    });

    // Each tree's boughs described in parallel, then made in place, tree by tree, in the
    // trees' order (the primitive indices do not depend on the threads).
    std::vector<std::vector<BoughDescription>> described(out.trees.size());
    tbb::parallel_for(std::size_t(0), out.trees.size(), [&](std::size_t i) {
        const scenes::Tree& tree = out.trees[i];
        const scenes::Species& species = *tree.species;
        const std::vector<bake::BoughSpec> specs = bake::treeBoughs(tree);
        for (std::size_t j = 0; j < specs.size(); ++j) {
            if (!(glm::length(specs[j].tip_cm - specs[j].base_cm) > 0.0)) continue;
            BoughDescription d;
            d.spec = specs[j];
            d.specularWeight = species.needleSpecular;
            d.exponent = species.specularExponent;
            // A variant's copies bear its first tree's needles (geometry instances them).
            const long long variantOf = scene.trees[i].variantOf;
            const std::size_t first = variantOf < 0 ? i : std::size_t(variantOf);
            d.seed = unsigned(first * 7919u + j * 104729u + scene.trees[i].seed);
            d.tree = int(i);
            if (solidBark) d.barkRadius_cm = tree.segments[tree.boughs[j].segment].radius_cm;
            described[i].push_back(d);
        }
    });
    std::vector<std::size_t> firstBough(out.trees.size() + 1, 0);
    std::vector<std::size_t> firstBranch(out.trees.size() + 1, 0);
    for (std::size_t i = 0; i < out.trees.size(); ++i) {
        firstBough[i + 1] = firstBough[i] + described[i].size();
        firstBranch[i + 1] = firstBranch[i] + out.trees[i].segments.size();
    }
    out.branches.resize(firstBranch.back());
    out.boughs.resize(firstBough.back());
    const auto context = lawContext(scene.camera.position_cm, out.lights, *law, layers, needs);
    tbb::parallel_for(std::size_t(0), out.trees.size(), [&](std::size_t i) {
        const scenes::Tree& tree = out.trees[i];
        const Vec3 bark = scenes::barkColour(*tree.species);
        for (std::size_t k = 0; k < tree.segments.size(); ++k) {
            const scenes::Segment& s = tree.segments[k];
            out.branches[firstBranch[i] + k] = {s.base_cm, s.tip_cm, s.radius_cm, bark, int(i)};
        }
        for (std::size_t k = 0; k < described[i].size(); ++k) {
            TracedBough& b = out.boughs[firstBough[i] + k];
            b = makeTracedBough(described[i][k], context, parts.boughLaws);
        }
        std::vector<BoughDescription>().swap(described[i]);
    });

    out.treeCounts.reserve(out.trees.size());
    for (const scenes::Tree& tree : out.trees) out.treeCounts.push_back(tree.counts());
    if (!parts.grownTrees) std::vector<scenes::Tree>().swap(out.trees);
    if (parts.primitiveIndex) indexPrimitives(out);
    return out;
}

}  // namespace pine::vdbtrace
