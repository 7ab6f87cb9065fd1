#include "pine/vdbtrace/bough_shadows.h"

#include "pine/analytic/direction.h"
#include "pine/vdbtrace/bough_law.h"
#include "pine/vdbtrace/surface_shading.h"
#include "pine/vdbtrace/traced_scene.h"

#include <glm/geometric.hpp>

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace pine::vdbtrace {

namespace {

// Where a bough's needles lie in its cross-section: rings at the centres of kRings equal parts
// of [0, R] (needle length per area falls as 1/rho, so it is even in rho), kRingPoints each,
// every point read with a footprint of kPointWidth R. Twice as many points move the paper
// forest's per-tree luminance by under 0.5%.
constexpr int kRings = 3, kRingPoints = 8;
constexpr double kPointWidth = 0.25;

// Of a chord of the bough's cylinder along the section's unit direction `d` through the
// section point `o` (offset `across` from the axis on the strip that direction sees), how
// much lies in front of o, as a fraction of the chord: a point that far into the bough sees
// out through (1 - alpha)^fraction, alpha the chord's opacity.
double fractionInFront(const Vec3& o, const Vec3& d, double across, double R)
{
    const double h = std::sqrt(std::max(R * R - across * across, 1e-12));
    return std::clamp((h - glm::dot(o, d)) / (2.0 * h), 0.0, 1.0);
}

// Unit projection of `v` on the plane perpendicular to the unit `axis`, or zero.
Vec3 inSection(const Vec3& v, const Vec3& axis)
{
    const Vec3 p = v - glm::dot(v, axis) * axis;
    const double n = glm::length(p);
    return n > 1e-9 ? p / n : Vec3(0.0);
}

}  // namespace

BoughShadows::BoughShadows(const TracedScene& scene, bool selfShadowing)
    : mScene(scene), mSelfShadowing(selfShadowing)
{
    const std::size_t lights = scene.lights.size(), boughs = scene.boughs.size();
    mCount.resize(boughs);
    mFirst.resize(boughs * lights);
    std::size_t next = 0;
    for (std::size_t k = 0; k < boughs; ++k) {
        mCount[k] = std::uint8_t(samplesAlong(scene.boughs[k]));
        for (std::size_t i = 0; i < lights; ++i) {
            mFirst[k * lights + i] = std::uint32_t(next);
            next += mCount[k];
        }
    }
    if (next > std::size_t(UINT32_MAX)) throw std::length_error("too many bough shadow samples");
    mValues.assign(next, 1.0);
    mOnce = std::make_unique<std::once_flag[]>(boughs * lights);
}

int BoughShadows::samplesAlong(const TracedBough& b)
{
    const double length = glm::length(b.conesEnd() - b.base_cm);
    const double perDiameter = length / std::max(2.0 * b.radius_cm, 1e-9);
    return int(std::clamp(std::ceil(perDiameter), 1.0, double(kMaxSamples)));
}

void BoughShadows::fill(std::size_t bough, std::size_t light, RenderStats& stats) const
{
    const TracedBough& b = mScene.boughs[bough];
    const double R = b.radius_cm;
    const int count = mCount[bough];
    // The opacity of a chord of the bough seen from the camera, at offset xi on its strip.
    const std::shared_ptr<const BoughView> view = b.view();
    const FrontRearProfile& seen = view->alpha;
    const auto viewOpacity = [&](double xi) {
        return std::min(0.999, bothHalvesOpacity(seen, b.rearComposite, xi, R, kPointWidth * R));
    };
    double* out = &mValues[mFirst[bough * mScene.lights.size() + light]];
    ShadowSamples section;
    for (int k = 0; k < count; ++k) {
        const Vec3 x = b.base_cm + (k + 0.5) / count * (b.conesEnd() - b.base_cm);
        Vec3 L, irradiance;
        double distance;
        mScene.lights[light].at(x, L, distance, irradiance);
        // The section's frame: `across` perpendicular to the light, `up` in the plane of the
        // axis and the light; a point `u` up lies u lift nearer the light.
        const Vec3 across = stripAcross(b.axis, L);
        const Vec3 up = glm::cross(b.axis, across);
        const double lift = glm::dot(up, L);
        const Vec3 upAcrossLight = up - lift * L;
        const double upShown = glm::length(upAcrossLight);
        section.across = across;
        section.sideways = upShown > 1e-9 ? upAcrossLight / upShown : Vec3(0.0);
        section.points.clear();
        const Vec3 towardsEye = inSection(mScene.scene->camera.position_cm - x, b.axis);
        const Vec3 towardsLight = inSection(L, b.axis);
        for (int j = 0; j < kRings; ++j) {
            const double rho = (j + 0.5) / kRings * R;
            for (int m = 0; m < kRingPoints; ++m) {
                const double theta = 2.0 * analytic::kPi * (m + 0.5 * j) / kRingPoints;
                const double u = rho * std::cos(theta), v = rho * std::sin(theta);
                const Vec3 o = u * up + v * across;
                // The light a needle there reflects to the camera: seen through the bough's
                // layers in front of it and, with self-shadowing, lit through those towards
                // the light. The needles' shadows from the rest of the scene are averaged
                // with that weight, as the explicit needles' are: a needle lit through its
                // own bough also lies where the others' shadows fall less (correlated
                // occlusions, docs/models.md).
                const double xi = glm::dot(o, b.across);
                double weight = std::pow(1.0 - viewOpacity(xi),
                                         fractionInFront(o, towardsEye, xi, R));
                if (mSelfShadowing) {
                    const double alpha = std::min(
                        0.999, b.opacityFromLight(light)->overFootprint(v, R, kPointWidth * R));
                    weight *= std::pow(1.0 - alpha, fractionInFront(o, towardsLight, v, R));
                }
                section.points.push_back({v, weight, u * upShown, u * lift});
            }
        }
        out[k] = shadowConeTransmittance(mScene, x, light, kPointWidth * R,
                                         mScene.branches.size() + bough, true, &section);
        ++stats.shadowRays;
    }
}

double BoughShadows::transmittance(std::size_t primitive, std::size_t light, const Vec3& x,
                                   RenderStats& stats) const
{
    const std::size_t bough = primitive - mScene.branches.size();
    const std::size_t key = bough * mScene.lights.size() + light;
    std::call_once(mOnce[key], [&] { fill(bough, light, stats); });
    const TracedBough& b = mScene.boughs[bough];
    const Vec3 span = b.conesEnd() - b.base_cm;
    const int count = mCount[bough];
    // Where x lies between the samples, which stand at the centres of `count` equal parts.
    const double u = glm::dot(x - b.base_cm, span) / glm::dot(span, span) * count - 0.5;
    const double at = std::clamp(u, 0.0, double(count - 1));
    const int k = std::min(int(at), count - 1);
    const double* T = &mValues[mFirst[key]];
    if (k + 1 >= count) return T[k];
    const double f = at - k;
    return (1.0 - f) * T[k] + f * T[k + 1];
}

}  // namespace pine::vdbtrace
