// The fibre laws (errata E13): the needles as thin cylinders, met at a rate of (needle length
// per volume) 2 r |d x a| per cm along d. Needle length per volume is N / (2 pi rho dh sin(phi))
// (N needles of cone j fan out from its apex; the cones are dh sin(phi) apart across them), so
// the rate is needle_coverage |d x needle_direction| |layer_gradient| with the grids' fields.
//
// - "poisson": needles placed independently, so the rate is an extinction (a Poisson medium).
//   Evenly spaced needles overlap less than that: on the long paper bough side-on it covers
//   0.944 of the explicit needles.
// - "fibre": the needles evenly spaced in each cone, as the fibre layer model of levels 2-3
//   holds them. A line meets one cone's needles over a band; if it meets n of them on average
//   there, it is stopped with probability min(1, n), not 1 - exp(-n). The reference follows
//   the bands along the line (layer_bands.h), so the rate is the law's and the band is the
//   tracer's; within one layer crossing n = A s_v / |n . d| with the local coverage for A.
//
// Both write the rate's mean over directions as `density`: the mean needles met per length, which
// is the Poisson medium's extinction (a volume renderer elsewhere sees that medium).
#include "pine/bake/extinction_law.h"

#include <glm/geometric.hpp>

#include <memory>

namespace pine::bake {
namespace {

class FibreExtinctionLaw final : public ExtinctionLaw {
public:
    explicit FibreExtinctionLaw(bool evenlySpaced) : mEvenlySpaced(evenlySpaced) {}

    std::string formula() const override
    {
        const std::string rate =
            "needles met per unit length along d: needle_coverage |d x needle_direction| "
            "|layer_gradient|; ";
        return rate +
               (mEvenlySpaced ? "each band of one layer along the line (d . layer_gradient of one "
                                "sign, at most one layer) stopping it with probability min(1, "
                                "needles met there); "
                              : "sigma(d) = that rate; ") +
               "density = the rate's mean over directions";
    }
    double extinction(const LayerSample& field, const Vec3& d) const override
    {
        return field.needleCoverage * glm::length(glm::cross(d, field.needle)) *
               glm::length(field.gradient);
    }
    double meanExtinction(const LayerSample& field) const override
    {
        // The mean of |d x a| = sin(d, a) over the unit sphere is pi / 4.
        return field.needleCoverage * 0.25 * 3.14159265358979323846 * glm::length(field.gradient);
    }
    bool banded() const override { return mEvenlySpaced; }

private:
    bool mEvenlySpaced;
};

}  // namespace

std::unique_ptr<ExtinctionLaw> makeFibreExtinctionLaw()
{
    return std::make_unique<FibreExtinctionLaw>(true);
}

std::unique_ptr<ExtinctionLaw> makePoissonExtinctionLaw()
{
    return std::make_unique<FibreExtinctionLaw>(false);
}

}  // namespace pine::bake
