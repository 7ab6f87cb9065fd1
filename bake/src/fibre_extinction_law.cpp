// The fibre law (errata E13): the needles as a medium of thin cylinders, sigma(d) = (needle
// length per volume) 2 r |d x a| per cm. Needle length per volume is N / (2 pi rho dh sin(phi))
// (N needles of cone j fan out from its apex; the cones are dh sin(phi) apart across them), so
// sigma(d) = needle_coverage |d x needle_direction| |layer_gradient| with the grids' fields.
// It is the continuous limit of the fibre layer model (vdbtrace), with the needles placed
// independently (a Poisson medium): evenly spaced needles overlap less than that, so it covers
// a little less than they do.
#include "pine/bake/extinction_law.h"

#include <glm/geometric.hpp>

#include <memory>

namespace pine::bake {
namespace {

class FibreExtinctionLaw final : public ExtinctionLaw {
public:
    std::string formula() const override
    {
        return "sigma(d) = needle_coverage |d x needle_direction| |layer_gradient| per cm; "
               "density = mean extinction / pine:density_scale_per_cm";
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
};

}  // namespace

std::unique_ptr<ExtinctionLaw> makeFibreExtinctionLaw()
{
    return std::make_unique<FibreExtinctionLaw>();
}

}  // namespace pine::bake
