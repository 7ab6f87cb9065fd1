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
#include "exact_bough_law.h"

#include "pine/vdbtrace/bough_law.h"

#include "pine/analytic/needle_shader.h"
#include "pine/vdbtrace/cone_crossings.h"
#include "pine/vdbtrace/layer_model.h"
#include "pine/vdbtrace/traced_scene.h"

#include <glm/geometric.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <stdexcept>

namespace pine::vdbtrace {
namespace {

// Cells across the strip and chords per cell, spread along the bough, so that each cell
// averages over where the cones fall. A chord's opacity is even in its offset (the mirror
// through the plane of the axis and the chord maps cones onto cones), so opacities are
// computed on half the cells; transfers are not even (the light is on one side).
constexpr int kCells = kExactLawCells;
// A chord's layers, each lit through the bough: the shading's chords cost a walk towards each
// light per layer and are fewer; the opacity from a light, whose deep shadows show its every
// cell, takes more.
struct Chords {
    int count, atEachEnd;  ///< per cell; of them at each end of a bough with an interior
};
constexpr Chords kShadingChords{6, 2}, kOpacityChords{10, 3};
// Below this transmittance a chord stops: nothing behind shows.
constexpr double kOpaque = 1e-4;

double cellCentre(int k) { return -1.0 + (k + 0.5) * 2.0 / kCells; }

// Chord p of cell k along d at signed offset xi along `across` (orthogonal to the axis and to
// d): it passes the axis closest at `at` along it. Its interval inside the cylinder, false if
// it misses it; `weight` is the share of the strip's length it stands for.
//
// The passages that meet the layered cylinder run from -reach to the cones' end + reach. Near
// each end (within the cones' reach l cos(phi) and the chord's own reach) a chord meets fewer
// cones; between them, on a long bough, its layers repeat with the cone spacing dh. So each
// end gets kEndChords chords spread evenly over it, and the interior the rest, stratified over
// the phase of one cone spacing at its middle, each weighted by the length it stands for: four
// chords spread evenly over a 200 cm bough put a quarter of a cell's weight wherever the
// last one fell, an end or an arbitrary phase (a cell 10% off the needles). A bough too short
// for an interior spreads all its chords evenly. Each cell's chords are shifted by a
// different fraction, so that the cells do not share where the cones fall.
bool chord(const TracedBough& b, const Vec3& d, const Vec3& across, int k, int p,
           const Chords& chords, Vec3& o, double& tIn, double& tOut, double& weight)
{
    const int kChords = chords.count, kEndChords = chords.atEachEnd;
    const double xi = cellCentre(k) * b.radius_cm;
    const double c = glm::dot(d, b.axis), s = std::sqrt(std::max(0.0, 1.0 - c * c));
    const double cotangent = s > 0.05 ? std::abs(c) / s : 20.0;
    const double reach = std::sqrt(std::max(0.0, b.radius_cm * b.radius_cm - xi * xi)) * cotangent;
    const double cones = glm::length(b.conesEnd() - b.base_cm);
    const double apexes = glm::length(b.tip_cm - b.base_cm);
    const double dh = b.geometry.coneSpacing_cm;
    const double shift = std::fmod(0.5 + 0.6180339887498949 * k, 1.0);
    const double first = -reach, last = cones + reach;
    const double interiorFrom = (cones - apexes) + reach, interiorTo = apexes - reach;
    double at, length;
    if (interiorTo - interiorFrom < 2.0 * dh) {
        length = (last - first) / kChords;
        at = first + (p + shift) * length;
    } else if (p < 2 * kEndChords) {
        const bool base = p < kEndChords;
        const double from = base ? first : interiorTo, to = base ? interiorFrom : last;
        length = (to - from) / kEndChords;
        at = from + (p % kEndChords + shift) * length;
    } else {
        const int interior = kChords - 2 * kEndChords;
        length = (interiorTo - interiorFrom) / interior;
        const double middle = 0.5 * (interiorFrom + interiorTo);
        at = middle + dh * ((p - 2 * kEndChords + shift) / interior - 0.5);
    }
    weight = length / cones;
    const double far = last - first + 25.0 * b.radius_cm;
    o = b.base_cm + at * b.axis + xi * across - far * d;
    return layeredInterval(b, o, d, tIn, tOut);
}

class ExactBoughLaw final : public BoughLaw {
public:
    explicit ExactBoughLaw(int density)
        : mShadingChords{kShadingChords.count * density, kShadingChords.atEachEnd * density},
          mOpacityChords{kOpacityChords.count * density, kOpacityChords.atEachEnd * density}
    {
        if (density < 1) throw std::invalid_argument("the exact law needs a chord density >= 1");
    }

    BoughLawTraits traits() const override
    {
        return {RearComposite::Share, /*stripToConesEnd=*/true, /*shadesNeedles=*/true};
    }
    BoughShading shade(const TracedBough& b, const Vec3& V,
                       const std::vector<Vec3>& towardsLights, const LayerModel& layers,
                       const BoughLawNeeds& needs) const override
    {
        BoughShading out;
        const ApertureTrig trig = apertureTrig(b.geometry.cone.aperture_rad);
        const double cotPhi = trig.oneOverTan, sinPhi = trig.sinPhi, cosPhi = trig.cosPhi;
        const std::size_t lights = towardsLights.size();
        // Per half (0 front, 1 rear) and cell: the opacity; per light, what is lit (the
        // transfer) and what it reflects. Per thread, so that a bough's shading allocates
        // only the profiles it returns.
        using Cells = std::array<double, kCells>;
        struct PerLight {
            Cells lit[2], diffuse[2], specular[2];
        };
        Cells alpha[2] = {};
        thread_local std::vector<PerLight> perLight;
        perLight.assign(lights, PerLight{});
        // Opacities are even in the offset: with no light to shade, half the cells do.
        const auto shade = [&](const ShownLayer& shown) {
            alpha[shown.half][shown.cell] += shown.share;
            if (shown.share <= 0.0) return;
            double rho;
            Vec3 radial;
            coneHeight(b, cotPhi, shown.x, &rho, &radial);
            const Vec3 needle = cosPhi * b.axis + sinPhi * radial;  // as at level 2
            for (std::size_t i = 0; i < lights; ++i) {
                const Vec3& L = towardsLights[i];
                const double seen = shown.share * (needs.transfer ? shown.lit[i] : 1.0);
                PerLight& light = perLight[i];
                light.lit[shown.half][shown.cell] += seen;
                if (needs.diffuse) {
                    light.diffuse[shown.half][shown.cell] +=
                        seen * analytic::needleDiffuse(needle, L, V);
                }
                if (needs.specular) {
                    light.specular[shown.half][shown.cell] +=
                        seen * analytic::needleSpecular(needle, L, V, b.exponent);
                }
            }
        };
        const std::vector<Vec3> none;
        forEachShownLayer(b, V, layers, lights > 0, needs.transfer ? towardsLights : none, shade);
        for (int k = kCells / 2; k < kCells && lights == 0; ++k) {
            alpha[0][k] = alpha[0][kCells - 1 - k];
            alpha[1][k] = alpha[1][kCells - 1 - k];
        }
        for (int k = 0; k < kCells; ++k) {
            // Oblique chords beyond the strip's ends, put onto it, may add up past 1.
            const double total = alpha[0][k] + alpha[1][k];
            if (!(total > 1.0)) continue;
            for (int h = 0; h < 2; ++h) {
                alpha[h][k] /= total;
                for (PerLight& light : perLight) {
                    light.lit[h][k] /= total;
                    light.diffuse[h][k] /= total;
                    light.specular[h][k] /= total;
                }
            }
        }
        const auto profiles = [](const Cells(&halves)[2]) {
            return FrontRearProfile{StripProfile::sampled(halves[0]),
                                    StripProfile::sampled(halves[1])};
        };
        out.alpha = profiles(alpha);
        out.lights.reserve(lights);
        for (const PerLight& light : perLight) {
            out.lights.push_back(
                {profiles(light.lit), profiles(light.diffuse), profiles(light.specular)});
        }
        return out;
    }

    // The whole bough's opacity for chords along d = -towardsLight, across their strip.
    StripProfile opacityFromLight(const TracedBough& b, const Vec3& towardsLight,
                                  const LayerModel& layers) const override
    {
        const Vec3 d = -towardsLight;
        const Vec3 across = stripAcross(b.axis, -d);
        std::vector<double> cells(kCells, 0.0);
        for (int k = 0; k < kCells; ++k) {
            if (k >= kCells / 2) {
                cells[k] = cells[kCells - 1 - k];
                continue;
            }
            for (int p = 0; p < mOpacityChords.count; ++p) {
                Vec3 o;
                double tIn, tOut, weight;
                if (!chord(b, d, across, k, p, mOpacityChords, o, tIn, tOut, weight)) continue;
                double T = 1.0;
                layers.layers(b, o, d, tIn, tOut, [&](const LayerHit& hit) {
                    T *= 1.0 - hit.opacity;
                    return T > 0.0;  // none further changes it
                });
                cells[k] += (1.0 - T) * weight;
            }
            cells[k] = std::min(cells[k], 1.0);
        }
        return StripProfile::sampled(cells);
    }

    std::vector<double> seenByAzimuth(const TracedBough& b, const Vec3& V,
                                      const LayerModel& layers, int bins) const
    {
        const double cotPhi = apertureTrig(b.geometry.cone.aperture_rad).oneOverTan;
        const Vec3 ev = glm::cross(b.across, b.axis);
        std::vector<double> seen(2 * kCells * std::size_t(bins), 0.0);
        const auto at = [&](int half, int cell, int bin) -> double& {
            return seen[(std::size_t(half) * kCells + std::size_t(cell)) * bins + bin];
        };
        forEachShownLayer(b, V, layers, true, {}, [&](const ShownLayer& shown) {
            Vec3 radial;
            coneHeight(b, cotPhi, shown.x, nullptr, &radial);
            const double psi = std::atan2(glm::dot(radial, b.across), glm::dot(radial, ev));
            const double u = (psi + analytic::kPi) / (2.0 * analytic::kPi);
            const int bin = std::clamp(int(u * bins), 0, bins - 1);
            at(shown.half, shown.cell, bin) += shown.share;
        });
        for (int k = 0; k < kCells; ++k) {
            double total = 0.0;
            for (int h = 0; h < 2; ++h) {
                for (int i = 0; i < bins; ++i) total += at(h, k, i);
            }
            if (!(total > 1.0)) continue;
            for (int h = 0; h < 2; ++h) {
                for (int i = 0; i < bins; ++i) at(h, k, i) /= total;
            }
        }
        return seen;
    }

private:
    // A layer a chord of the view meets and what of it shows: its share of the chord's
    // transmittance times the chord's weight, in half `half` (0 front, 1 rear) of cell `cell`;
    // lit[i] the light from the i-th direction forEachShownLayer was asked for that reaches it
    // through the bough (its self-shadowing).
    struct ShownLayer {
        int half, cell;
        double share;
        Vec3 x;
        long cone;
        const double* lit;
    };
    // Every layer the view's chords meet along -V, cell by cell (the first half of the cells
    // only unless `allCells`), until the chord is opaque, lit from each of `towardsLights`.
    template <class Visit>
    void forEachShownLayer(const TracedBough& b, const Vec3& V, const LayerModel& layers,
                           bool allCells, const std::vector<Vec3>& towardsLights,
                           Visit&& visit) const
    {
        const Vec3 d = -V;
        const std::size_t lights = towardsLights.size();
        thread_local std::vector<LayerHit> hits;
        thread_local std::vector<double> lit, fromOne;  // lit: hit-major, a value per light
        for (int k = 0; k < (allCells ? kCells : kCells / 2); ++k) {
            for (int p = 0; p < mShadingChords.count; ++p) {
                Vec3 o;
                double tIn, tOut, weight;
                if (!chord(b, d, b.across, k, p, mShadingChords, o, tIn, tOut, weight)) continue;
                hits.clear();
                double T = 1.0;
                layers.layers(b, o, d, tIn, tOut, [&](const LayerHit& hit) {
                    hits.push_back(hit);
                    T *= 1.0 - hit.opacity;
                    return T >= kOpaque;
                });
                // The chord's layers in front of each are those the view's line met.
                lit.resize(hits.size() * lights);
                for (std::size_t i = 0; i < lights; ++i) {
                    layers.transmittancesAlong(b, o, d, hits, towardsLights[i], fromOne);
                    for (std::size_t h = 0; h < hits.size(); ++h) lit[h * lights + i] = fromOne[h];
                }
                const double tMid = 0.5 * (tIn + tOut);
                T = 1.0;
                for (std::size_t h = 0; h < hits.size(); ++h) {
                    const LayerHit& hit = hits[h];
                    const double share = T * hit.opacity;  // what this layer shows
                    T *= 1.0 - hit.opacity;
                    visit(ShownLayer{hit.t < tMid ? 0 : 1, k, share * weight, o + hit.t * d,
                                     hit.cone, lit.data() + h * lights});
                }
            }
        }
    }

    Chords mShadingChords, mOpacityChords;
};

}  // namespace

std::unique_ptr<BoughLaw> makeExactBoughLaw(int density)
{
    return std::make_unique<ExactBoughLaw>(density);
}

std::vector<double> exactSeenByAzimuth(const TracedBough& b, const Vec3& V,
                                       const LayerModel& layers, int density, int bins)
{
    if (bins < 1) throw std::invalid_argument("needle azimuths need at least one bin");
    return ExactBoughLaw(density).seenByAzimuth(b, V, layers, bins);
}

}  // namespace pine::vdbtrace
