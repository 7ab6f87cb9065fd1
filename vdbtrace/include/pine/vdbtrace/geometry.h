// Rays, boxes and the cylinder tests the cone tracer needs. World cm.
#pragma once

#include <glm/common.hpp>
#include <glm/vec3.hpp>

#include <algorithm>
#include <cmath>
#include <limits>

namespace pine::vdbtrace {

using Vec3 = glm::dvec3;

/// A cone ray: apex `origin`, unit `direction`, and `spread`: the footprint's width grows by
/// `spread` cm per cm of distance (the pixel's angular size).
struct ConeRay {
    Vec3 origin{0.0}, direction{0.0, 0.0, 1.0};
    double spread = 0.0;
    double width(double t) const { return spread * t; }  ///< footprint width at distance t
};

struct Aabb {
    Vec3 lo{std::numeric_limits<double>::infinity()};
    Vec3 hi{-std::numeric_limits<double>::infinity()};
    void grow(const Vec3& p) { lo = glm::min(lo, p); hi = glm::max(hi, p); }
    void grow(const Aabb& b) { lo = glm::min(lo, b.lo); hi = glm::max(hi, b.hi); }
    Vec3 centre() const { return 0.5 * (lo + hi); }
    bool valid() const { return lo.x <= hi.x; }
};

/// Box of a cylinder (segment a-b, radius r), conservatively.
Aabb cylinderBounds(const Vec3& a, const Vec3& b, double radius);

/// Where a cone ray passes a finite thin cylinder (segment a-b, radius r): closest approach of
/// the ray's axis to the cylinder's, its distance `t` along the ray, the distance `gap` between
/// the two axes, and where on the segment (`s` in [0, 1]). False when the closest point lies
/// behind the ray or beyond the segment's ends, or when the axes are parallel.
struct Passage {
    double t = 0.0, gap = 0.0, s = 0.0;
};
bool closestPassage(const ConeRay& ray, const Vec3& a, const Vec3& b, Passage& out);

/// The fraction of a footprint of width w that a strip of half-width `halfWidth` at signed
/// offset `gap` from the footprint's centre covers (1D, across the strip): the anti-aliased
/// coverage of a long cylinder seen in a pixel.
inline double stripCoverage(double gap, double halfWidth, double w)
{
    if (!(w > 0.0)) return std::abs(gap) < halfWidth ? 1.0 : 0.0;
    const double overlap = std::min(gap + halfWidth, 0.5 * w) - std::max(gap - halfWidth, -0.5 * w);
    return std::clamp(overlap / w, 0.0, 1.0);
}

/// The ray's interval inside a solid finite cylinder (segment a-b, radius r): false if none.
bool intersectCylinder(const ConeRay& ray, const Vec3& a, const Vec3& b, double radius,
                       double& tIn, double& tOut);

}  // namespace pine::vdbtrace
