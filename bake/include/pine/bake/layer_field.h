// The continuous layer field of a bough (paper section 6), pointwise: what `bake` voxelizes and
// the reference renderer integrates. Cone j is the surface g = h - rho cot(phi) = j dh, with h
// along the branch from its base and rho the distance from it: a ray along unit d crosses
// |d . grad g| / dh layers per cm (the true cones, no asymptotes; errata E12), each of opacity
// A: under the layer law (extinction_law.h) sigma(d) = -ln(1 - A) |d . G| per cm with
// G = grad g / dh.
#pragma once

#include "pine/analytic/bough_shader.h"

#include <glm/vec3.hpp>

#include <optional>

namespace pine::bake {

using Vec3 = glm::dvec3;

/// One bough: its branch from base to tip and the needle parameters at mid-bough, in the
/// shaders' own type (section 3.1's phi, l, r, N and dh), which the tracer reads too.
struct BoughSpec {
    Vec3 base_cm{0.0}, tip_cm{0.0, 0.0, 1.0};
    analytic::BoughGeometry needles;
    Vec3 needleAlbedo{0.2};
    /// The scene's tree (index of its placement) the bough belongs to, -1 if none is known:
    /// names the voxels' tree (TreeGrids::tree), baked into no field.
    int tree = -1;
};

/// The largest extinction per layer, -ln(1e-6): a layer whose needles cover its cone (A = 1)
/// lets 1e-6 through instead of nothing, so that grids and their normalization stay finite;
/// below A = 1 - 1e-6 the cap changes nothing. (added)
inline constexpr double kMaxLayerExtinction = 13.815510557964274;

/// The field at a point inside a bough's layered region: what a voxel holds. How it stops
/// light is an extinction law's (extinction_law.h).
struct LayerSample {
    Vec3 gradient{0.0};         ///< G = (axis - cot(phi) radial) / dh, layers per cm
    Vec3 needle{0.0};           ///< unit needle direction there: cos(phi) axis + sin(phi) radial
    double layerOpacity = 0.0;  ///< A = 2 N r / (pi R)
    /// The needles' coverage of their cone here, min(1, N r / (pi rho)): they fan out from
    /// the axis, so their mean over the cone's area is A (errata E13).
    double needleCoverage = 0.0;
    /// mu = -ln(1 - A): extinction per layer crossed (docs/errata.md, E10), capped at
    /// kMaxLayerExtinction so that A = 1 stays finite. (added)
    double layerExtinction() const;
};

/// The field at x, or nothing outside the region the bough's cones fill: rho <= R = l sin(phi)
/// and 0 <= h - rho cot(phi) <= length (a cone's apex lies on the branch).
std::optional<LayerSample> sampleBough(const BoughSpec& bough, const Vec3& x_cm);

}  // namespace pine::bake
