// Where a line meets a cone's needles, exactly (the "arcs" layer model, docs/models.md
// "Crossing arcs"): cone j's N needles are the segments from its apex along
// cos(phi) axis + sin(phi) radial(psi), psi = roll + k P (P = 2 pi / N), l long, r thick. The
// needle at azimuth psi meets the line o + t d where some point of it lies within r of the
// needle's axis. A point at height u above the apex, rho from the axis and azimuth psi_L
// projects onto that needle's axis at w = u cos(phi) + rho sin(phi) cos(psi - psi_L), and lies
// within r of the segment iff w > w_r, w_r = sqrt(u^2 + rho^2 - r^2) where that is at most l
// (beside the needle) and (u^2 + rho^2 + l^2 - r^2) / (2 l) past it (near its tip). So the
// point meets the needles at |psi - psi_L| < delta, cos(delta) = (w_r - u cos(phi)) /
// (rho sin(phi)), and the line, over a passage where it stays near the cone's sheet, the union
// of those intervals: one arc, [min(psi_L - delta), max(psi_L + delta)], as psi_L and delta
// vary continuously along it. The line misses the cone's needles where no psi = roll + k P
// falls in the arcs of all its passages: over a uniform roll, with probability 1 - |union of
// the arcs taken modulo P| / P.
//
// The fibre model's bands (cone_crossings.h) smear each cone's needles over dh and stop a
// line with probability min(1, n) a band: near the axis, where a line grazes narrow, dense
// cones, that is 20-50% more opaque than the needles (scripts/fibre_middle_study.py); the arcs
// are the needles' own expectation.
#pragma once

#include "pine/vdbtrace/cone_crossings.h"

#include <algorithm>
#include <cmath>

namespace pine::vdbtrace {

/// A line's passage within a needle's radius of cone j's sheet (|g - j dh| sin(phi) < r), and
/// the arc of needle azimuths whose needles it meets there: a needle of cone j at azimuth psi
/// (radians about the axis, from e1 towards e2 = axis x e1) meets the line iff psi lies in
/// [from, from + width] modulo 2 pi. width is in [0, 2 pi]; above the needle period 2 pi / N
/// the cone is surely hit.
struct ConeArc {
    long cone = 0;
    double t = 0.0;  ///< where the line passes the arc's middle azimuth (its needles' mean)
    double from = 0.0, width = 0.0;
};

/// The arc of cone j's needles the line meets over the passage t in [ta, tb] (ConeArc), from
/// points evenly over it, each extreme refined by a golden-section search between its best
/// point's neighbours (cone_arcs.cpp). False if no point of it lies within r of a needle.
bool coneArc(const TracedBough& b, const ConeLine& line, const Vec3& o, const Vec3& d,
             const Vec3& e1, const Vec3& e2, long j, double ta, double tb, ConeArc& out);

/// Calls visit(arc) -> bool (false stops) for every passage of o + t d (d unit), t in
/// [tIn, tOut], near a sheet of cones 0 .. floor(length / dh), in order along the line: the
/// rising piece of g cone by cone upwards, the falling one downwards (ConeLine), a passage
/// over g's turn once. Passages inside the bark (insideBark) are cut out of the line: the
/// needles' roots there are hidden.
template <class Visit>
void forEachConeArc(const TracedBough& b, const Vec3& o, const Vec3& d, double tIn, double tOut,
                    const Vec3& e1, const Vec3& e2, Visit&& visit)
{
    if (!(tOut > tIn) || !std::isfinite(tIn) || !std::isfinite(tOut)) return;
    const double dh = b.geometry.coneSpacing_cm;
    const double slab = b.geometry.cone.needleRadius_cm /
                        apertureTrig(b.geometry.cone.aperture_rad).sinPhi;  // in g
    const long jMax = long(std::floor(b.length_cm / dh));
    const ConeLine line(b, o, d);
    double barkIn, barkOut;
    barkInterval(b, o, d, barkIn, barkOut);
    // One passage [from, to] of cone j, less what lies in the bark.
    const auto pass = [&](long j, double from, double to) {
        const auto arc = [&](double a, double z) {
            ConeArc out;
            return !(z > a) || !coneArc(b, line, o, d, e1, e2, j, a, z, out) || visit(out);
        };
        if (barkOut > barkIn && barkIn < to && barkOut > from) {
            return arc(from, std::min(to, barkIn)) && arc(std::max(from, barkOut), to);
        }
        return arc(from, to);
    };
    const double cut = std::clamp(line.turn(), tIn, tOut);
    const double gIn = line.g(tIn), gCut = line.g(cut), gOut = line.g(tOut);
    // The cones whose slab [c - slab, c + slab] a piece from g = lo to g = hi enters.
    const auto lowest = [&](double lo) {
        return std::max(0L, long(std::floor((lo - slab) / dh)) + 1);
    };
    const auto highest = [&](double hi) {
        return std::min(jMax, long(std::ceil((hi + slab) / dh)) - 1);
    };
    long skipOnFall = -1;  // a cone whose passage ran over the turn, visited with the rising
    if (cut > tIn) {
        const long top = highest(gCut);
        for (long j = lowest(gIn); j <= top; ++j) {
            const double c = double(j) * dh;
            const double from = gIn >= c - slab ? tIn : line.level(c - slab, tIn, cut);
            double to = gCut <= c + slab ? cut : line.level(c + slab, tIn, cut);
            if (to >= cut && cut < tOut) {  // on over the turn, down the falling piece
                to = gOut >= c - slab ? tOut : line.level(c - slab, cut, tOut);
                skipOnFall = j;
            }
            if (!pass(j, from, to)) return;
        }
    }
    if (cut < tOut) {
        for (long j = highest(gCut); j >= lowest(gOut); --j) {
            if (j == skipOnFall) continue;
            const double c = double(j) * dh;
            const double from = gCut <= c + slab ? cut : line.level(c + slab, cut, tOut);
            const double to = gOut >= c - slab ? tOut : line.level(c - slab, cut, tOut);
            if (!pass(j, from, to)) return;
        }
    }
}

}  // namespace pine::vdbtrace
