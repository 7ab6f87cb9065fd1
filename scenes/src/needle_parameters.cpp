#include "pine/scenes/species.h"

namespace pine::scenes {

// Section 3.1: phi, l, r and the density change slowly along a branch, so a bough is described
// by its two ends and each parameter varies linearly between them.
NeedleParameters lerp(const NeedleParameters& a, const NeedleParameters& b, double t)
{
    const auto mix = [t](double x, double y) { return x + t * (y - x); };
    NeedleParameters p;
    p.aperture_rad = mix(a.aperture_rad, b.aperture_rad);
    p.length_cm = mix(a.length_cm, b.length_cm);
    p.radius_cm = mix(a.radius_cm, b.radius_cm);
    p.perCone = mix(a.perCone, b.perCone);
    p.coneSpacing_cm = mix(a.coneSpacing_cm, b.coneSpacing_cm);
    return p;
}

}  // namespace pine::scenes
