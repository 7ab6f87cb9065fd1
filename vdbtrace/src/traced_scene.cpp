#include "pine/vdbtrace/traced_scene.h"

#include "pine/analytic/cone_shader.h"

#include <glm/geometric.hpp>
#include <tbb/parallel_for.h>

#include <cmath>
#include <limits>

namespace pine::vdbtrace {
namespace {

// Needle and bark colours: the species gives a scalar albedo; the hue is fixed here.
const Vec3 kNeedleHue{0.45, 1.0, 0.35};
const Vec3 kBarkHue{1.0, 0.75, 0.55};

Vec3 hued(const Vec3& hue, double albedo) { return hue * (albedo / hue.y); }

analytic::BoughGeometry boughGeometry(const scenes::NeedleParameters& p)
{
    analytic::BoughGeometry g;
    g.cone.aperture_rad = p.aperture_rad;
    g.cone.needleLength_cm = p.length_cm;
    g.cone.needleRadius_cm = p.radius_cm;
    g.cone.needlesPerCone = p.perCone;
    g.coneSpacing_cm = p.coneSpacing_cm;
    return g;
}

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

TracedScene buildTracedScene(const scenes::Scene& scene)
{
    TracedScene out;
    out.scene = &scene;
    out.lights = unifiedLights(scene);
    out.trees.resize(scene.trees.size());
    tbb::parallel_for(std::size_t(0), scene.trees.size(), [&](std::size_t i) {
        const scenes::TreePlacement& placement = scene.trees[i];
        out.trees[i] = scenes::growTree(scene.species.at(placement.species), placement);
    });

    for (std::size_t i = 0; i < out.trees.size(); ++i) {
        const scenes::Tree& tree = out.trees[i];
        const scenes::Species& species = *tree.species;
        for (const scenes::Segment& s : tree.segments) {
            out.branches.push_back(
                {s.base_cm, s.tip_cm, s.radius_cm, hued(kBarkHue, species.barkAlbedo)});
        }
        for (std::size_t j = 0; j < tree.boughs.size(); ++j) {
            const scenes::Bough& b = tree.boughs[j];
            const scenes::Segment& s = tree.segments[b.segment];
            TracedBough tb;
            tb.base_cm = s.base_cm;
            tb.tip_cm = s.tip_cm;
            tb.length_cm = glm::length(s.tip_cm - s.base_cm);
            if (!(tb.length_cm > 0.0)) continue;
            tb.axis = (s.tip_cm - s.base_cm) / tb.length_cm;
            tb.geometry = boughGeometry(scenes::lerp(b.atBase, b.atTip, 0.5));
            tb.radius_cm = analytic::boughRadius(tb.geometry.cone);
            tb.layerOpacity = analytic::layerOpacity(tb.geometry.cone);
            tb.conesEnd_cm = tb.tip_cm + tb.geometry.cone.needleLength_cm *
                                             std::cos(tb.geometry.cone.aperture_rad) * tb.axis;
            tb.needleAlbedo = hued(kNeedleHue, species.needleAlbedo);
            tb.specularWeight = species.needleSpecular;
            tb.exponent = species.specularExponent;
            tb.seed = unsigned(i * 7919u + j * 104729u + scene.trees[i].seed);
            out.boughs.push_back(tb);
        }
    }

    // Directions from each bough's centre: to the camera (V) and to each light (L).
    const Vec3 eye = scene.camera.position_cm;
    tbb::parallel_for(std::size_t(0), out.boughs.size(), [&](std::size_t k) {
        TracedBough& b = out.boughs[k];
        const Vec3 centre = 0.5 * (b.base_cm + b.tip_cm);
        const Vec3 V = glm::normalize(eye - centre);
        const double phiAperture = b.geometry.cone.aperture_rad;
        b.alpha =
            analytic::boughLinearLaw(b.geometry, analytic::boughView(phiAperture, b.axis, V, V))
                .alphaView;
        for (const Light& light : out.lights) {
            Vec3 L, irradiance;
            double distance;
            light.at(centre, L, distance, irradiance);
            BoughLighting lit;
            const double phi = b.geometry.cone.aperture_rad;
            const auto sums = analytic::coneSums(
                b.geometry.cone, analytic::coneIntegrals(phi, b.axis, L, V, b.exponent),
                b.exponent);
            lit.front = analytic::meanReflectance(sums.front);
            lit.rear = analytic::meanReflectance(sums.rear);
            lit.view = analytic::boughView(phi, b.axis, L, V);
            lit.law = analytic::boughLinearLaw(b.geometry, lit.view);
            const auto fromLight =
                analytic::boughLinearLaw(b.geometry, analytic::boughView(phi, b.axis, L, L));
            lit.opacityFromLight = fromLight.alphaView.front + fromLight.alphaView.rear;
            b.lighting.push_back(lit);
        }
    });

    std::vector<Aabb> boxes;
    boxes.reserve(out.branches.size() + out.boughs.size());
    for (const TracedBranch& b : out.branches) {
        boxes.push_back(cylinderBounds(b.base_cm, b.tip_cm, b.radius_cm));
    }
    for (const TracedBough& b : out.boughs) {
        boxes.push_back(cylinderBounds(b.base_cm, b.conesEnd_cm, b.radius_cm));
    }
    out.bvh = Bvh(boxes);
    return out;
}

}  // namespace pine::vdbtrace
