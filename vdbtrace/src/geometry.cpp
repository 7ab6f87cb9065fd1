#include "pine/vdbtrace/geometry.h"

#include <glm/geometric.hpp>

#include <cmath>

namespace pine::vdbtrace {

Aabb cylinderBounds(const Vec3& a, const Vec3& b, double radius)
{
    Aabb box;
    box.grow(a);
    box.grow(b);
    box.lo -= Vec3(radius);
    box.hi += Vec3(radius);
    return box;
}

bool closestPassage(const ConeRay& ray, const Vec3& a, const Vec3& b, Passage& out)
{
    const Vec3 axis = b - a;
    const double length = glm::length(axis);
    if (!(length > 0.0)) return false;
    const Vec3 u = axis / length;
    const Vec3 w0 = ray.origin - a;
    const double du = glm::dot(ray.direction, u);
    const double denom = 1.0 - du * du;
    if (denom < 1e-12) return false;  // parallel: the strip model does not apply
    const double dw = glm::dot(ray.direction, w0), uw = glm::dot(u, w0);
    const double t = (du * uw - dw) / denom;
    const double s = (uw - du * dw) / denom;  // along the segment, in cm
    if (t < 0.0 || s < 0.0 || s > length) return false;
    const Vec3 gap = (ray.origin + t * ray.direction) - (a + s * u);
    out = {t, glm::length(gap), s / length};
    return true;
}

namespace {

// The ray against the infinite cylinder about segment a-b, |(o + t d - a) x u| = r, as
// A t^2 + B t + C = 0; m = o - a. False for a segment or radius of no size.
struct AboutAxis {
    Vec3 u, m;
    double length, A, B, C;
};

bool aboutAxis(const ConeRay& ray, const Vec3& a, const Vec3& b, double radius, AboutAxis& q)
{
    const Vec3 axis = b - a;
    q.length = glm::length(axis);
    if (!(q.length > 0.0) || !(radius > 0.0)) return false;
    q.u = axis / q.length;
    q.m = ray.origin - a;
    const Vec3 dp = ray.direction - glm::dot(ray.direction, q.u) * q.u;
    const Vec3 mp = q.m - glm::dot(q.m, q.u) * q.u;
    q.A = glm::dot(dp, dp);
    q.B = 2.0 * glm::dot(dp, mp);
    q.C = glm::dot(mp, mp) - radius * radius;
    return true;
}

}  // namespace

bool intersectCylinder(const ConeRay& ray, const Vec3& a, const Vec3& b, double radius,
                       double& tIn, double& tOut)
{
    AboutAxis c;
    if (!aboutAxis(ray, a, b, radius, c)) return false;
    const Vec3 &u = c.u, &m = c.m;
    const double length = c.length, A = c.A, B = c.B, C = c.C;
    double t0 = -std::numeric_limits<double>::infinity(),
           t1 = std::numeric_limits<double>::infinity();
    if (A > 1e-300) {
        const double disc = B * B - 4.0 * A * C;
        if (disc < 0.0) return false;
        const double q = std::sqrt(disc);
        t0 = (-B - q) / (2.0 * A);
        t1 = (-B + q) / (2.0 * A);
    } else if (C > 0.0) {
        return false;  // parallel to the axis and outside
    }
    // End caps: the slab 0 <= (x - a).u <= length.
    const double du = glm::dot(ray.direction, u), mu = glm::dot(m, u);
    if (std::abs(du) > 1e-300) {
        double s0 = (0.0 - mu) / du, s1 = (length - mu) / du;
        if (s0 > s1) std::swap(s0, s1);
        t0 = std::max(t0, s0);
        t1 = std::min(t1, s1);
    } else if (mu < 0.0 || mu > length) {
        return false;
    }
    t0 = std::max(t0, 0.0);
    if (t0 > t1) return false;
    tIn = t0;
    tOut = t1;
    return true;
}

bool entersCylinderSide(const ConeRay& ray, const Vec3& a, const Vec3& b, double radius, double& t)
{
    AboutAxis q;
    if (!aboutAxis(ray, a, b, radius, q)) return false;
    if (!(q.A > 1e-300)) return false;  // along the axis: never through the side
    const double disc = q.B * q.B - 4.0 * q.A * q.C;
    if (disc < 0.0) return false;
    const double t0 = (-q.B - std::sqrt(disc)) / (2.0 * q.A);  // into the infinite cylinder
    if (t0 < 0.0) return false;
    const double s = glm::dot(q.m, q.u) + t0 * glm::dot(ray.direction, q.u);
    if (s < 0.0 || s > q.length) return false;
    t = t0;
    return true;
}

}  // namespace pine::vdbtrace
