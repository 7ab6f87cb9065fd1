// The paper's bough law (sections 6.4-6.6): the linear law (1 - A)^n ~ 1 - n A on section
// 6.2's layer rates, each half's opacity and each bracket clamped as analytic::boughLinearLaw
// documents (errata E11: on the paper's own bough the unclamped law exceeds 1). One value for
// the whole strip, and the rear's alpha composited behind the front as printed. It reads the
// paper's constant A whatever the layer model.
#include "pine/analytic/bough_shader.h"
#include "pine/vdbtrace/bough_law.h"
#include "pine/vdbtrace/traced_scene.h"

namespace pine::vdbtrace {
namespace {

class LinearBoughLaw final : public BoughLaw {
public:
    BoughShading shade(const TracedBough& b, const Vec3& V,
                       const std::vector<Vec3>& towardsLights, const LayerModel&,
                       const BoughLawNeeds&) const override
    {
        const double phi = b.geometry.cone.aperture_rad;
        const auto constant = [](const analytic::FrontRear& x) {
            return FrontRearProfile{StripProfile::constant(x.front),
                                    StripProfile::constant(x.rear)};
        };
        BoughShading out;
        out.alpha = constant(
            analytic::boughLinearLaw(b.geometry, analytic::boughView(phi, b.axis, V, V))
                .alphaView);
        for (const Vec3& L : towardsLights) {
            BoughLightTransfer light;
            light.transfer = constant(
                analytic::boughLinearLaw(b.geometry, analytic::boughView(phi, b.axis, L, V))
                    .transfer);
            out.lights.push_back(light);
        }
        return out;
    }
    StripProfile opacityFromLight(const TracedBough& b, const Vec3& L,
                                  const LayerModel&) const override
    {
        const double phi = b.geometry.cone.aperture_rad;
        const analytic::FrontRear fromLight =
            analytic::boughLinearLaw(b.geometry, analytic::boughView(phi, b.axis, L, L))
                .alphaView;
        return StripProfile::constant(fromLight.front + fromLight.rear);
    }
};

}  // namespace

std::unique_ptr<BoughLaw> makeLinearBoughLaw() { return std::make_unique<LinearBoughLaw>(); }

}  // namespace pine::vdbtrace
