#include "pine/analytic/needle_shader.h"

#include <glm/geometric.hpp>

#include <algorithm>
#include <cmath>

namespace pine::analytic {

double diffuseG(double da) { return std::sin(da) + (kPi - da) * std::cos(da); }

double needleDiffuse(const Vec3& axis, const Vec3& L, const Vec3& V)
{
    const AxisProjection l = projectOnAxis(axis, L);
    const AxisProjection v = projectOnAxis(axis, V);
    const double da = angleBetween(l.perp, v.perp);  // delta-alpha in [0, pi]
    return 0.25 * l.s * diffuseG(da);
}

double needleSpecular(const Vec3& axis, const Vec3& L, const Vec3& V, double exponent)
{
    const auto H = safeNormalize(L + V);
    if (!H) return 0.0;
    const AxisProjection h = projectOnAxis(axis, *H);
    const AxisProjection v = projectOnAxis(axis, V);
    const double shsv = h.s * v.s;
    if (shsv <= 0.0) return 0.0;
    // cos(alpha_H - alpha_V) = H_p . V_p / (s_h s_v), clamped (see header).
    const double cosHV = std::clamp(glm::dot(h.perp, v.perp) / shsv, 0.0, 1.0);
    // The lobe's integral, sqrt(2 pi / n) by Laplace, never above pi's (see header).
    const double lobe = exponent >= 2.0 / kPi ? std::sqrt(2.0 * kPi / exponent) : kPi;
    return 0.5 * std::pow(h.s, exponent) * cosHV * lobe;
}

double needleProjectedArea(const Vec3& axis, const Vec3& V, double radius_cm, double length_cm)
{
    return 2.0 * radius_cm * length_cm * projectOnAxis(axis, V).s;
}

double needleOpacity(double projectedArea_cm2, double footprintArea_cm2)
{
    if (projectedArea_cm2 <= 0.0) return 0.0;
    if (footprintArea_cm2 <= projectedArea_cm2) return 1.0;
    return projectedArea_cm2 / footprintArea_cm2;
}

}  // namespace pine::analytic
