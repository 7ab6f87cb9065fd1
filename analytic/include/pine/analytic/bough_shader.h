// Level 3: a bough, the cylinder of radius R = l sin(phi) around a branch filled with cones of
// needles every dh along it, shaded as an anisotropic volume (paper section 6).
//
// A ray at angle phi_r to the branch crosses k(phi_r, phi) / dh cone layers per unit of its
// path projected on the plane orthogonal to the branch on the half where it enters (front),
// and kbar = k(phi_r, pi - phi) / dh on the other half (section 6.1):
//   k(phi_r, phi) = |cot(phi) - cot(phi_r)| = |sin(phi_r - phi)| / (sin(phi) sin(phi_r)).
// Each layer has opacity A (section 3.3). Values here are per unit apparent area of the bough
// (its projected width 2R times length) and per unit needle reflectance I^cyl of the face.
#pragma once

#include "pine/analytic/cone_shader.h"

namespace pine::analytic {

struct BoughGeometry {
    ConeGeometry cone;
    double coneSpacing_cm = 0.9;  ///< dh, distance between successive cones along the branch
};

/// The paper's benchmark bough (section 7): N = 12, r = 0.05 cm, l = 4.25 cm, phi = pi/8,
/// dh = 0.9 cm.
inline BoughGeometry paperBough()
{
    return {{kPi / 8, 4.25, 0.05, 12}, 0.9};
}

/// k(phi_r, phi) from phi_r's cosine c and sine s; +inf for a ray along the branch (s = 0).
double layerRate(double aperture_rad, double c, double s);
/// kbar = k(phi_r, pi - phi).
double layerRateMirror(double aperture_rad, double c, double s);

/// The view and light geometry of a bough.
struct BoughView {
    double kV = 0.0, kVbar = 0.0;  ///< front and rear layer rates for the view ray
    double kL = 0.0, kLbar = 0.0;  ///< the same for the shadow ray
    double cosLV = 0.0;  ///< cos(l_v), l_v the angle between L_p and V_p; 0 if either is 0
};
BoughView boughView(double aperture_rad, const Vec3& axis, const Vec3& L, const Vec3& V);

/// Front (entry) and rear halves of one quantity.
struct FrontRear {
    double front = 0.0, rear = 0.0;
};

/// The bough under the paper's linear law (1 - A)^n ~ 1 - n A (sections 6.4-6.6).
struct BoughLinearLaw {
    double a = 0.0;  ///< a = (pi/4) A R / dh: opacity per unit k
    double alphaUnclamped = 0.0;  ///< a (kV + kVbar): the law's total opacity, may exceed 1
    FrontRear alphaView;   ///< alpha_FV = a kV, alpha_RV = a kVbar, clamped: sum in [0, 1]
    FrontRear alphaLight;  ///< alpha_FL, alpha_RL, clamped likewise
    /// I_FV / I^cyl_front and I_RV / I^cyl_rear of section 6.6, each bracket kept in [0, 1].
    FrontRear transfer;
    /// The same from the unclamped alphas and brackets: the formula exactly as derived, which
    /// can exceed 1 or go negative when n A is not small.
    FrontRear transferUnclamped;
};
BoughLinearLaw boughLinearLaw(const BoughGeometry& bough, const BoughView& view);

/// The same continuous layer model with exact transmittance T^(layers crossed), T = 1 - A,
/// for the view and shadow rays: equation (7) without the linear law. Integrated over the
/// bough's cross-section by Gauss-Legendre in the opacity variable tau = 1 - T^(layers)
/// along each chord, which stays finite when k -> inf or A -> 1.
/// alpha.front = 1 - <T^front>, alpha.rear = <T^front (1 - T^rear)>, sum = whole bough.
/// transfer.front and .rear are the radiance of each half per unit I^cyl, with shadows.
struct BoughExact {
    FrontRear alpha;
    FrontRear transfer;
    double total() const { return alpha.front + alpha.rear; }
};
BoughExact boughExact(const BoughGeometry& bough, const BoughView& view, bool shadows = true);

/// The four swept-area integrals of section 6.5 over the unit disk: the integral over the
/// view's front (F_V) or rear (R_V) half of the shadow ray's projected length in the light's
/// front (F_L) or rear (R_L) half. Closed forms (verified by quadrature in the tests):
///   F_V x F_L: 1 - cos(l_v)/3      F_V x R_L: (1 - cos(l_v))/3
///   R_V x F_L: 1 + cos(l_v)/3      R_V x R_L: (1 + cos(l_v))/3
/// The paper prints these with a factor sin(l_v) (cancelled by its Jacobian) and R^2 for R^3.
struct SweptAreas {
    double fvFl, fvRl, rvFl, rvRl;
};
SweptAreas sweptAreas(double cosLV);

}  // namespace pine::analytic
