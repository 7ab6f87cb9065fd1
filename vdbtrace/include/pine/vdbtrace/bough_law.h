// Level 3's law: how a bough, shaded as a volume (paper section 6), covers the pixel and passes
// light. A law is a type registered by name in src/bough_laws.cpp and chosen once per render
// (TracedSceneOptions::boughLaw): the view opacity, each light's transfer and each light's
// opacity all come from the same law, in one call, so that no render mixes two laws.
#pragma once

#include "pine/analytic/bough_shader.h"
#include "pine/vdbtrace/geometry.h"

#include <memory>
#include <string>
#include <vector>

namespace pine::vdbtrace {

/// A bough as one light sees it, under a law.
struct BoughLightTransfer {
    /// Radiance of each half per unit I^cyl of its face and unit opacity-weighted irradiance,
    /// with the bough's self-shadowing (section 6.6's I_FV / I^cyl and I_RV / I^cyl).
    analytic::FrontRear transfer;
    /// The whole bough's opacity seen from the light: what its shadow takes from light
    /// crossing it.
    double opacityFromLight = 0.0;
};

/// A bough under a law, for one camera position and the scene's lights.
struct BoughShading {
    analytic::FrontRear alpha;               ///< opacity of each half seen from the camera
    std::vector<BoughLightTransfer> lights;  ///< one per light, in the scene's order
};

class BoughLaw {
public:
    virtual ~BoughLaw() = default;
    /// The bough `geometry` around unit `axis`, seen along unit V (towards the camera) and lit
    /// along each unit direction of `towardsLights`.
    virtual BoughShading shade(const analytic::BoughGeometry& geometry, const Vec3& axis,
                               const Vec3& V, const std::vector<Vec3>& towardsLights) const = 0;
};

/// The law registered as `name`; throws InputError naming the registered ones.
const BoughLaw& boughLaw(const std::string& name);
/// The registered names, in registration order (the first is the default).
std::vector<std::string> boughLawNames();

}  // namespace pine::vdbtrace
