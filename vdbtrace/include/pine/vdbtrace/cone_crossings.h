// Where a line crosses the true cones of a bough (paper section 3.1, errata E12): cone j is the
// surface g = h - rho cot(phi) = j dh, h along the branch from its base, rho the distance from
// it. Two ways to walk a line through them: its crossings of each cone (the paper's layer
// model) and its bands, where it passes each cone's needles (level 1's needle search and the
// fibre layer model). Shared by the multiscale levels 1-2, their self-shadowing and the exact
// bough law.
#pragma once

#include "pine/vdbtrace/traced_scene.h"

#include <glm/geometric.hpp>

#include <algorithm>
#include <cmath>
#include <type_traits>

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

/// The interval of o + t d inside the region bough b's cones fill, as levels 1-2 and the layer
/// models see it: the cylinder of radius R from the base to the cones' end. False if none.
inline bool layeredInterval(const TracedBough& b, const Vec3& o, const Vec3& d, double& tIn,
                            double& tOut)
{
    return intersectCylinder(ConeRay{o, d, 0.0}, b.base_cm, b.conesEnd_cm, b.radius_cm, tIn, tOut);
}

/// Whether x lies inside the bark of bough b's branch: within barkRadius_cm of the axis,
/// between the base and the tip.
inline bool insideBark(const TracedBough& b, const Vec3& x)
{
    if (!(b.barkRadius_cm > 0.0)) return false;
    const Vec3 r = x - b.base_cm;
    const double h = glm::dot(r, b.axis);
    return h >= 0.0 && h <= b.length_cm &&
           glm::length(r - h * b.axis) < b.barkRadius_cm;
}

/// Calls visit(j, t) for every crossing of cone j in [0, floor(length / dh)] by the line
/// o + t d, t in [tIn, tOut], in order: the march moves g by at most dh / 4 a step (|dg/dt|
/// <= 1 + cot(phi)) and places each crossing by linear interpolation within its step.
/// Crossings inside the bark (insideBark) are not visited. A visit that returns bool ends
/// the walk by returning false.
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
            const double t = t0 + (double(j) * dh - g0) / (g1 - g0) * (t1 - t0);
            if (insideBark(b, o + t * d)) continue;  // hidden
            if constexpr (std::is_same_v<std::invoke_result_t<Visit, long, double>, bool>) {
                if (!visit(j, t)) return;
            } else {
                visit(j, t);
            }
        }
        t0 = t1;
        g0 = g1;
    }
}

/// Where a line passes cone j's needles (the fibre layer model, errata E13): one band is the
/// part of the line nearer cone j than any other (|g - j dh| < dh / 2) on one monotone piece of
/// g, so that a line crossing a cone twice meets its needles twice, at two azimuths, and a line
/// tangent to a cone meets them once, over the finite length the curvature allows.
struct ConeBand {
    long cone = 0;
    double t = 0.0;        ///< the needle-weighted mean of t over the band
    double needles = 0.0;  ///< expected number of cone j's needles the line hits there
};

/// Calls visit(band) -> bool (false stops) for every band of cones 0 .. floor(length / dh)
/// along o + t d (d unit), t in [tIn, tOut], in order. `needles` integrates
/// sigma = (needle length per volume) 2 r |d x a| along the band: thin needles placed
/// independently. Needles fan out from the axis, so their length per volume is
/// N / (2 pi rho dh sin(phi)) and their coverage of their cone N r / (pi rho), capped at 1
/// where they overlap near the apex; its mean over the cone is the paper's A = 2 N r / (pi R).
/// The same march as forEachConeCrossing; each step's needles are split between the bands it
/// spans in proportion to g. Inside the bark (insideBark) the needles' roots are hidden: the
/// march steps to the bark's surface and counts nothing within it, unless !hiddenInBark (level
/// 1 looks for whole needles, whose roots the branch's own fragment hides).
template <class Visit>
void forEachConeBand(const TracedBough& b, const Vec3& o, const Vec3& d, double tIn, double tOut,
                     Visit&& visit, bool hiddenInBark = true)
{
    const analytic::ConeGeometry& cone = b.geometry.cone;
    const double dh = b.geometry.coneSpacing_cm;
    const double sinPhi = std::sin(cone.aperture_rad), cosPhi = std::cos(cone.aperture_rad);
    const double cotPhi = cosPhi / sinPhi;
    const long jMax = long(std::floor(b.length_cm / dh));
    const double dt = dh / (4.0 * (1.0 + cotPhi));
    const double coverageTimesRho = cone.needlesPerCone * cone.needleRadius_cm / analytic::kPi;
    const double layersPerCm = 1.0 / (dh * sinPhi);  // |grad g| / dh
    // g and sigma at o + t d. Along the line h and the offset from the axis are linear in t;
    // |d x a| = sqrt(1 - (d . a)^2) for the needle direction a = cos(phi) axis + sin(phi)
    // radial.
    const Vec3 r0 = o - b.base_cm;
    const double h0 = glm::dot(r0, b.axis), dAlong = glm::dot(d, b.axis);
    const Vec3 across0 = r0 - h0 * b.axis, dAcross = d - dAlong * b.axis;
    const auto at = [&](double t, double& g, double& sigma) {
        const Vec3 across = across0 + t * dAcross;
        const double rho = glm::length(across);
        g = h0 + t * dAlong - rho * cotPhi;
        const double dNeedle =
            rho > 0.0 ? cosPhi * dAlong + sinPhi * glm::dot(d, across) / rho : dAlong;
        const double coverage = rho > coverageTimesRho ? coverageTimesRho / rho : 1.0;
        sigma = coverage * std::sqrt(std::max(0.0, 1.0 - dNeedle * dNeedle)) * layersPerCm;
    };
    const auto bandOf = [&](double g) { return long(std::floor(g / dh + 0.5)); };
    // Where the line lies inside the bark: the branch's cylinder of radius barkRadius_cm
    // from the base to the tip (beyond the tip the last cones' needles are not in it). Its
    // needles there are hidden; the march steps to the bark's surface, so that each step lies
    // wholly in or out of it.
    double barkIn = 0.0, barkOut = 0.0;
    if (hiddenInBark && b.barkRadius_cm > 0.0 &&
        !intersectCylinder(ConeRay{o, d, 0.0}, b.base_cm, b.tip_cm, b.barkRadius_cm, barkIn,
                           barkOut)) {
        barkIn = barkOut = 0.0;
    }

    double t0 = tIn, g0, s0;
    at(t0, g0, s0);
    long band = bandOf(g0);
    double needles = 0.0, weightedT = 0.0;
    int direction = 0;
    // Ends the current band; false when the visitor wants no more.
    const auto finish = [&]() {
        bool more = true;
        if (needles > 0.0 && band >= 0 && band <= jMax) {
            more = visit(ConeBand{band, weightedT / needles, needles});
        }
        needles = weightedT = 0.0;
        return more;
    };
    int steps = 0;
    while (t0 < tOut && steps++ < 100000) {
        double t1 = std::min(t0 + dt, tOut);
        for (const double edge : {barkIn, barkOut}) {
            if (edge > t0 && edge < t1) t1 = edge;
        }
        double g1, s1;
        at(t1, g1, s1);
        const int stepDirection = g1 > g0 ? 1 : (g1 < g0 ? -1 : direction);
        if (direction != 0 && stepDirection != direction && !finish()) return;  // g turned
        direction = stepDirection;
        const double middle = 0.5 * (t0 + t1);
        const bool inBark = middle > barkIn && middle < barkOut;
        const double count = inBark ? 0.0 : 0.5 * (s0 + s1) * (t1 - t0);
        double done = 0.0;  // fraction of the step already given to a band
        while (bandOf(g1) != band && direction != 0) {
            const double boundary = (double(band) + 0.5 * direction) * dh;
            const double f = std::clamp((boundary - g0) / (g1 - g0), done, 1.0);
            needles += (f - done) * count;
            weightedT += (f - done) * count * (t0 + 0.5 * (done + f) * (t1 - t0));
            if (!finish()) return;
            band += direction;
            done = f;
        }
        needles += (1.0 - done) * count;
        weightedT += (1.0 - done) * count * (t0 + 0.5 * (done + 1.0) * (t1 - t0));
        t0 = t1;
        g0 = g1;
        s0 = s1;
    }
    finish();
}

}  // namespace pine::vdbtrace
