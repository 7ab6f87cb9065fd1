#include "pine/vdbtrace/ground_hit.h"

#include <glm/geometric.hpp>

#include <algorithm>
#include <cmath>
#include <limits>

namespace pine::vdbtrace {
namespace {

// Where the ray's axis meets the plane z = height_cm, or -1 where it does not go down.
double toBasePlane(const scenes::Ground& g, const ConeRay& ray)
{
    return ray.direction.z < -1e-12 ? (g.height_cm - ray.origin.z) / ray.direction.z : -1.0;
}

}  // namespace

bool hitGround(const scenes::Ground& g, const ConeRay& ray, double& t, Vec3& normal)
{
    using Kind = scenes::Ground::Kind;
    if (g.kind == Kind::None) return false;
    if (g.kind == Kind::Plane) {
        t = toBasePlane(g, ray);
        normal = Vec3(0, 0, 1);
        return t > 0.0;
    }
    // Hill: march until the ray is below the surface, then bisect.
    const auto below = [&](double s) {
        const Vec3 p = ray.origin + s * ray.direction;
        return p.z - g.heightAt(p.x, p.y);
    };
    const double top = g.height_cm + g.hillPeak_cm;
    if (ray.origin.z > top && ray.direction.z >= 0.0) return false;
    const double step = std::max(1.0, 0.05 * g.hillRadius_cm);
    if (below(0.0) <= 0.0) return false;  // the eye is under the ground
    // Beyond kReach radii of its centre the hill stands peak e^-32 (1e-14 of it) above its
    // base: the ray meets that ground as the plane, in closed form, and only its stretch within
    // reach is marched (a hill a centimetre wide and ten kilometres high took 41 s at 32 x 24,
    // marched a centimetre a step along every ray climbing to its top). The march keeps its
    // steps' places, so a hit within reach is the one it was.
    constexpr double kReach = 8.0, kNever = std::numeric_limits<double>::infinity();
    const double reach = kReach * g.hillRadius_cm;
    const scenes::Vec2 o(ray.origin.x - g.hillCentre_cm.x, ray.origin.y - g.hillCentre_cm.y);
    const scenes::Vec2 d(ray.direction.x, ray.direction.y);
    const double dd = glm::dot(d, d), od = glm::dot(o, d), oo = glm::dot(o, o);
    double enter = 0.0, leave = kNever;  // along the ray, within reach
    if (dd > 0.0) {
        const double disc = od * od - dd * (oo - reach * reach);
        if (disc > 0.0) {
            enter = std::max(0.0, (-od - std::sqrt(disc)) / dd);
            leave = (-od + std::sqrt(disc)) / dd;
        } else {
            leave = -1.0;
        }
    } else if (!(oo < reach * reach)) {
        leave = -1.0;
    }
    const auto plane = [&](double from, double to) {
        const double s = toBasePlane(g, ray);
        if (!(s >= from && s < to)) return false;
        t = s;
        normal = Vec3(0, 0, 1);
        return true;
    };
    if (!(leave > enter)) return plane(0.0, kNever);
    if (plane(0.0, enter)) return true;
    double a = std::max(0.0, std::floor(enter / step) * step);
    for (double b = a + step; b < 1e8 && a < leave; b += step) {
        const double fb = below(b);
        if (fb <= 0.0) {
            for (int i = 0; i < 40; ++i) {
                const double m = 0.5 * (a + b);
                (below(m) > 0.0 ? a : b) = m;
            }
            t = b;
            const Vec3 p = ray.origin + t * ray.direction;
            const double h = 1e-3 * g.hillRadius_cm;
            const double dx = (g.heightAt(p.x + h, p.y) - g.heightAt(p.x - h, p.y)) / (2 * h);
            const double dy = (g.heightAt(p.x, p.y + h) - g.heightAt(p.x, p.y - h)) / (2 * h);
            normal = glm::normalize(Vec3(-dx, -dy, 1.0));
            return true;
        }
        // Past the hill's top going up, or far below it: nothing to hit.
        const Vec3 p = ray.origin + b * ray.direction;
        if ((p.z > top && ray.direction.z >= 0.0) || p.z < g.height_cm - 1e4) return false;
        a = b;
    }
    // The march gave up (1e8 cm) before leaving the hill's reach: nothing seen past it.
    return a >= leave && plane(leave, kNever);
}

}  // namespace pine::vdbtrace
