// Rays, boxes and the cylinder tests the cone tracer needs. World cm.
#pragma once

#include <glm/common.hpp>
#include <glm/geometric.hpp>
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

/// A ball holding a primitive (or a node's primitives' balls).
struct Sphere {
    Vec3 centre{0.0};
    double radius = 0.0;
};

/// The ball about a cylinder's middle reaching its ends' rims (segment a-b, radius r).
inline Sphere cylinderSphere(const Vec3& a, const Vec3& b, double radius)
{
    return {0.5 * (a + b), 0.5 * glm::length(b - a) + radius};
}

/// No point of the ball that the cone ray touches lies nearer along the ray than this: the
/// ball's near side, less the footprint's width at its far side (a bound on the half-width
/// any point the footprint touches lies off the ray's axis). It is monotone in the ball: a
/// ball inside another gets no smaller a bound, so a node's bound holds for its primitives.
inline double nearestAlong(const ConeRay& ray, const Sphere& ball)
{
    const double centre = glm::dot(ball.centre - ray.origin, ray.direction);
    return centre - ball.radius - ray.width(std::max(0.0, centre + ball.radius));
}

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

/// The nearest float at or below (above) x: single-precision bounds that still hold x.
inline float roundedDown(double x)
{
    const float f = float(x);
    return double(f) > x ? std::nextafter(f, -std::numeric_limits<float>::infinity()) : f;
}
inline float roundedUp(double x)
{
    const float f = float(x);
    return double(f) < x ? std::nextafter(f, std::numeric_limits<float>::infinity()) : f;
}

/// The ray's interval inside a solid finite cylinder (segment a-b, radius r): false if none.
bool intersectCylinder(const ConeRay& ray, const Vec3& a, const Vec3& b, double radius,
                       double& tIn, double& tOut);

/// Where the ray, from its origin on, enters the same cylinder through its side (t >= 0):
/// false if it meets only an end, or nothing. A needle with open ends (render.needle_ends
/// "open", the ground truth's) stops just such a ray.
bool entersCylinderSide(const ConeRay& ray, const Vec3& a, const Vec3& b, double radius, double& t);

}  // namespace pine::vdbtrace
