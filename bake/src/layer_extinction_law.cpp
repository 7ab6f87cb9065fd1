// The layer law (paper section 6 on the true cones, errata E10 and E12): a ray along d crosses
// |d . G| layers per cm, each of opacity A, so sigma(d) = -ln(1 - A) |d . G|.
#include "pine/bake/extinction_law.h"

#include <glm/geometric.hpp>

#include <cmath>
#include <memory>

namespace pine::bake {
namespace {

class LayerExtinctionLaw final : public ExtinctionLaw {
public:
    std::string formula() const override
    {
        return "sigma(d) = -ln(1 - layer_opacity) |d . layer_gradient| per unit length; "
               "density = its mean over directions";
    }
    double extinction(const LayerSample& field, const Vec3& d) const override
    {
        return field.layerExtinction() * std::abs(glm::dot(d, field.gradient));
    }
    double meanExtinction(const LayerSample& field) const override
    {
        // The mean of |d . G| over the unit sphere is |G| / 2: with u = cos(d, G) uniform on
        // [-1, 1], E|u| = 1/2.
        return field.layerExtinction() * glm::length(field.gradient) * 0.5;
    }
};

}  // namespace

std::unique_ptr<ExtinctionLaw> makeLayerExtinctionLaw()
{
    return std::make_unique<LayerExtinctionLaw>();
}

}  // namespace pine::bake
