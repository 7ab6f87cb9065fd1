// Level 3's law: how a bough, shaded as a volume (paper section 6), covers the pixel and passes
// light. A law is a type registered by name in src/bough_laws.cpp and chosen once per render
// (the scene's render.bough_law): the view opacity, each light's transfer and each light's
// opacity all come from the same law, so that no render mixes two laws. Each is a
// profile across the bough's strip (strip_profile.h): the paper's laws are one value for the
// whole strip, the exact law a function of the chord's offset.
#pragma once

#include "pine/vdbtrace/effects_plan.h"
#include "pine/vdbtrace/geometry.h"
#include "pine/vdbtrace/strip_profile.h"

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace pine::vdbtrace {

struct TracedBough;
class LayerModel;

/// How the rear half's profiles composite behind the front's.
enum class RearComposite : std::uint8_t {  // one byte: a landscape holds 3.3 million boughs
    /// The rear profiles are its own opacity and radiance, composited as they are behind the
    /// front (the paper's section 6.6 alphas).
    Own,
    /// The rear profiles are its share of the strip's coverage and radiance as seen through the
    /// front: composited divided by what the front leaves, so that front and rear together
    /// give the strip's coverage at any pixel coverage.
    Share,
};

/// The opacity of a chord through both halves, their `alpha` profiles read over a footprint
/// `w` wide at offset xi on a strip of half-width R, composited as `rear` says.
inline double bothHalvesOpacity(const FrontRearProfile& alpha, RearComposite rear, double xi,
                                double R, double w)
{
    const double front = alpha.front.overFootprint(xi, R, w);
    const double back = alpha.rear.overFootprint(xi, R, w);
    return rear == RearComposite::Share ? front + back : 1.0 - (1.0 - front) * (1.0 - back);
}

/// A bough as one light sees it with the camera where it is, under a law.
struct BoughLightTransfer {
    /// Radiance of each half per unit I^cyl of its face and unit irradiance, with the
    /// bough's self-shadowing (section 6.6's I_FV / I^cyl and I_RV / I^cyl), across the
    /// view's strip.
    FrontRearProfile transfer;
    /// With BoughLawTraits::shadesNeedles: what each half reflects per unit irradiance, each
    /// needle by eqs. 1-2 at its own direction (diffuse per unit albedo / pi, specular per
    /// unit specular weight), with self-shadowing when asked: in place of the transfer times
    /// the face's mean I^cyl, which holds only where the light reaches every needle alike.
    FrontRearProfile diffuse, specular;
};

/// What a render needs of a bough law: a law may skip what is not needed.
struct BoughLawNeeds {
    bool transfer = true;  ///< self-shadowing: each light's transfer
    bool diffuse = true;   ///< the diffuse reflectance, for a law that shades needles
    bool specular = true;  ///< the specular one
    /// What a render of the effects `plan` reads.
    static BoughLawNeeds from(const EffectsPlan& plan)
    {
        return {plan.selfShadowing, plan.diffuse, plan.specular};
    }
};

/// How a law's profiles are drawn and read: the same for every bough.
struct BoughLawTraits {
    RearComposite rear = RearComposite::Own;
    /// The strip the profiles are drawn on runs from the base to the cones' end (where the last
    /// cone's needles end), not to the tip: level 3 and shadows then draw it so.
    bool stripToConesEnd = false;
    /// Each light's `diffuse` and `specular` profiles are set: level 3 reflects them.
    bool shadesNeedles = false;
};

/// A bough under a law, for one camera position and the scene's lights.
struct BoughShading {
    FrontRearProfile alpha;  ///< opacity of each half seen from the camera, across its strip
    std::vector<BoughLightTransfer> lights;  ///< one per light, in the scene's order
};

class BoughLaw {
public:
    virtual ~BoughLaw() = default;
    /// Its conventions, known without shading a bough (the paper's laws keep the defaults).
    virtual BoughLawTraits traits() const { return {}; }
    /// The law one scene renders with: this one (not owned) for a law without state; a law
    /// that fills tables as it goes makes a new one, so that every scene fills its own (compare
    /// and bench time each render from nothing).
    virtual std::shared_ptr<const BoughLaw> fresh() const
    {
        return std::shared_ptr<const BoughLaw>(std::shared_ptr<const BoughLaw>(), this);
    }
    /// Bough b (its frame, geometry, R and A set), seen along unit V (towards the camera),
    /// its strip's offsets measured along b.across, and lit along each unit direction of
    /// `towardsLights`. `layers` is the render's layer model, for a law that crosses the
    /// layers.
    virtual BoughShading shade(const TracedBough& b, const Vec3& V,
                               const std::vector<Vec3>& towardsLights, const LayerModel& layers,
                               const BoughLawNeeds& needs) const = 0;
    /// The whole bough's opacity seen along unit `towardsLight` (from the light), across the
    /// light's strip, offsets along normalize(b.axis x towardsLight): what its shadow takes
    /// from light crossing it. The same law as shade()'s, asked apart: a render needs it only
    /// of the boughs a shadow cone meets.
    virtual StripProfile opacityFromLight(const TracedBough& b, const Vec3& towardsLight,
                                          const LayerModel& layers) const = 0;
};

/// The exact law (registered as "exact" with density 1) with `density` times its chords per
/// cell: the converged law the corrected law tabulates and tests compare with. @throw
/// std::invalid_argument for a density below 1.
std::unique_ptr<BoughLaw> makeExactBoughLaw(int density = 1);

/// The law registered as `name`; throws InputError naming the registered ones.
const BoughLaw& boughLaw(const std::string& name);
/// The registered names, in registration order (the first is the default).
std::vector<std::string> boughLawNames();

}  // namespace pine::vdbtrace
