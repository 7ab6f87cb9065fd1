// A bough's opacity with its true cones: section 6 with exact transmittance, without section
// 6.2's asymptotes (docs/errata.md E12). The reference renderer's voxelized field converges to
// this; boughExact (the paper's geometry) differs from it off the axis.
#pragma once

#include "pine/analytic/bough_shader.h"

namespace pine::analytic {

/// Layers of true cones crossed by a ray along -V through the bough's cross-section at offset
/// u = x / R in [-1, 1] from the axis: the total variation of g = h - rho cot(phi) along the
/// chord, over dh. In the plane P_x, with Y = y / R across the chord, g / R = const - a Y -
/// b sqrt(u^2 + Y^2), a = cot(phi_V), b = cot(phi): at most one stationary point, at
/// Y* = -(a / b) |u| / sqrt(1 - a^2 / b^2) when |a| < b (the view outside the aperture).
/// @param cosPhiV, sinPhiV  of the angle between V and the branch; sinPhiV = 0 gives +inf
double trueConeLayers(const BoughGeometry& bough, double cosPhiV, double sinPhiV, double u);

/// The whole bough's opacity along -V with exact transmittance, 1 - mean over u of
/// exp(-mu layers(u)), mu = -ln(1 - A): Gauss-Legendre split where layers(u) has kinks
/// (u = 0 and +-sqrt(1 - a^2 / b^2)). 1 for a view along the branch; 0 for a bough without
/// needles or volume.
double trueConeOpacity(const BoughGeometry& bough, double cosPhiV, double sinPhiV);

}  // namespace pine::analytic
