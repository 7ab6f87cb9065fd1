// The paper's bough law (sections 6.4-6.6): the linear law (1 - A)^n ~ 1 - n A on section
// 6.2's layer rates, each half's opacity and each bracket clamped as analytic::boughLinearLaw
// documents (errata E11: on the paper's own bough the unclamped law exceeds 1).
#include "pine/vdbtrace/bough_law.h"

namespace pine::vdbtrace {
namespace {

class LinearBoughLaw final : public BoughLaw {
public:
    BoughShading shade(const analytic::BoughGeometry& geometry, const Vec3& axis, const Vec3& V,
                       const std::vector<Vec3>& towardsLights) const override
    {
        const double phi = geometry.cone.aperture_rad;
        BoughShading out;
        out.alpha = analytic::boughLinearLaw(geometry, analytic::boughView(phi, axis, V, V))
                        .alphaView;
        for (const Vec3& L : towardsLights) {
            BoughLightTransfer light;
            light.transfer =
                analytic::boughLinearLaw(geometry, analytic::boughView(phi, axis, L, V))
                    .transfer;
            const analytic::FrontRear fromLight =
                analytic::boughLinearLaw(geometry, analytic::boughView(phi, axis, L, L))
                    .alphaView;
            light.opacityFromLight = fromLight.front + fromLight.rear;
            out.lights.push_back(light);
        }
        return out;
    }
};

}  // namespace

std::unique_ptr<BoughLaw> makeLinearBoughLaw() { return std::make_unique<LinearBoughLaw>(); }

}  // namespace pine::vdbtrace
