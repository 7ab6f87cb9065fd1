// The exact bough law: section 6's quantities without the linear law, without the asymptotes
// and without one value for the whole strip. Chords through the bough's true cones, as the
// layer model stops them (layer by layer, each with its own opacity), give each half's
// opacity and each light's transfer as a function of the chord's offset from the axis: the
// expectation of what levels 1-2 render, over where the cones fall in a pixel (the footprint
// at level 3 is wider than the cone spacing). Precomputed once per bough and light.
//
// The chords of a cell run along the whole bough, ends included: a bough shorter than its
// cones reach (l cos(phi), 3.9 cm on the paper's) is thinner than a long one at every chord,
// and its needles spread beyond the tip, to the cones' end. The strip this law's profiles are
// drawn on runs from the base to the cones' end, and a cell's value is the integral over the
// chords' passages along the axis over that length, so that the strip covers what the needles
// cover; what oblique chords meet beyond its ends is put onto it, each cell kept a coverage.
#include "pine/vdbtrace/bough_law.h"
#include "pine/vdbtrace/cone_crossings.h"
#include "pine/vdbtrace/layer_model.h"
#include "pine/vdbtrace/traced_scene.h"

#include <glm/geometric.hpp>

#include <algorithm>
#include <cmath>

namespace pine::vdbtrace {
namespace {

// Cells across the strip and chords per cell, spread along the bough, so that each cell
// averages over where the cones fall. A chord's opacity is even in its offset (the mirror
// through the plane of the axis and the chord maps cones onto cones), so opacities are
// computed on half the cells; transfers are not even (the light is on one side).
constexpr int kCells = 12;
constexpr int kChords = 4;
// Below this transmittance a chord stops: nothing behind shows.
constexpr double kOpaque = 1e-4;

double cellCentre(int k) { return -1.0 + (k + 0.5) * 2.0 / kCells; }

// Chord p of cell k along d at signed offset xi along `across` (orthogonal to the axis and to
// d): it passes the axis closest at s along it, s spread evenly over every passage whose chord
// meets the layered cylinder (shifted by a different fraction per cell, so that the cells do
// not share where the cones fall). Its interval inside the cylinder, false if it misses it;
// `weight` is the share of the strip's length it stands for.
bool chord(const TracedBough& b, const Vec3& d, const Vec3& across, int k, int p, Vec3& o,
           double& tIn, double& tOut, double& weight)
{
    const double xi = cellCentre(k) * b.radius_cm;
    const double c = glm::dot(d, b.axis), s = std::sqrt(std::max(0.0, 1.0 - c * c));
    const double cotangent = s > 0.05 ? std::abs(c) / s : 20.0;
    const double reach = std::sqrt(std::max(0.0, b.radius_cm * b.radius_cm - xi * xi)) * cotangent;
    const double extent = glm::length(b.conesEnd_cm - b.base_cm) + 2.0 * reach;
    const double shift = std::fmod(0.5 + 0.6180339887498949 * k, 1.0);
    const double at = -reach + (p + shift) * extent / kChords;
    weight = extent / kChords / glm::length(b.conesEnd_cm - b.base_cm);
    const double far = extent + 25.0 * b.radius_cm;
    o = b.base_cm + at * b.axis + xi * across - far * d;
    return layeredInterval(b, o, d, tIn, tOut);
}

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
            if (!needs.transfer && k >= kCells / 2) continue;
            for (int p = 0; p < kChords; ++p) {
                Vec3 o;
                double tIn, tOut, weight;
                if (!chord(b, d, b.across, k, p, o, tIn, tOut, weight)) continue;
                const double tMid = 0.5 * (tIn + tOut);
                double T = 1.0;
                layers.layers(b, o, d, tIn, tOut, [&](const LayerHit& hit) {
                    if (T < kOpaque) return;
                    const double share = T * hit.opacity;  // what this layer shows
                    T *= 1.0 - hit.opacity;
                    const bool isFront = hit.t < tMid;
                    (isFront ? front : rear)[k] += share * weight;
                    if (!needs.transfer || share <= 0.0) return;
                    const Vec3 x = o + hit.t * d;
                    for (std::size_t i = 0; i < lights; ++i) {
                        const double lit =
                            share * layers.transmittance(b, x, towardsLights[i], hit.cone);
                        (isFront ? litFront : litRear)[i][k] += lit * weight;
                    }
                });
            }
        }
        for (int k = kCells / 2; k < kCells; ++k) {
            // The opacity from the mirrored cell whether or not the transfer was walked here,
            // so that the coverage is the same with self-shadowing or without.
            front[k] = front[kCells - 1 - k];
            rear[k] = rear[kCells - 1 - k];
        }
        for (int k = 0; k < kCells; ++k) {
            // Oblique chords beyond the strip's ends, put onto it, may add up past 1.
            const double total = front[k] + rear[k];
            if (total > 1.0) {
                for (std::size_t i = 0; i < lights; ++i) {
                    litFront[i][k] /= total;
                    litRear[i][k] /= total;
                }
                front[k] /= total;
                rear[k] /= total;
            }
        }
        out.alpha = {StripProfile::sampled(front), StripProfile::sampled(rear)};
        out.stripToConesEnd = true;
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
            for (int p = 0; p < kChords; ++p) {
                Vec3 o;
                double tIn, tOut, weight;
                if (!chord(b, d, across, k, p, o, tIn, tOut, weight)) continue;
                double T = 1.0;
                layers.layers(b, o, d, tIn, tOut, [&](const LayerHit& hit) {
                    T *= 1.0 - hit.opacity;
                });
                cells[k] += (1.0 - T) * weight;
            }
            cells[k] = std::min(cells[k], 1.0);
        }
        return StripProfile::sampled(cells);
    }
};

}  // namespace

std::unique_ptr<BoughLaw> makeExactBoughLaw() { return std::make_unique<ExactBoughLaw>(); }

}  // namespace pine::vdbtrace
