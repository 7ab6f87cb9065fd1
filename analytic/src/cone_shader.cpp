#include "pine/analytic/cone_shader.h"

#include "pine/analytic/needle_shader.h"
#include "pine/analytic/quadrature.h"

#include <glm/geometric.hpp>

#include <algorithm>
#include <cmath>
#include <utility>
#include <vector>

namespace pine::analytic {
namespace {

constexpr double kHalfPi = 0.5 * kPi;

// A direction's cosine with the needle at azimuth theta: c(theta) = u + p cos t + q sin t.
struct Harmonic {
    double u = 0.0, p = 0.0, q = 0.0;
    double at(double t) const { return u + p * std::cos(t) + q * std::sin(t); }
};

Harmonic harmonic(const ConeFrame& f, const Vec3& X)
{
    return {f.cosPhi * glm::dot(f.axis, X), f.sinPhi * glm::dot(f.e1, X),
            f.sinPhi * glm::dot(f.e2, X)};
}

double sine(double c) { return std::sqrt(std::max(0.0, (1.0 - c) * (1.0 + c))); }

// h(da) = g(da) - (pi/2) cos(da): symmetric about pi/2, in [1, pi/2].
double restOfG(double da) { return std::sin(da) + (kHalfPi - da) * std::cos(da); }

// int_face c_l c_v dtheta, exactly (both are degree-1 harmonics; q_v = 0 by the frame).
double productIntegral(const Harmonic& l, const Harmonic& v, double sign)
{
    return kPi * l.u * v.u + sign * 2.0 * (l.u * v.p + l.p * v.u) + kHalfPi * l.p * v.p;
}

// S of both faces. c_h(theta) = u + w cos(psi), psi = theta - theta_H, is nearest zero at the
// extremum psi_e (0 if u < 0, pi if u > 0), with roots c_h = 0 at psi_e +- delta when |u| <= w.
// Laplace's method (the paper's eq. 5) gives each root a peak of width 1 / (|c_h'| sqrt(n - 1)),
// |c_h'| = sqrt(w^2 - u^2): the Jacobian the printed form drops. Where the roots merge that
// width diverges and the true one is quartic, (8 / ((n - 1) w^2))^(1/4); with no root the
// lobe's tail near psi_e still counts when n is moderate. So instead of Laplace's closed form
// we integrate the exact integrand by Gauss-Legendre on windows of +-6 such widths placed
// where Laplace's analysis puts the peaks, split at the faces' edges: correct in all regimes,
// and O(1) in n: at most 2 windows x 4 panels x 8 nodes.
std::pair<double, double> specularFaceIntegrals(const Harmonic& hv, const Harmonic& hh,
                                                const Vec3& H, const Vec3& V, double exponent)
{
    const double kappa = exponent - 1.0;
    const double w = std::hypot(hh.p, hh.q);
    if (!(kappa > 0.0) || !(w > 0.0)) return {0.0, 0.0};  // lobe constant in theta: no peak
    const double absU = std::abs(hh.u);
    const double gap = absU - w;  // > 0: no needle is orthogonal to H
    if (gap > 0.0 && 0.5 * kappa * gap * gap > 40.0) return {0.0, 0.0};  // below e^-40

    const double thetaH = std::atan2(hh.q, hh.p);
    const double psiE = hh.u < 0.0 ? 0.0 : kPi;
    const double quartic = std::pow(8.0 / (kappa * w * w), 0.25);
    std::vector<std::pair<double, double>> windows;  // in psi, relative to psi_e
    double peakWidth;                                // std-dev of each peak, in psi
    if (gap <= 0.0) {
        const double delta = std::acos(std::min(1.0, absU / w));
        peakWidth = std::min(quartic, 1.0 / std::sqrt((w - absU) * (w + absU) * kappa));
        // One window per peak, meeting at the extremum between them where they overlap: a
        // merged window would hold two narrow peaks too few nodes apart.
        windows = {{-delta - 6.0 * peakWidth, std::min(-delta + 6.0 * peakWidth, 0.0)},
                   {std::max(delta - 6.0 * peakWidth, 0.0), delta + 6.0 * peakWidth}};
    } else {
        peakWidth = std::min(quartic, 1.0 / std::sqrt(kappa * gap * w));
        windows = {{-6.0 * peakWidth, 6.0 * peakWidth}};
    }
    const double VH = glm::dot(V, H);
    const auto lobe = [&](double theta) {
        const double ch = hh.at(theta), cv = hv.at(theta);
        const double cosine = VH - ch * cv;  // H_p . V_p
        if (!(cosine > 0.0)) return 0.0;
        return std::exp(0.5 * kappa * std::log1p(-std::min(1.0, ch * ch))) * cosine;
    };
    double front = 0.0, rear = 0.0;
    for (auto [a, b] : windows) {
        a = std::max(a, -kPi);
        b = std::min(b, kPi);
        // Split at the faces' edges, theta = +-pi/2 (mod 2 pi), between a and b.
        const double from = thetaH + psiE + a, to = thetaH + psiE + b;
        std::vector<double> cuts{from};
        const double firstEdge = std::ceil((from - kHalfPi) / kPi) * kPi + kHalfPi;
        for (double edge = firstEdge; edge < to; edge += kPi) {
            if (edge > from) cuts.push_back(edge);
        }
        cuts.push_back(to);
        for (std::size_t i = 0; i + 1 < cuts.size(); ++i) {
            // Panels at most 3 peak widths wide (4 over a whole window): 8 nodes each.
            const double length = cuts[i + 1] - cuts[i];
            const int panels = std::clamp(int(std::ceil(length / (3.0 * peakWidth))), 1, 4);
            double piece = 0.0;
            for (int k = 0; k < panels; ++k) {
                const double h = length / panels;
                piece += gaussLegendre8(lobe, cuts[i] + k * h, cuts[i] + (k + 1) * h);
            }
            const double mid = std::remainder(0.5 * (cuts[i] + cuts[i + 1]), 2.0 * kPi);
            (std::abs(mid) <= kHalfPi ? front : rear) += piece;
        }
    }
    return {front, rear};
}

}  // namespace

double boughRadius(const ConeGeometry& cone)
{
    return cone.needleLength_cm * std::sin(cone.aperture_rad);
}

double layerCoverage(const ConeGeometry& cone)
{
    const double R = boughRadius(cone);
    if (!(R > 0.0)) return 0.0;
    return 2.0 * cone.needlesPerCone * cone.needleRadius_cm / (kPi * R);
}

double layerOpacity(const ConeGeometry& cone) { return std::clamp(layerCoverage(cone), 0.0, 1.0); }

Vec3 ConeFrame::needle(double theta) const
{
    return cosPhi * axis + sinPhi * (std::cos(theta) * e1 + std::sin(theta) * e2);
}

ConeFrame coneFrame(double aperture_rad, const Vec3& axis, const Vec3& L, const Vec3& V)
{
    ConeFrame f;
    f.axis = axis;
    f.cosPhi = std::cos(aperture_rad);
    f.sinPhi = std::sin(aperture_rad);
    const AxisProjection v = projectOnAxis(axis, V);
    const AxisProjection l = projectOnAxis(axis, L);
    // e1 along V_p puts theta_V at 0; with V on the axis any azimuth serves, L_p is stable.
    if (auto e = safeNormalize(v.perp); e && v.s > 1e-12) {
        f.e1 = *e;
    } else if (auto lp = safeNormalize(l.perp); lp && l.s > 1e-12) {
        f.e1 = *lp;
    } else {
        f.e1 = anyPerpendicular(axis);
    }
    f.e1 = glm::normalize(f.e1 - glm::dot(f.e1, axis) * axis);
    f.e2 = glm::cross(axis, f.e1);
    return f;
}

ConeIntegrals coneIntegrals(double aperture_rad, const Vec3& axis, const Vec3& L, const Vec3& V,
                            double exponent)
{
    const ConeFrame f = coneFrame(aperture_rad, axis, L, V);
    const Harmonic hv = harmonic(f, V), hl = harmonic(f, L);
    ConeIntegrals out;

    // J: s_v(theta) is even in theta (theta_V = 0), so each face is twice a quarter.
    const auto sv = [&](double t) { return sine(hv.at(t)); };
    out.front.J = 2.0 * gaussLegendre8(sv, 0.0, kHalfPi);
    out.rear.J = 2.0 * gaussLegendre8(sv, kHalfPi, kPi);

    // G = (pi/2) int Q + int s_l s_v h(da).
    const double LV = glm::dot(L, V);
    const auto rest = [&](double t) {
        const Vec3 a = f.needle(t);
        const AxisProjection l = projectOnAxis(a, L), v = projectOnAxis(a, V);
        return l.s * v.s * restOfG(angleBetween(l.perp, v.perp));
    };
    out.front.G = kHalfPi * (kPi * LV - productIntegral(hl, hv, +1.0)) +
                  gaussLegendre8(rest, -kHalfPi, 0.0) + gaussLegendre8(rest, 0.0, kHalfPi);
    out.rear.G = kHalfPi * (kPi * LV - productIntegral(hl, hv, -1.0)) +
                 gaussLegendre8(rest, kHalfPi, kPi) + gaussLegendre8(rest, kPi, 1.5 * kPi);
    // Q's exact integral and the rest's quadrature may differ in the last digits where G ~ 0.
    out.front.G = std::max(0.0, out.front.G);
    out.rear.G = std::max(0.0, out.rear.G);

    // S: the lobe s_h^(n-1) peaks where the needle is orthogonal to H, c_h(theta) = 0; see
    // specularFaceIntegrals.
    if (const auto H = safeNormalize(L + V)) {
        const auto [front, rear] = specularFaceIntegrals(hv, harmonic(f, *H), *H, V, exponent);
        out.front.S = front;
        out.rear.S = rear;
    }
    return out;
}

ConeSums coneSums(const ConeGeometry& cone, const ConeIntegrals& in, double exponent)
{
    const double nrl = cone.needlesPerCone * cone.needleRadius_cm * cone.needleLength_cm;
    const double specularScale = nrl / (2.0 * kPi) * std::sqrt(2.0 * kPi / exponent);
    const auto face = [&](const ConeFaceIntegrals& i) {
        return ConeFaceSums{nrl / kPi * i.J, nrl / (4.0 * kPi) * i.G, specularScale * i.S};
    };
    return {face(in.front), face(in.rear)};
}

FaceReflectance meanReflectance(const ConeFaceSums& face)
{
    if (!(face.area > 0.0)) return {};
    return {face.diffuse / face.area, face.specular / face.area};
}

ConeShading shadeCone(const ConeSums& sums, double footprintArea_cm2)
{
    // The face's needles cover the footprint as one needle of their summed area would (eq. 3).
    ConeShading s;
    s.alphaFront = needleOpacity(sums.front.area, footprintArea_cm2);
    s.alphaRear = needleOpacity(sums.rear.area, footprintArea_cm2);
    const FaceReflectance front = meanReflectance(sums.front), rear = meanReflectance(sums.rear);
    s.diffuseFront = s.alphaFront * front.diffuse;
    s.specularFront = s.alphaFront * front.specular;
    s.diffuseRear = s.alphaRear * rear.diffuse;
    s.specularRear = s.alphaRear * rear.specular;
    return s;
}

// ---- printed forms ----

double coneOpacityPrinted(double phi, double phiV)
{
    return kPi * std::cos(phi) * std::cos(phiV) - 2.0 * std::sin(phi) * std::sin(phiV);
}

double coneDiffuseLambdaFit(double aperture_rad, const Vec3& axis, const Vec3& L, const Vec3& V,
                            bool front)
{
    const double phi = aperture_rad;
    const ConeFrame f = coneFrame(aperture_rad, axis, L, V);
    const AxisProjection l = projectOnAxis(axis, L), v = projectOnAxis(axis, V);
    const double phiL = std::atan2(l.s, l.c), phiV = std::atan2(v.s, v.c);
    // The angle between a(theta) and X is largest at the azimuth opposite X_p's.
    const double thetaL = std::atan2(glm::dot(f.e2, L), glm::dot(f.e1, L)) + kPi;
    const double thetaV = kPi;  // V_p lies along e1
    const double AL = std::max(phiL, phi), BL = std::min(phiL, phi);
    const double AV = std::max(phiV, phi), BV = std::min(phiV, phi);
    const double ASigma = AL + AV;
    const double cx = BL * std::cos(thetaL) + BV * std::cos(thetaV);
    const double cy = BL * std::sin(thetaL) + BV * std::sin(thetaV);
    const double BSigma = std::hypot(cx, cy);
    const double thetaM = std::atan2(cy, cx);
    const double M = std::cos(ASigma - BSigma), m = std::cos(ASigma + BSigma);
    const double lambda1 = 0.5 * (m - M);
    const bool crossesPi = ASigma + BSigma > kPi && ASigma - BSigma < kPi;
    const double lambda2 = crossesPi ? lambda1 * BSigma / (4.0 * (2.0 * kPi - ASigma)) : 0.0;
    const double lambda0 = 0.5 * (m + M) - lambda2;
    // int over [c - pi/2, c + pi/2] of cos(theta - thetaM) = 2 cos(c - thetaM); c = 0 or pi.
    const double faceCentre = front ? 0.0 : kPi;
    return kPi * (glm::dot(L, V) - lambda0) - 2.0 * lambda1 * std::cos(faceCentre - thetaM);
}

double coneSpecularPrinted(double aperture_rad, const Vec3& axis, const Vec3& L, const Vec3& V,
                           double exponent, bool front)
{
    const auto H = safeNormalize(L + V);
    if (!H) return 0.0;
    const ConeFrame f = coneFrame(aperture_rad, axis, L, V);
    const Harmonic hh = harmonic(f, *H);
    const double w = std::hypot(hh.p, hh.q);
    if (!(w > 0.0) || std::abs(hh.u) >= w) return 0.0;
    const double thetaH = std::atan2(hh.q, hh.p);
    const double offset = std::acos(std::clamp(-hh.u / w, -1.0, 1.0));
    int eps = 0;
    for (const double root : {thetaH - offset, thetaH + offset}) {
        const bool onFront = std::abs(std::remainder(root, 2.0 * kPi)) <= kHalfPi;
        eps += (onFront == front) ? 1 : 0;
    }
    return eps * std::sqrt(2.0 * kPi / exponent) * std::max(0.0, glm::dot(V, *H));
}

double diffuseFFit(double da)
{
    const double c = std::cos(da);
    return 0.5 * (1.0 + c) * (2.0 + (kPi - 2.0) * c);
}

}  // namespace pine::analytic
