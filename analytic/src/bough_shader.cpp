#include "pine/analytic/bough_shader.h"

#include "pine/analytic/quadrature.h"

#include <glm/geometric.hpp>

#include <algorithm>
#include <cmath>
#include <limits>

namespace pine::analytic {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

// rate x length, where a zero length crosses no layer even at an infinite rate.
double layers(double rate, double length) { return length > 0.0 ? rate * length : 0.0; }

// Gauss-Legendre on [a, b] in `panels` equal panels of 8 nodes.
template <class F>
double glPanels(F&& f, double a, double b, int panels)
{
    double sum = 0.0;
    const double h = (b - a) / panels;
    for (int i = 0; i < panels; ++i) sum += gaussLegendre8(f, a + i * h, a + (i + 1) * h);
    return sum;
}

}  // namespace

double layerRate(double aperture_rad, double c, double s)
{
    const double sinPhi = std::sin(aperture_rad);
    if (!(s > 0.0) || !(sinPhi > 0.0)) return kInf;
    return std::abs(std::cos(aperture_rad) * s - sinPhi * c) / (sinPhi * s);
}

double layerRateMirror(double aperture_rad, double c, double s)
{
    return layerRate(aperture_rad, -c, s);
}

BoughView boughView(double aperture_rad, const Vec3& axis, const Vec3& L, const Vec3& V)
{
    const AxisProjection v = projectOnAxis(axis, V), l = projectOnAxis(axis, L);
    BoughView b;
    b.kV = layerRate(aperture_rad, v.c, v.s);
    b.kVbar = layerRateMirror(aperture_rad, v.c, v.s);
    b.kL = layerRate(aperture_rad, l.c, l.s);
    b.kLbar = layerRateMirror(aperture_rad, l.c, l.s);
    // l_v is undefined when L or V runs along the branch; cos = 0 is its mean over azimuths.
    b.cosLV = (v.s > 1e-9 && l.s > 1e-9) ? std::cos(angleBetween(l.perp, v.perp)) : 0.0;
    return b;
}

BoughLinearLaw boughLinearLaw(const BoughGeometry& bough, const BoughView& view)
{
    BoughLinearLaw law;
    const double A = layerOpacity(bough.cone), R = boughRadius(bough.cone);
    if (!(A * R > 0.0)) return law;  // no needles or no volume: transparent
    law.a = 0.25 * kPi * A * R / bough.coneSpacing_cm;
    law.alphaUnclamped = law.a * (view.kV + view.kVbar);

    // The front half hides the rear: alpha_F + alpha_R <= 1 keeps the total a coverage.
    const auto clampPair = [&](double k, double kbar) {
        const double front = std::min(1.0, law.a * k);
        return FrontRear{front, std::clamp(law.a * kbar, 0.0, 1.0 - front)};
    };
    law.alphaView = clampPair(view.kV, view.kVbar);
    law.alphaLight = clampPair(view.kL, view.kLbar);

    // Section 6.6, with k-bar_V in the rear terms where sections 6.4-6.5 print k_V.
    const double c = view.cosLV, s = 8.0 / (3.0 * kPi * kPi);
    const auto brackets = [&](double fv, double rv, double fl, double rl) {
        return FrontRear{1.0 - s * (2.0 * fv + (1.0 - c) * rl + (3.0 - c) * fl),
                         1.0 - s * (4.0 * fv + 2.0 * rv + (1.0 + c) * rl + (3.0 + c) * fl)};
    };
    const FrontRear& v = law.alphaView;
    const FrontRear& l = law.alphaLight;
    const FrontRear kept = brackets(v.front, v.rear, l.front, l.rear);
    law.transfer = {v.front * std::clamp(kept.front, 0.0, 1.0),
                    v.rear * std::clamp(kept.rear, 0.0, 1.0)};
    const double fv = law.a * view.kV, rv = law.a * view.kVbar;
    const FrontRear raw = brackets(fv, rv, law.a * view.kL, law.a * view.kLbar);
    law.transferUnclamped = {fv * raw.front, rv * raw.rear};
    return law;
}

BoughExact boughExact(const BoughGeometry& bough, const BoughView& view, bool shadows)
{
    BoughExact out;
    const double A = layerOpacity(bough.cone), R = boughRadius(bough.cone);
    if (!(A * R > 0.0)) return out;
    const double mu = -std::log1p(-A);  // optical depth of one layer; +inf when A = 1
    const double scale = R / bough.coneSpacing_cm;
    // Layers per unit of normalised projected length (unit disk) for each half and ray.
    const double nuV = layers(view.kV, scale), nuVbar = layers(view.kVbar, scale);
    const double nuL = layers(view.kL, scale), nuLbar = layers(view.kLbar, scale);
    const auto transmittance = [&](double n) { return n > 0.0 ? std::exp(-mu * n) : 1.0; };
    // Where the bough is dense, only a skin of optical depth ~1 is lit or seen: its thickness,
    // 1 / (mu nu) of the radius, sets how finely the rule must sample (2 to 8 panels of 8
    // nodes on each piece).
    const double sharpness = A < 1.0 ? mu * std::max({nuV, nuVbar, shadows ? nuL : 0.0,
                                                      shadows ? nuLbar : 0.0}) : 0.0;
    const int panels =
        std::isfinite(sharpness) ? std::clamp(int(std::ceil(sharpness / 6.0)), 2, 8) : 8;

    // Unit-disk frame: zeta along V_p (towards the viewer), xi across; e_l at angle l_v.
    const double cl = view.cosLV, sl = std::sqrt(std::max(0.0, 1.0 - cl * cl));
    const auto shadowTransmittance = [&](double zeta, double xi) {
        if (!shadows) return 1.0;
        const double u = zeta * cl + xi * sl;   // along L_p, towards the light
        const double w = -zeta * sl + xi * cl;  // across L_p
        const double half = std::sqrt(std::max(0.0, 1.0 - w * w));
        const double n = u >= 0.0 ? layers(nuL, half - u)
                                  : layers(nuL, half) + layers(nuLbar, -u);
        return transmittance(n);
    };
    // A chord at offset xi = sin(t) has half-length rho = cos(t); dxi = cos(t) dt.
    // Along its front half, with optical depth s = mu nuV (rho - zeta) from the entry,
    // tau = 1 - exp(-s) runs over [0, 1 - T^(nuV rho)] and d tau = mu nuV T^(...) dzeta.
    const auto zetaAt = [&](double tau, double nu) {
        const double depth = -std::log1p(-tau) / mu;  // layers crossed
        return std::isinf(nu) ? 0.0 : depth / nu;
    };
    // The shadow chord changes halves (a kink in T_L) where u = 0: zeta = -xi sin / cos(l_v).
    // Gauss-Legendre is split there, mapped to tau.
    const auto tauOf = [&](double depthFromEntry, double nu) {
        return 1.0 - transmittance(layers(nu, depthFromEntry));
    };
    const auto splitAt = [&](auto&& f, double end, double kinkTau) {
        if (kinkTau > 0.0 && kinkTau < end) {
            return glPanels(f, 0.0, kinkTau, panels) + glPanels(f, kinkTau, end, panels);
        }
        return glPanels(f, 0.0, end, panels);
    };
    const auto chord = [&](double t, bool wantAlpha, bool rear) {
        const double xi = std::sin(t), rho = std::cos(t);
        const double frontAlpha = 1.0 - transmittance(layers(nuV, rho));
        const double rearAlpha = 1.0 - transmittance(layers(nuVbar, rho));
        const double kink = std::abs(cl) > 1e-12 ? -xi * sl / cl : 2.0;  // outside if none
        double value;
        if (wantAlpha) {
            value = rear ? (1.0 - frontAlpha) * rearAlpha : frontAlpha;
        } else if (!rear) {
            const double kinkTau = kink > 0.0 && kink < rho ? tauOf(rho - kink, nuV) : -1.0;
            value = frontAlpha <= 0.0 ? 0.0 : splitAt([&](double tau) {
                return shadowTransmittance(rho - zetaAt(tau, nuV), xi);
            }, frontAlpha, kinkTau);
        } else {
            const double kinkTau = kink < 0.0 && kink > -rho ? tauOf(-kink, nuVbar) : -1.0;
            value = rearAlpha <= 0.0 ? 0.0 : (1.0 - frontAlpha) * splitAt([&](double tau) {
                return shadowTransmittance(-zetaAt(tau, nuVbar), xi);
            }, rearAlpha, kinkTau);
        }
        return 0.5 * value * rho;  // the mean over xi in [-1, 1] is half the integral
    };
    // One rule over the chords for all four, so that without shadows each transfer equals its
    // opacity to the last digit. The kink line enters or leaves a half chord at xi = 0 and
    // xi = +-|cos l_v|: the rule is split there.
    constexpr double kHalfPi = 0.5 * kPi;
    const double edge = std::asin(std::min(1.0, std::abs(cl)));
    const double cuts[] = {-kHalfPi, -edge, 0.0, edge, kHalfPi};
    const auto overChords = [&](bool wantAlpha, bool rear) {
        double sum = 0.0;
        for (int i = 0; i < 4; ++i) {
            if (cuts[i + 1] > cuts[i]) {
                sum += glPanels([&](double t) { return chord(t, wantAlpha, rear); }, cuts[i],
                                cuts[i + 1], panels);
            }
        }
        return sum;
    };
    out.alpha = {overChords(true, false), overChords(true, true)};
    out.transfer = {overChords(false, false), overChords(false, true)};
    // The rule integrates an opaque strip to 1 within rounding (1 + 2^-52 was seen): kept in
    // the physical bounds, each half's transfer within its opacity.
    out.alpha.front = std::clamp(out.alpha.front, 0.0, 1.0);
    out.alpha.rear = std::clamp(out.alpha.rear, 0.0, 1.0 - out.alpha.front);
    out.transfer.front = std::clamp(out.transfer.front, 0.0, out.alpha.front);
    out.transfer.rear = std::clamp(out.transfer.rear, 0.0, out.alpha.rear);
    return out;
}

SweptAreas sweptAreas(double c)
{
    return {1.0 - c / 3.0, (1.0 - c) / 3.0, 1.0 + c / 3.0, (1.0 + c) / 3.0};
}

}  // namespace pine::analytic
