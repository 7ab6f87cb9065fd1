// Where a ray meets the ground of a scene (plane or Gaussian hill), for every tracer.
#pragma once

#include "pine/scenes/scene.h"
#include "pine/vdbtrace/geometry.h"

namespace pine::vdbtrace {

/// The first hit of the ray's axis with the ground: its distance and the surface normal.
/// False if there is none (no ground, looking up, or the eye is under the hill).
bool hitGround(const scenes::Ground& ground, const ConeRay& ray, double& t, Vec3& normal);

}  // namespace pine::vdbtrace
