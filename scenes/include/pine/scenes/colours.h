// The colours a species' grey albedos stand for, in one place for every method and the bake:
// the scene gives an albedo per material, the hue is fixed here.
#pragma once

#include "pine/scenes/species.h"

#include <glm/vec3.hpp>

namespace pine::scenes {

/// Linear RGB of the needles: a green hue scaled so that its G channel is needleAlbedo.
glm::dvec3 needleColour(const Species& species);
/// Linear RGB of the bark: a brown hue scaled so that its G channel is barkAlbedo.
glm::dvec3 barkColour(const Species& species);

}  // namespace pine::scenes
