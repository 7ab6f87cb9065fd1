#include "pine/analytic/true_cone_bough.h"

#include "pine/analytic/quadrature.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

namespace pine::analytic {

double trueConeLayers(const BoughGeometry& bough, double cosPhiV, double sinPhiV, double u)
{
    const double R = boughRadius(bough.cone);
    if (!(R > 0.0)) return 0.0;
    if (!(sinPhiV > 0.0)) return std::numeric_limits<double>::infinity();
    const double a = cosPhiV / sinPhiV, b = 1.0 / std::tan(bough.cone.aperture_rad);
    const double c = std::sqrt(std::max(0.0, 1.0 - u * u));  // half chord
    const auto f = [&](double Y) { return -a * Y - b * std::sqrt(u * u + Y * Y); };
    double variation = std::abs(f(c) - f(-c));
    if (std::abs(a) < b) {
        const double s = a / b;
        const double yStar = -s * std::abs(u) / std::sqrt(1.0 - s * s);
        if (yStar > -c && yStar < c) {
            variation = std::abs(f(-c) - f(yStar)) + std::abs(f(c) - f(yStar));
        }
    }
    return variation * R / bough.coneSpacing_cm;
}

double trueConeOpacity(const BoughGeometry& bough, double cosPhiV, double sinPhiV)
{
    const double A = layerOpacity(bough.cone), R = boughRadius(bough.cone);
    if (!(A * R > 0.0)) return 0.0;
    if (!(sinPhiV > 0.0) || A >= 1.0) return 1.0;
    const double mu = -std::log1p(-A);
    // With u = sin(t) the chord's half-length cos(t) is smooth at the bough's edge, where
    // sqrt(1 - u^2) is not; the mean over u in [-1, 1] is int_0^(pi/2) T(sin t) cos t dt.
    const auto transparency = [&](double t) {
        return std::exp(-mu * trueConeLayers(bough, cosPhiV, sinPhiV, std::sin(t))) * std::cos(t);
    };
    const double a = cosPhiV / sinPhiV, b = 1.0 / std::tan(bough.cone.aperture_rad);
    const double edge = std::abs(a) < b ? std::asin(std::sqrt(1.0 - (a * a) / (b * b))) : 0.5 * kPi;
    double mean = 0.0;
    for (const auto& [lo, hi] : {std::pair{0.0, edge}, std::pair{edge, 0.5 * kPi}}) {
        if (hi > lo) mean += gaussLegendre8(transparency, lo, 0.5 * (lo + hi)) +
                             gaussLegendre8(transparency, 0.5 * (lo + hi), hi);
    }
    return 1.0 - mean;
}

}  // namespace pine::analytic
