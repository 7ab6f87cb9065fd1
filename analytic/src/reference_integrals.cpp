#include "pine/analytic/reference_integrals.h"

#include "pine/analytic/needle_shader.h"
#include "pine/analytic/quadrature.h"

#include <glm/geometric.hpp>

#include <algorithm>
#include <cmath>

namespace pine::analytic::reference {
namespace {

constexpr double kHalfPi = 0.5 * kPi;

// The cylinder's outward normal at angle alpha around `axis`.
struct CylinderNormals {
    Vec3 e1, e2;
    explicit CylinderNormals(const Vec3& axis)
        : e1(anyPerpendicular(axis)), e2(glm::cross(axis, e1)) {}
    Vec3 at(double alpha) const { return std::cos(alpha) * e1 + std::sin(alpha) * e2; }
};

// Integral over the circle of angles, on equal panels (each adaptive), so that narrow lobes
// are sampled.
double circleIntegral(const std::function<double(double)>& f, double from, double to,
                      int panels)
{
    double sum = 0.0;
    const double h = (to - from) / panels;
    for (int i = 0; i < panels; ++i) {
        sum += integrateAdaptive(f, from + i * h, from + (i + 1) * h, 1e-14, 1e-11);
    }
    return sum;
}

double positive(double x) { return x > 0.0 ? x : 0.0; }

}  // namespace

double needleDiffuse(const Vec3& axis, const Vec3& L, const Vec3& V)
{
    const CylinderNormals n(axis);
    const double num = circleIntegral(
        [&](double a) { return positive(glm::dot(n.at(a), L)) * positive(glm::dot(n.at(a), V)); },
        0.0, 2.0 * kPi, 64);
    const double den =
        circleIntegral([&](double a) { return positive(glm::dot(n.at(a), V)); }, 0.0, 2.0 * kPi, 64);
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
        0.0, 2.0 * kPi, 512);
    const double den =
        circleIntegral([&](double a) { return positive(glm::dot(n.at(a), V)); }, 0.0, 2.0 * kPi, 64);
    return den > 0.0 ? num / den : 0.0;
}

double needleProjectedArea(const Vec3& axis, const Vec3& V, double radius_cm, double length_cm)
{
    const CylinderNormals n(axis);
    return radius_cm * length_cm *
           circleIntegral([&](double a) { return positive(glm::dot(n.at(a), V)); }, 0.0,
                          2.0 * kPi, 64);
}

ConeIntegrals coneIntegrals(double aperture_rad, const Vec3& axis, const Vec3& L, const Vec3& V,
                            double exponent)
{
    const ConeFrame f = coneFrame(aperture_rad, axis, L, V);
    const auto sv = [&](double t) { return projectOnAxis(f.needle(t), V).s; };
    const auto g = [&](double t) { return 4.0 * sv(t) * analytic::needleDiffuse(f.needle(t), L, V); };
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
    const double cl = view.cosLV, sl = std::sqrt(std::max(0.0, 1.0 - cl * cl));

    // Layers crossed from (zeta, xi) to the light, straight from the definition: walk the
    // shadow chord's light half and, if inside, its far half.
    const auto shadowLayers = [&](double zeta, double xi) {
        if (!shadows) return 0.0;
        const double u = zeta * cl + xi * sl, w = -zeta * sl + xi * cl;
        const double half = std::sqrt(std::max(0.0, 1.0 - w * w));
        return u >= 0.0 ? nuL * (half - u) : nuL * half + nuLbar * (-u);
    };
    const auto viewLayers = [&](double zeta, double rho) {
        return zeta >= 0.0 ? nuV * (rho - zeta) : nuV * rho + nuVbar * (-zeta);
    };
    const auto overXi = [&](const std::function<double(double)>& perChord) {
        return 0.5 * integrateAdaptive(perChord, -1.0, 1.0, 1e-11, 1e-9);
    };
    const auto overZeta = [&](const std::function<double(double)>& f, double a, double b,
                              double split) {
        // Split where the shadow chord changes halves (a kink) if it falls inside.
        if (split > a && split < b) {
            return integrateAdaptive(f, a, split, 1e-12, 1e-10) +
                   integrateAdaptive(f, split, b, 1e-12, 1e-10);
        }
        return integrateAdaptive(f, a, b, 1e-12, 1e-10);
    };
    out.alpha.front = overXi([&](double xi) {
        const double rho = std::sqrt(std::max(0.0, 1.0 - xi * xi));
        return 1.0 - std::exp(-mu * nuV * rho);
    });
    out.alpha.rear = overXi([&](double xi) {
        const double rho = std::sqrt(std::max(0.0, 1.0 - xi * xi));
        return std::exp(-mu * nuV * rho) * (1.0 - std::exp(-mu * nuVbar * rho));
    });
    for (const bool front : {true, false}) {
        const double density = mu * (front ? nuV : nuVbar);  // emission per unit length
        (front ? out.transfer.front : out.transfer.rear) = overXi([&](double xi) {
            const double rho = std::sqrt(std::max(0.0, 1.0 - xi * xi));
            const double split = std::abs(cl) > 1e-12 ? -xi * sl / cl : 2.0;
            const auto f = [&](double zeta) {
                return density * std::exp(-mu * (viewLayers(zeta, rho) + shadowLayers(zeta, xi)));
            };
            return front ? overZeta(f, 0.0, rho, split) : overZeta(f, -rho, 0.0, split);
        });
    }
    return out;
}

SweptAreas sweptAreas(double cosLV)
{
    const double cl = cosLV, sl = std::sqrt(std::max(0.0, 1.0 - cl * cl));
    // Shadow-chord lengths within the light's front (u > 0 side) and rear halves.
    const auto inFront = [&](double zeta, double xi) {
        const double u = zeta * cl + xi * sl, w = -zeta * sl + xi * cl;
        const double half = std::sqrt(std::max(0.0, 1.0 - w * w));
        return u >= 0.0 ? half - u : half;
    };
    const auto inRear = [&](double zeta, double xi) {
        const double u = zeta * cl + xi * sl;
        return u >= 0.0 ? 0.0 : -u;
    };
    const auto region = [&](auto length, bool viewFront) {
        return integrateAdaptive(
            [&](double xi) {
                const double rho = std::sqrt(std::max(0.0, 1.0 - xi * xi));
                const double a = viewFront ? 0.0 : -rho, b = viewFront ? rho : 0.0;
                const double split = std::abs(cl) > 1e-12 ? -xi * sl / cl : 2.0;
                const auto f = [&](double zeta) { return length(zeta, xi); };
                if (split > a && split < b) {
                    return integrateAdaptive(f, a, split, 1e-13) + integrateAdaptive(f, split, b, 1e-13);
                }
                return integrateAdaptive(f, a, b, 1e-13);
            },
            -1.0, 1.0, 1e-11);
    };
    return {region(inFront, true), region(inRear, true), region(inFront, false),
            region(inRear, false)};
}

}  // namespace pine::analytic::reference
