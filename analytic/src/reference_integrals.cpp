#include "pine/analytic/reference_integrals.h"

#include "pine/analytic/needle_shader.h"
#include "pine/analytic/quadrature.h"

#include <glm/geometric.hpp>

#include <algorithm>
#include <cmath>
#include <utility>
#include <vector>

namespace pine::analytic::reference {
namespace {

constexpr double kHalfPi = 0.5 * kPi;

// The cylinder's outward normal at angle alpha around `axis`.
struct CylinderNormals {
    Vec3 e1, e2;
    explicit CylinderNormals(const Vec3& axis)
        : e1(anyPerpendicular(axis)), e2(glm::cross(axis, e1)) {}
    Vec3 at(double alpha) const { return std::cos(alpha) * e1 + std::sin(alpha) * e2; }
    /// The two angles in [0, 2 pi) where N . X = 0: the kinks of (N . X)+.
    std::vector<double> terminator(const Vec3& X) const
    {
        const double a = std::atan2(glm::dot(X, e2), glm::dot(X, e1));
        return {std::fmod(a + 2.5 * kPi, 2 * kPi), std::fmod(a + 3.5 * kPi, 2 * kPi)};
    }
};

// Integral over [from, to] on equal panels (each adaptive) so that narrow lobes are sampled,
// with the panels also cut at the given kinks.
double circleIntegral(const std::function<double(double)>& f, double from, double to,
                      int panels, const std::vector<double>& kinks = {})
{
    std::vector<double> points;
    for (int i = 0; i <= panels; ++i) points.push_back(from + (to - from) * i / panels);
    for (const double k : kinks) {
        if (k > from && k < to) points.push_back(k);
    }
    return integrateAdaptive(f, points, 1e-14, 1e-11);
}

double positive(double x) { return x > 0.0 ? x : 0.0; }

// The unit cross-section disk, in the frame of the view: zeta along V_p (towards the viewer),
// xi across it; L_p at angle l_v from V_p. A shadow chord from (zeta, xi) runs along L_p.
struct DiskFrame {
    double cl, sl;  // cos and sin of l_v
    explicit DiskFrame(double cosLV)
        : cl(cosLV), sl(std::sqrt(std::max(0.0, 1.0 - cosLV * cosLV))) {}
    double along(double zeta, double xi) const { return zeta * cl + xi * sl; }    // u
    double across(double zeta, double xi) const { return -zeta * sl + xi * cl; }  // w
    /// Shadow-chord lengths from (zeta, xi) within the light's front and rear halves.
    std::pair<double, double> shadowLengths(double zeta, double xi) const
    {
        const double u = along(zeta, xi), w = across(zeta, xi);
        const double half = std::sqrt(std::max(0.0, 1.0 - w * w));
        return u >= 0.0 ? std::pair{half - u, 0.0} : std::pair{half, -u};
    }
    /// The zeta on chord xi where the shadow chord changes halves (u = 0): a kink.
    double kink(double xi) const { return std::abs(cl) > 1e-12 ? -xi * sl / cl : 2.0; }
    /// Chord offsets where that kink enters or leaves a half chord: kinks of the outer integral.
    std::vector<double> chordBreaks() const
    {
        return {-1.0, -std::abs(cl), 0.0, std::abs(cl), 1.0};
    }
};

double halfChordRho(double xi) { return std::sqrt(std::max(0.0, 1.0 - xi * xi)); }

// Integral over the view's front (zeta in [0, rho]) or rear half of chord xi, split at the
// shadow kink when it falls inside.
double overHalfChord(const std::function<double(double)>& f, const DiskFrame& disk, double xi,
                     bool front, double absTol)
{
    const double rho = halfChordRho(xi);
    const double a = front ? 0.0 : -rho, b = front ? rho : 0.0, k = disk.kink(xi);
    if (k > a && k < b)
        return integrateAdaptive(f, a, k, absTol) + integrateAdaptive(f, k, b, absTol);
    return integrateAdaptive(f, a, b, absTol);
}

// Layers crossed by the view ray from its entry to (zeta, on a chord of half-length rho).
double viewLayers(double zeta, double rho, double nuV, double nuVbar)
{
    return zeta >= 0.0 ? nuV * (rho - zeta) : nuV * rho + nuVbar * (-zeta);
}

}  // namespace

double needleDiffuse(const Vec3& axis, const Vec3& L, const Vec3& V)
{
    const CylinderNormals n(axis);
    std::vector<double> kinks = n.terminator(L);
    for (const double k : n.terminator(V)) kinks.push_back(k);
    const double num = circleIntegral(
        [&](double a) { return positive(glm::dot(n.at(a), L)) * positive(glm::dot(n.at(a), V)); },
        0.0, 2.0 * kPi, 64, kinks);
    const double den = circleIntegral([&](double a) { return positive(glm::dot(n.at(a), V)); },
                                      0.0, 2.0 * kPi, 64, n.terminator(V));
    return den > 0.0 ? num / den : 0.0;
}

double needleSpecular(const Vec3& axis, const Vec3& L, const Vec3& V, double exponent)
{
    const auto H = safeNormalize(L + V);
    if (!H) return 0.0;
    const CylinderNormals n(axis);
    const double num = circleIntegral(
        [&](double a) {
            const double nh = positive(glm::dot(n.at(a), *H));
            return nh > 0.0 ? std::pow(nh, exponent) * positive(glm::dot(n.at(a), V)) : 0.0;
        },
        0.0, 2.0 * kPi, 512, n.terminator(V));
    const double den = circleIntegral([&](double a) { return positive(glm::dot(n.at(a), V)); },
                                      0.0, 2.0 * kPi, 64, n.terminator(V));
    return den > 0.0 ? num / den : 0.0;
}

double needleProjectedArea(const Vec3& axis, const Vec3& V, double radius_cm, double length_cm)
{
    const CylinderNormals n(axis);
    return radius_cm * length_cm *
           circleIntegral([&](double a) { return positive(glm::dot(n.at(a), V)); }, 0.0,
                          2.0 * kPi, 64, n.terminator(V));
}

ConeIntegrals coneIntegrals(double aperture_rad, const Vec3& axis, const Vec3& L, const Vec3& V,
                            double exponent)
{
    const ConeFrame f = coneFrame(aperture_rad, axis, L, V);
    const auto sv = [&](double t) { return projectOnAxis(f.needle(t), V).s; };
    const auto g = [&](double t) {
        return 4.0 * sv(t) * analytic::needleDiffuse(f.needle(t), L, V);
    };
    const auto s = [&](double t) {
        return 2.0 * sv(t) * analytic::needleSpecular(f.needle(t), L, V, exponent) /
               std::sqrt(2.0 * kPi / exponent);
    };
    ConeIntegrals out;
    for (const bool front : {true, false}) {
        const double from = front ? -kHalfPi : kHalfPi;
        ConeFaceIntegrals& face = front ? out.front : out.rear;
        face.J = circleIntegral(sv, from, from + kPi, 64);
        face.G = circleIntegral(g, from, from + kPi, 64);
        face.S = circleIntegral(s, from, from + kPi, 256);
    }
    return out;
}

double coneLambdaFitIntegral(double aperture_rad, const Vec3& axis, const Vec3& L, const Vec3& V,
                             bool front)
{
    const ConeFrame f = coneFrame(aperture_rad, axis, L, V);
    const double LV = glm::dot(L, V);
    const auto P = [&](double t) {
        const Vec3 a = f.needle(t);
        const AxisProjection l = projectOnAxis(a, L), v = projectOnAxis(a, V);
        return LV + l.s * v.s - l.c * v.c;
    };
    const double from = front ? -kHalfPi : kHalfPi;
    return circleIntegral(P, from, from + kPi, 64);
}

BoughExact boughExact(const BoughGeometry& bough, const BoughView& view, bool shadows)
{
    BoughExact out;
    const double A = layerOpacity(bough.cone), R = boughRadius(bough.cone);
    if (!(A * R > 0.0)) return out;
    const double mu = -std::log1p(-A);
    const double scale = R / bough.coneSpacing_cm;
    const double nuV = view.kV * scale, nuVbar = view.kVbar * scale;
    const double nuL = view.kL * scale, nuLbar = view.kLbar * scale;
    const DiskFrame disk(view.cosLV);
    const auto overXi = [&](const std::function<double(double)>& perChord) {
        return 0.5 * integrateAdaptive(perChord, disk.chordBreaks(), 1e-12, 1e-10);
    };
    out.alpha.front = overXi([&](double xi) {
        return 1.0 - std::exp(-mu * nuV * halfChordRho(xi));
    });
    out.alpha.rear = overXi([&](double xi) {
        const double rho = halfChordRho(xi);
        return std::exp(-mu * nuV * rho) * (1.0 - std::exp(-mu * nuVbar * rho));
    });
    for (const bool front : {true, false}) {
        const double density = mu * (front ? nuV : nuVbar);  // emission per unit length
        (front ? out.transfer.front : out.transfer.rear) = overXi([&](double xi) {
            const double rho = halfChordRho(xi);
            const auto f = [&](double zeta) {
                const auto [inFront, inRear] = disk.shadowLengths(zeta, xi);
                const double nL = shadows ? nuL * inFront + nuLbar * inRear : 0.0;
                return density * std::exp(-mu * (viewLayers(zeta, rho, nuV, nuVbar) + nL));
            };
            return overHalfChord(f, disk, xi, front, 1e-12);
        });
    }
    return out;
}

FrontRear boughLinearized(const BoughGeometry& bough, const BoughView& view)
{
    const double A = layerOpacity(bough.cone), R = boughRadius(bough.cone);
    if (!(A * R > 0.0)) return {};
    const double scale = R / bough.coneSpacing_cm;
    const double nuV = view.kV * scale, nuVbar = view.kVbar * scale;
    const double nuL = view.kL * scale, nuLbar = view.kLbar * scale;
    const DiskFrame disk(view.cosLV);
    FrontRear out;
    for (const bool front : {true, false}) {
        // Emission A per layer crossed, nu layers per unit length: A nu per unit length; the
        // mean over the chords' offsets xi in [-1, 1] is half the integral.
        const double density = A * (front ? nuV : nuVbar);
        (front ? out.front : out.rear) = 0.5 * integrateAdaptive(
            [&](double xi) {
                const double rho = halfChordRho(xi);
                const auto f = [&](double zeta) {
                    const auto [inFront, inRear] = disk.shadowLengths(zeta, xi);
                    const double nL = nuL * inFront + nuLbar * inRear;
                    return density * (1.0 - A * viewLayers(zeta, rho, nuV, nuVbar) - A * nL);
                };
                return overHalfChord(f, disk, xi, front, 1e-13);
            },
            disk.chordBreaks(), 1e-12);
    }
    return out;
}

SweptAreas sweptAreas(double cosLV)
{
    const DiskFrame disk(cosLV);
    const auto region = [&](bool lightFront, bool viewFront) {
        return integrateAdaptive(
            [&](double xi) {
                const auto f = [&](double zeta) {
                    const auto lengths = disk.shadowLengths(zeta, xi);
                    return lightFront ? lengths.first : lengths.second;
                };
                return overHalfChord(f, disk, xi, viewFront, 1e-13);
            },
            disk.chordBreaks(), 1e-12);
    };
    return {region(true, true), region(false, true), region(true, false), region(false, false)};
}

}  // namespace pine::analytic::reference
