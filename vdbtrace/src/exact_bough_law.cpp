// The exact bough law: section 6's quantities without the linear law, without the asymptotes
// and without one value for the whole strip. Chords through the bough's true cones, as the
// layer model stops them (layer by layer, each with its own opacity), give each half's
// opacity and each light's transfer as a function of the chord's offset from the axis: the
// expectation of what levels 1-2 render, over where the cones fall in a pixel (the footprint
// at level 3 is wider than the cone spacing). Precomputed once per bough and light.
#include "pine/vdbtrace/bough_law.h"
#include "pine/vdbtrace/layer_model.h"
#include "pine/vdbtrace/traced_scene.h"

#include <glm/geometric.hpp>

#include <algorithm>
#include <cmath>

namespace pine::vdbtrace {
namespace {

// Cells across the strip and chords per cell, at axial positions dh / kPhases apart, so that
// each cell averages over where the cones fall. A chord's opacity is even in its offset (the
// mirror through the plane of the axis and the chord maps cones onto cones), so opacities are
// computed on half the cells; transfers are not even (the light is on one side).
constexpr int kCells = 12;
constexpr int kPhases = 2;
// Below this transmittance a chord stops: nothing behind shows.
constexpr double kOpaque = 1e-4;

// The chord along d through the bough at signed offset xi along `across`, phase p: its
// interval inside the layered cylinder, false if it misses it.
bool chord(const TracedBough& b, const Vec3& d, const Vec3& across, double xi, int p, Vec3& o,
           double& tIn, double& tOut)
{
    const double h = 0.5 * b.length_cm + b.geometry.coneSpacing_cm * (double(p) / kPhases);
    const double far = b.length_cm + 4.0 * b.radius_cm;
    o = b.base_cm + h * b.axis + xi * across - far * d;
    return intersectCylinder(ConeRay{o, d, 0.0}, b.base_cm, b.conesEnd_cm, b.radius_cm, tIn, tOut);
}

double cellCentre(int k) { return -1.0 + (k + 0.5) * 2.0 / kCells; }

class ExactBoughLaw final : public BoughLaw {
public:
    BoughShading shade(const TracedBough& b, const Vec3& V,
                       const std::vector<Vec3>& towardsLights, const LayerModel& layers,
                       const BoughLawNeeds& needs) const override
    {
        BoughShading out;
        out.rear = RearComposite::Share;
        const Vec3 d = -V;
        const std::size_t lights = towardsLights.size();
        std::vector<double> front(kCells, 0.0), rear(kCells, 0.0);
        std::vector<std::vector<double>> litFront(lights, front), litRear(lights, front);
        for (int k = 0; k < kCells; ++k) {
            if (!needs.transfer && k >= kCells / 2) {
                front[k] = front[kCells - 1 - k];
                rear[k] = rear[kCells - 1 - k];
                continue;
            }
            for (int p = 0; p < kPhases; ++p) {
                Vec3 o;
                double tIn, tOut;
                if (!chord(b, d, b.across, cellCentre(k) * b.radius_cm, p, o, tIn, tOut)) continue;
                const double tMid = 0.5 * (tIn + tOut);
                double T = 1.0;
                layers.layers(b, o, d, tIn, tOut, [&](const LayerHit& hit) {
                    if (T < kOpaque) return;
                    const double share = T * hit.opacity;  // what this layer shows
                    T *= 1.0 - hit.opacity;
                    const bool isFront = hit.t < tMid;
                    (isFront ? front : rear)[k] += share / kPhases;
                    if (!needs.transfer || share <= 0.0) return;
                    const Vec3 x = o + hit.t * d;
                    for (std::size_t i = 0; i < lights; ++i) {
                        const double lit =
                            share * layers.transmittance(b, x, towardsLights[i], hit.cone);
                        (isFront ? litFront : litRear)[i][k] += lit / kPhases;
                    }
                });
            }
        }
        out.alpha = {StripProfile::sampled(front), StripProfile::sampled(rear)};
        for (std::size_t i = 0; i < lights; ++i) {
            BoughLightTransfer light;
            light.transfer = needs.transfer ? FrontRearProfile{StripProfile::sampled(litFront[i]),
                                                               StripProfile::sampled(litRear[i])}
                                            : out.alpha;
            if (needs.shadowOpacity) {
                light.opacityFromLight = opacityAlong(b, -towardsLights[i], layers);
            }
            out.lights.push_back(light);
        }
        return out;
    }

private:
    // The whole bough's opacity for chords along d, across their strip.
    static StripProfile opacityAlong(const TracedBough& b, const Vec3& d, const LayerModel& layers)
    {
        const Vec3 across = stripAcross(b.axis, -d);
        std::vector<double> cells(kCells, 0.0);
        for (int k = 0; k < kCells; ++k) {
            if (k >= kCells / 2) {
                cells[k] = cells[kCells - 1 - k];
                continue;
            }
            for (int p = 0; p < kPhases; ++p) {
                Vec3 o;
                double tIn, tOut;
                if (!chord(b, d, across, cellCentre(k) * b.radius_cm, p, o, tIn, tOut)) continue;
                double T = 1.0;
                layers.layers(b, o, d, tIn, tOut, [&](const LayerHit& hit) {
                    T *= 1.0 - hit.opacity;
                });
                cells[k] += (1.0 - T) / kPhases;
            }
        }
        return StripProfile::sampled(cells);
    }
};

}  // namespace

std::unique_ptr<BoughLaw> makeExactBoughLaw() { return std::make_unique<ExactBoughLaw>(); }

}  // namespace pine::vdbtrace
