// Level 2: a cone of N needles around a branch (paper section 5), shaded as a continuous
// semi-opaque cone whose every point reflects like the local needle.
//
// A needle at azimuth theta points along a(theta) = cos(phi) axis + sin(phi) (cos t e1 + sin t e2),
// with e1 along V_p: theta_V = 0. The front face is theta in [-pi/2, pi/2] (needles leaning
// towards the viewer), the rear face the other half. With N/(2 pi) needles per radian, the sums
// over a face of the needles' projected areas (2 r l s_v) and of area x reflectance are
//   area     = N r l / pi             * J,   J = int_face s_v dtheta               (eq. 6)
//   diffuse  = N r l / (4 pi)         * G,   G = int_face s_l s_v g(da) dtheta      (eq. 4)
//   specular = N r l / (2 pi) sqrt(2 pi / n) * S,  S = int_face s_h^(n-1) (H_p.V_p)+ dtheta (eq. 5)
// with g(da) = sin(da) + (pi - da) cos(da) from eq. (1). The paper's own normalisations of these
// (l A / 4, l A / 2, l A) drop the factor R / 2 and the footprint; see docs/errata.md.
#pragma once

#include "pine/analytic/direction.h"

namespace pine::analytic {

/// A cone of needles (section 3.1). Lengths in cm, the paper's unit.
struct ConeGeometry {
    double aperture_rad = kPi / 8;  ///< phi, angle of each needle to the branch, in (0, pi/2]
    double needleLength_cm = 4.25;  ///< l
    double needleRadius_cm = 0.05;  ///< r
    double needlesPerCone = 12;     ///< N
};

/// R = l sin(phi): radius of the bough cylinder, in cm (section 3.1).
double boughRadius(const ConeGeometry& cone);

/// 2 N r / (pi R): the needles' projected area over the cone's, unclamped; above 1 the needles
/// of one cone overlap and no shader level describes them (what scene files are checked
/// against). 0 for a cone of zero radius.
double layerCoverage(const ConeGeometry& cone);

/// A = 2 N r / (pi R): the mean fraction of the cone surface the needles cover (section 3.3).
/// layerCoverage clamped to [0, 1].
double layerOpacity(const ConeGeometry& cone);

/// The dimensionless face integrals J, G, S of the header comment.
struct ConeFaceIntegrals {
    double J = 0.0;  ///< int s_v: projected needle length per unit needle length, summed
    double G = 0.0;  ///< int s_l s_v g(da)
    double S = 0.0;  ///< int s_h^(n-1) (H_p . V_p)+
};

struct ConeIntegrals {
    ConeFaceIntegrals front, rear;
};

/// Our closed forms for J, G and S of both faces (corrections of eqs. 4-6, docs/errata.md):
///  - J has no elementary antiderivative (an incomplete elliptic integral): an 8-point
///    Gauss-Legendre sum on each symmetric quarter, whose kinks (needle along V) fall on its
///    ends; relative error < 1e-4 (tests).
///  - G = (pi/2) int Q + int s_l s_v h(da), where Q = L.V - c_l c_v = s_l s_v cos(da) is a
///    trigonometric polynomial of degree 2 in theta, integrated exactly, and the positive,
///    slowly varying rest h(da) = sin(da) + (pi/2 - da) cos(da), in [1, pi/2], by 8-point
///    Gauss-Legendre on each half face.
///  - S: the lobe peaks at the azimuths where the needle is orthogonal to H (the paper's idea,
///    eq. 5). Laplace's method there needs the Jacobian 1 / |dc_h/dtheta| the paper drops, and
///    fails where the two peaks merge or where no needle is orthogonal to H but n is moderate.
///    We integrate the exact integrand by Gauss-Legendre (<= 64 nodes) on windows placed and sized
///    by that analysis: a cost independent of n, relative error < 1e-3 (tests).
/// @param axis  unit branch direction; L, V unit; exponent n > 1.
ConeIntegrals coneIntegrals(double aperture_rad, const Vec3& axis, const Vec3& L,
                            const Vec3& V, double exponent);

/// Sums over the needles of each face, in cm^2 (see header comment).
struct ConeFaceSums {
    double area = 0.0;      ///< sum of projected needle areas
    double diffuse = 0.0;   ///< sum of projected area x R_d
    double specular = 0.0;  ///< sum of projected area x R_s
};

struct ConeSums {
    ConeFaceSums front, rear;
};

ConeSums coneSums(const ConeGeometry& cone, const ConeIntegrals& integrals, double exponent);

/// A face's mean reflectances per unit projected needle area: what section 6 calls
/// I^cyl_front and I^cyl_rear. Zero for a face of zero projected area.
struct FaceReflectance {
    double diffuse = 0.0;
    double specular = 0.0;
};
FaceReflectance meanReflectance(const ConeFaceSums& face);

/// A cone shaded in a footprint of area S_pix that contains it (paper's alpha^cone, I_d^cone,
/// I_s^cone): alpha = min(1, area / S_pix), illumination = alpha x mean reflectance, so that
/// I <= alpha max(R) holds even where the needles' area exceeds the footprint.
struct ConeShading {
    double alphaFront = 0.0, alphaRear = 0.0;
    double diffuseFront = 0.0, diffuseRear = 0.0;
    double specularFront = 0.0, specularRear = 0.0;
};
ConeShading shadeCone(const ConeSums& sums, double footprintArea_cm2);

// ---- The paper's printed forms, kept only to measure them (sweep, errata). ----

/// Eq. (6) as printed, divided by l A: pi cos(phi) cos(phi_V) - 2 sin(phi) sin(phi_V), the
/// claimed value of J_front. It integrates c_v, not s_v, with a sign slip: negative for a view
/// orthogonal to the branch.
double coneOpacityPrinted(double aperture_rad, double phiV_rad);

/// Eq. (4) as printed: the lambda fit of the first factor P = L.V - cos(AL + AV) of F, with the
/// angle model AL ~ A_L + B_L cos(theta - theta_L), A_L = max(phi_L, phi), B_L = min(phi_L, phi),
/// integrated over the front (`front` true) or rear face. Its own defining integral is
/// int_face P dtheta; it omits F's second factor (2 + (pi - 2) cos(da)) / 2.
double coneDiffuseLambdaFit(double aperture_rad, const Vec3& axis, const Vec3& L, const Vec3& V,
                            bool front);

/// Eq. (5) as printed, in the normalisation of S: eps sqrt(2 pi / n) (V.H), eps the number of
/// azimuths on the face where the needle is orthogonal to H. No Jacobian.
double coneSpecularPrinted(double aperture_rad, const Vec3& axis, const Vec3& L, const Vec3& V,
                           double exponent, bool front);

/// The F fit of section 5 as a function of da alone: (1 + cos da)/2 (2 + (pi - 2) cos da),
/// the paper's stand-in for diffuseG(da) of eq. (1).
double diffuseFFit(double da);

/// The needle direction a(theta) of the cone in the frame used by coneIntegrals.
struct ConeFrame {
    Vec3 axis, e1, e2;
    double cosPhi = 1.0, sinPhi = 0.0;
    Vec3 needle(double theta) const;
};
ConeFrame coneFrame(double aperture_rad, const Vec3& axis, const Vec3& L, const Vec3& V);

}  // namespace pine::analytic
