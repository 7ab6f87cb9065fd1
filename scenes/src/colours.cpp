#include "pine/scenes/colours.h"

namespace pine::scenes {
namespace {

const glm::dvec3 kNeedleHue{0.45, 1.0, 0.35};
const glm::dvec3 kBarkHue{1.0, 0.75, 0.55};

glm::dvec3 hued(const glm::dvec3& hue, double albedo) { return hue * (albedo / hue.y); }

}  // namespace

glm::dvec3 needleColour(const Species& species) { return hued(kNeedleHue, species.needleAlbedo); }

glm::dvec3 barkColour(const Species& species) { return hued(kBarkHue, species.barkAlbedo); }

}  // namespace pine::scenes
