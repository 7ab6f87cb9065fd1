#include "pine/vdbtrace/ground_hit.h"

#include <glm/geometric.hpp>

#include <algorithm>
#include <cmath>

namespace pine::vdbtrace {

bool hitGround(const scenes::Ground& g, const ConeRay& ray, double& t, Vec3& normal)
{
    using Kind = scenes::Ground::Kind;
    if (g.kind == Kind::None) return false;
    if (g.kind == Kind::Plane) {
        if (ray.direction.z >= -1e-12) return false;
        t = (g.height_cm - ray.origin.z) / ray.direction.z;
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
    double a = 0.0, fa = below(a);
    if (fa <= 0.0) return false;  // the eye is under the ground
    for (double b = step; b < 1e8; b += step) {
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
        fa = fb;
    }
    return false;
}

}  // namespace pine::vdbtrace
