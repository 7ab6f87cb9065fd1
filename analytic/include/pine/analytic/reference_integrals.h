// The defining integrals of the paper's shaders, evaluated by brute adaptive quadrature.
// Slow and accurate: these are what the closed forms are tested and swept against. They share
// no parametrisation with the shaders (the bough reference integrates in depth, the shader in
// opacity; the needle reference sums normals around the cylinder, the shader uses eq. 1).
#pragma once

#include "pine/analytic/bough_shader.h"
#include "pine/analytic/cone_shader.h"

namespace pine::analytic::reference {

/// Section 4's defining ratios for a needle, by quadrature over the cylinder's normals:
/// int (N.L)+ (N.V)+ / int (N.V)+  and  int (N.H)+^n (N.V)+ / int (N.V)+.
double needleDiffuse(const Vec3& axis, const Vec3& L, const Vec3& V);
double needleSpecular(const Vec3& axis, const Vec3& L, const Vec3& V, double exponent);

/// Projected area of a needle by quadrature of int (N.V)+ dS over its side.
double needleProjectedArea(const Vec3& axis, const Vec3& V, double radius_cm, double length_cm);

/// J, G, S of both cone faces by adaptive quadrature over the needle azimuth of the level-1
/// expressions (eq. 1 for G, eq. 2 for S), on 256 panels so that no specular peak is missed.
ConeIntegrals coneIntegrals(double aperture_rad, const Vec3& axis, const Vec3& L, const Vec3& V,
                            double exponent);

/// int_face P dtheta, P = L.V + s_l s_v - c_l c_v: the defining integral of the lambda fit.
double coneLambdaFitIntegral(double aperture_rad, const Vec3& axis, const Vec3& L, const Vec3& V,
                             bool front);

/// Equation (7) in the continuous layer model with exact transmittance: opacities and
/// radiance transfer of both halves, by nested adaptive quadrature over the cross-section in
/// depth. Needs finite layer rates (no ray along the branch).
BoughExact boughExact(const BoughGeometry& bough, const BoughView& view, bool shadows = true);

/// Equation (7) under the linear law, before any closed-form step: the transfer of each half,
/// (A / (2 R dh)) int k (1 - A n_V - A n_L) over the half disk, by quadrature. Section 6.6's
/// formula (BoughLinearLaw::transferUnclamped) must equal it. Needs finite layer rates.
FrontRear boughLinearized(const BoughGeometry& bough, const BoughView& view);

/// The swept-area integrals of section 6.5 on the unit disk, by nested adaptive quadrature.
SweptAreas sweptAreas(double cosLV);

}  // namespace pine::analytic::reference
