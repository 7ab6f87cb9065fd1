#include "pine/analytic/direction.h"

#include <glm/geometric.hpp>

#include <algorithm>
#include <cmath>
#include <limits>

namespace pine::analytic {

AxisProjection projectOnAxis(const Vec3& axis, const Vec3& dir)
{
    AxisProjection p;
    p.c = glm::dot(axis, dir);
    p.s = std::min(1.0, glm::length(glm::cross(axis, dir)));
    p.perp = dir - p.c * axis;
    return p;
}

std::optional<Vec3> safeNormalize(const Vec3& v)
{
    const double len = glm::length(v);
    if (!std::isfinite(len) || len < std::numeric_limits<double>::min() * 1e4) {
        return std::nullopt;
    }
    return v / len;
}

std::optional<Vec3> normalizeGiven(const Vec3& v)
{
    if (!std::isfinite(v.x) || !std::isfinite(v.y) || !std::isfinite(v.z)) return std::nullopt;
    const double largest = std::max({std::abs(v.x), std::abs(v.y), std::abs(v.z)});
    if (!(largest > 0.0)) return std::nullopt;
    const Vec3 scaled = v / largest;  // its largest component is +-1: no under- or overflow
    return scaled / glm::length(scaled);
}

double angleBetween(const Vec3& a, const Vec3& b)
{
    return std::atan2(glm::length(glm::cross(a, b)), glm::dot(a, b));
}

Vec3 anyPerpendicular(const Vec3& axis)
{
    // Cross with the world axis least aligned with `axis`: never parallel, so never zero.
    const Vec3 a = glm::abs(axis);
    const Vec3 pick = (a.x <= a.y && a.x <= a.z) ? Vec3(1, 0, 0)
                      : (a.y <= a.z)             ? Vec3(0, 1, 0)
                                                 : Vec3(0, 0, 1);
    return glm::normalize(glm::cross(axis, pick));
}

}  // namespace pine::analytic
