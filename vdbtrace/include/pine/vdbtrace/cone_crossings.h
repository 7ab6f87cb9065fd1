// Where a line crosses the true cones of a bough (paper section 3.1, errata E12): cone j is the
// surface g = h - rho cot(phi) = j dh, h along the branch from its base, rho the distance from
// it. Shared by the multiscale levels 1-2 (the cones a view ray meets) and their
// self-shadowing (the layers a ray to the light crosses).
#pragma once

#include "pine/vdbtrace/traced_scene.h"

#include <glm/geometric.hpp>

#include <algorithm>
#include <cmath>

namespace pine::vdbtrace {

/// g = h - rho cot(phi) at a point of bough b, with rho and the unit radial direction (zero
/// on the axis).
inline double coneHeight(const TracedBough& b, double cotPhi, const Vec3& x, double* rho = nullptr,
                         Vec3* radial = nullptr)
{
    const Vec3 r = x - b.base_cm;
    const double h = glm::dot(r, b.axis);
    const Vec3 across = r - h * b.axis;
    const double d = glm::length(across);
    if (rho) *rho = d;
    if (radial) *radial = d > 0.0 ? across / d : Vec3(0.0);
    return h - d * cotPhi;
}

/// Calls visit(j, t) for every crossing of cone j in [0, floor(length / dh)] by the line
/// o + t d, t in [tIn, tOut], in order: the march moves g by at most dh / 4 a step (|dg/dt|
/// <= 1 + cot(phi)) and places each crossing by linear interpolation within its step.
template <class Visit>
void forEachConeCrossing(const TracedBough& b, const Vec3& o, const Vec3& d, double tIn,
                         double tOut, Visit&& visit)
{
    const double dh = b.geometry.coneSpacing_cm;
    const double cotPhi = 1.0 / std::tan(b.geometry.cone.aperture_rad);
    const long jMax = long(std::floor(b.length_cm / dh));
    const double dt = dh / (4.0 * (1.0 + cotPhi));
    double t0 = tIn, g0 = coneHeight(b, cotPhi, o + t0 * d);
    int steps = 0;
    while (t0 < tOut && steps++ < 100000) {
        const double t1 = std::min(t0 + dt, tOut), g1 = coneHeight(b, cotPhi, o + t1 * d);
        const long j0 = long(std::floor(g0 / dh)), j1 = long(std::floor(g1 / dh));
        for (long j = std::min(j0, j1) + 1; j <= std::max(j0, j1); ++j) {
            if (j < 0 || j > jMax) continue;
            visit(j, t0 + (double(j) * dh - g0) / (g1 - g0) * (t1 - t0));
        }
        t0 = t1;
        g0 = g1;
    }
}

}  // namespace pine::vdbtrace
