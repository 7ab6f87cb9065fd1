// Level 1: one needle, a thin cylinder (paper section 4).
//
// Reflectances are per unit projected area of the needle, the paper's R = I / alpha: the mean,
// over what the viewer sees of the cylinder, of the cosine factor. Multiply by the needle's
// albedo / pi and the light's irradiance for radiance. End caps are ignored (r << l).
//
// Every direction is a unit vector: `axis` along the needle, `L` towards the light, `V` towards
// the viewer.
#pragma once

#include "pine/analytic/direction.h"

namespace pine::analytic {

/// g(da) = sin(da) + (pi - da) cos(da): eq. (1)'s dependence on the angle da between L_p and
/// V_p; decreasing from pi at 0 to 0 at pi.
double diffuseG(double da);

/// Eq. (1): diffuse reflectance of a Lambertian cylinder,
///   R_d = s_l / 4 (sin(da) + (pi - da) cos(da)),  da = angle between L_p and V_p.
/// In [0, pi/4]. Where V or L is along the axis, da is taken as 0 (the limit is direction-
/// dependent there; the needle's projected area, hence its weight, vanishes with s_v).
double needleDiffuse(const Vec3& axis, const Vec3& L, const Vec3& V);

/// Eq. (2): specular reflectance of a cylinder under a cos^n lobe on N.H, by the Gaussian
/// (Laplace) approximation of cos^n,
///   R_s = 1/2 s_h^n max(0, cos(alpha_H - alpha_V)) sqrt(2 pi / n).
/// The max(0, .) is our correction: printed without it, eq. (2) goes negative when H_p leans
/// more than 90 degrees from V_p. Relative error O(1/n) while the lobe lies inside the visible
/// half of the cylinder; valid for n >~ 20. Zero when L = -V (no half vector). Below
/// n = 2 / pi, where sqrt(2 pi / n) would exceed pi, the integral of cos^n over the half-circle
/// (at most pi, the integral of 1), the factor is pi: bounded as n -> 0, where the printed
/// form diverges (an exponent of 5e-324 gave NaN); unchanged for every n >= 2 / pi.
/// @param exponent  n > 0
double needleSpecular(const Vec3& axis, const Vec3& L, const Vec3& V, double exponent);

/// Projected area of a needle seen from V: 2 r l s_v, in cm^2 for r, l in cm. This is what
/// eq. (3) divides by the footprint; printed as "2 R_s^cyl", a typo (see docs/errata.md).
double needleProjectedArea(const Vec3& axis, const Vec3& V, double radius_cm, double length_cm);

/// Eq. (3), corrected: the needle's coverage of a pixel footprint of area S_pix (cm^2) that
/// contains it, min(1, projected area / S_pix). A footprint of zero area is fully covered by
/// any needle of non-zero area.
double needleOpacity(double projectedArea_cm2, double footprintArea_cm2);

}  // namespace pine::analytic
