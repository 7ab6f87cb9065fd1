// A bough's outer radius and its cone and needle counts (paper section 3.1).
#include "pine/scenes/tree.h"

#include <glm/geometric.hpp>

#include <algorithm>
#include <cmath>

namespace pine::scenes {
namespace {

// R = l sin(phi) (section 3.1).
double boughRadiusAt(const Bough& b, double t)
{
    const NeedleParameters p = lerp(b.atBase, b.atTip, t);
    return p.length_cm * std::sin(p.aperture_rad);
}

// Integral over t in [0, 1] of N(t) / dh(t), both linear in t.
double needlesPerLength(const NeedleParameters& a, const NeedleParameters& b)
{
    const double d0 = a.coneSpacing_cm, dd = b.coneSpacing_cm - a.coneSpacing_cm;
    const double n0 = a.perCone, dn = b.perCone - a.perCone;
    if (std::abs(dd) <= 0.01 * d0) {
        // Nearly constant spacing: the integrand is smooth and far from its pole, so 8-point
        // Gauss-Legendre is exact to rounding (and exact for constant spacing).
        static constexpr double x[4] = {0.1834346424956498, 0.5255324099163290,
                                        0.7966664774136267, 0.9602898564975363};
        static constexpr double w[4] = {0.3626837833783620, 0.3137066458778873,
                                        0.2223810344533745, 0.1012285362903763};
        double sum = 0.0;
        for (int i = 0; i < 4; ++i) {
            for (double s : {-x[i], x[i]}) {
                const double t = 0.5 * (1.0 + s);
                sum += w[i] * (n0 + t * dn) / (d0 + t * dd);
            }
        }
        return 0.5 * sum;
    }
    // (n0 + t dn) / (d0 + t dd) = dn/dd + (n0 - d0 dn/dd) / (d0 + t dd).
    const double slope = dn / dd;
    return slope + (n0 - d0 * slope) * std::log1p(dd / d0) / dd;
}

}  // namespace

double Bough::radius_cm() const
{
    // R(t) = l(t) sin(phi(t)) with l linear and phi in (0, pi/2]: both factors are log-concave,
    // so R is unimodal on [0, 1] and a ternary search finds its largest value.
    double lo = 0.0, hi = 1.0;
    for (int i = 0; i < 80; ++i) {
        const double a = lo + (hi - lo) / 3.0, b = hi - (hi - lo) / 3.0;
        if (boughRadiusAt(*this, a) < boughRadiusAt(*this, b)) {
            lo = a;
        } else {
            hi = b;
        }
    }
    return std::max({boughRadiusAt(*this, 0.0), boughRadiusAt(*this, 1.0),
                     boughRadiusAt(*this, 0.5 * (lo + hi))});
}

double Bough::coneCount(double length_cm) const
{
    NeedleParameters one = atBase, oneTip = atTip;
    one.perCone = oneTip.perCone = 1.0;  // one "needle" per cone counts the cones
    return length_cm * needlesPerLength(one, oneTip);
}

double Bough::needleCount(double length_cm) const
{
    return coneCount(length_cm) * wholeNeedles(lerp(atBase, atTip, 0.5).perCone);
}

TreeCounts Tree::counts() const
{
    TreeCounts c;
    for (const Segment& s : segments) {
        if (s.order >= 1) ++c.branches;
    }
    c.boughs = boughs.size();
    for (const Bough& b : boughs) {
        const Segment& s = segments.at(b.segment);
        const double length = glm::length(s.tip_cm - s.base_cm);
        c.cones += b.coneCount(length);
        c.needles += b.needleCount(length);
    }
    return c;
}

}  // namespace pine::scenes
