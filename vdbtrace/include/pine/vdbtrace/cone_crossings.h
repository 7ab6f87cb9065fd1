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
#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <tuple>
#include <type_traits>

// Packed only where scalar doubles are SSE2's too and nothing fuses a multiply and an add
// (x87's excess precision, or -mfma's contractions of the scalar form, would differ).
#if defined(__SSE2_MATH__) && !defined(__FMA__)
#define PINE_CONE_BANDS_SSE2 1
#include <emmintrin.h>
#endif

namespace pine::vdbtrace {

/// The trigonometry of a cone aperture phi, kept for the last phi this thread asked about: a
/// scene's boughs share one or a few, and every walk through a bough's cones needs them. The
/// cotangent two ways, as the walks have always computed it, so that each gives the same bits.
struct ApertureTrig {
    double phi, sinPhi, cosPhi;
    double cosOverSin;  ///< cos(phi) / sin(phi)
    double oneOverTan;  ///< 1 / tan(phi)
};
inline ApertureTrig apertureTrig(double phi)
{
    thread_local ApertureTrig last{std::numeric_limits<double>::quiet_NaN(), 0.0, 0.0, 0.0, 0.0};
    // The same bits, not the same value: -0 and +0 are equal but their tangents are not.
    if (std::bit_cast<std::uint64_t>(phi) != std::bit_cast<std::uint64_t>(last.phi)) {
        const double s = std::sin(phi), c = std::cos(phi);
        last = ApertureTrig{phi, s, c, c / s, 1.0 / std::tan(phi)};
    }
    return last;
}

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
    return intersectCylinder(ConeRay{o, d, 0.0}, b.base_cm, b.conesEnd(), b.radius_cm, tIn, tOut);
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

/// Where o + t d lies inside the bark, [barkIn, barkOut]: the branch's cylinder of radius
/// barkRadius_cm from the base to the tip (beyond the tip the last cones' needles are not in
/// it); an empty [0, 0] where it does not, or b has no bark.
inline void barkInterval(const TracedBough& b, const Vec3& o, const Vec3& d, double& barkIn,
                         double& barkOut)
{
    barkIn = barkOut = 0.0;
    if (b.barkRadius_cm > 0.0 && !intersectCylinder(ConeRay{o, d, 0.0}, b.base_cm, b.tip_cm,
                                                    b.barkRadius_cm, barkIn, barkOut)) {
        barkIn = barkOut = 0.0;
    }
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
    const double cotPhi = apertureTrig(b.geometry.cone.aperture_rad).oneOverTan;
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

/// A line o + t d (d unit) against bough b's cones: g = h - rho cot(phi) along it, closed
/// form. rho^2 is quadratic in t, so g is concave (g'' = -cot(phi) m^2 |d x axis|^2 / rho^3,
/// m the line's distance from the axis): it rises to one maximum at most and falls after,
/// and a level g = c is met where a quadratic vanishes.
class ConeLine {
public:
    ConeLine(const TracedBough& b, const Vec3& o, const Vec3& d)
        : mCotPhi(apertureTrig(b.geometry.cone.aperture_rad).oneOverTan)
    {
        const Vec3 r0 = o - b.base_cm;
        mH0 = glm::dot(r0, b.axis);
        mAlong = glm::dot(d, b.axis);
        const Vec3 across0 = r0 - mH0 * b.axis, dAcross = d - mAlong * b.axis;
        mQ0 = glm::dot(across0, across0);
        mQ1 = glm::dot(across0, dAcross);
        mQ2 = glm::dot(dAcross, dAcross);
        if (mQ2 > 1e-24) {  // else along the axis: rho is constant
            mClosest = -mQ1 / mQ2;
            mM2 = mQ0 - mQ1 * mQ1 / mQ2;
        }
    }
    double along() const { return mAlong; }  ///< d . axis
    /// rho^2 = q0 + t (2 q1 + t q2).
    double q0() const { return mQ0; }
    double q1() const { return mQ1; }
    double q2() const { return mQ2; }
    double rho(double t) const { return std::sqrt(std::max(0.0, mQ0 + t * (2.0 * mQ1 + t * mQ2))); }
    /// d . (the point's offset from the axis): rho times the radial part of d.
    double radialRate(double t) const { return mQ1 + mQ2 * t; }
    double g(double t) const { return mH0 + t * mAlong - rho(t) * mCotPhi; }
    /// Where the line passes the axis closest, and where it is `rho` from the axis (false if
    /// never), entering and leaving.
    double closest() const { return mClosest; }
    bool within(double rho, double& tIn, double& tOut) const
    {
        if (!(mQ2 > 1e-24) || !(rho * rho > mM2)) return false;
        const double half = std::sqrt((rho * rho - mM2) / mQ2);
        tIn = mClosest - half;
        tOut = mClosest + half;
        return true;
    }
    /// Where g is largest: g rises before it and falls after; +-infinity where g only rises
    /// or only falls (the line steeper along the axis than the cones' generators).
    double turn() const
    {
        constexpr double kInf = std::numeric_limits<double>::infinity();
        if (!(mQ2 > 1e-24)) return mAlong >= 0.0 ? kInf : -kInf;
        const double root = std::sqrt(mQ2);
        // g' = 0 where (t - tc) Q2 / rho = along / cot(phi), rho^2 = m^2 + Q2 (t - tc)^2.
        const double s = mAlong / (mCotPhi * root);
        if (s >= 1.0) return kInf;
        if (s <= -1.0) return -kInf;
        const double m = std::sqrt(std::max(0.0, mM2));
        return mClosest + s * m / (std::sqrt(1.0 - s * s) * root);
    }
    /// The t in [lo, hi] where g = c, g monotone there and between g(lo) and g(hi) c.
    double level(double c, double lo, double hi) const
    {
        // (h0 - c + along t)^2 = cot^2(phi) rho^2, with h0 - c + along t >= 0.
        const double k2 = mCotPhi * mCotPhi, e = mH0 - c;
        const double A = mAlong * mAlong - k2 * mQ2, B = e * mAlong - k2 * mQ1,
                     C = e * e - k2 * mQ0;
        double roots[2];
        int n = 0;
        if (std::abs(A) > 1e-12 * (std::abs(B) + std::abs(C) + 1e-300)) {
            const double q = -(B + std::copysign(std::sqrt(std::max(0.0, B * B - A * C)), B));
            roots[n++] = q / A;
            if (q != 0.0) roots[n++] = C / q;
        } else if (B != 0.0) {
            roots[n++] = -C / (2.0 * B);
        }
        const double slack = 1e-9 * (hi - lo) + 1e-12;
        double best = 0.0, bestMiss = std::numeric_limits<double>::infinity();
        for (int i = 0; i < n; ++i) {
            if (!(roots[i] >= lo - slack && roots[i] <= hi + slack)) continue;
            const double t = std::clamp(roots[i], lo, hi);
            const double miss = std::abs(g(t) - c);
            if (miss < bestMiss) {
                best = t;
                bestMiss = miss;
            }
        }
        if (bestMiss <= 1e-9 * (std::abs(c) + 1.0)) return best;
        // Rounding left no root in reach: bisect the monotone piece.
        const bool rising = g(hi) > g(lo);
        for (int i = 0; i < 100 && hi - lo > 1e-13 * (std::abs(lo) + std::abs(hi) + 1.0); ++i) {
            const double mid = 0.5 * (lo + hi);
            ((g(mid) < c) == rising ? lo : hi) = mid;
        }
        return 0.5 * (lo + hi);
    }

private:
    double mCotPhi, mH0 = 0.0, mAlong = 0.0, mQ0 = 0.0, mQ1 = 0.0, mQ2 = 0.0;
    double mClosest = 0.0;  ///< t where the line passes the axis closest
    double mM2 = 0.0;       ///< the square of its distance there
};

/// Calls visit(band) -> bool (false stops) for every band of cones 0 .. floor(length / dh)
/// along o + t d (d unit), t in [tIn, tOut], in order. `needles` integrates
/// sigma = (needle length per volume) 2 r |d x a| along the band: thin needles placed
/// independently. Needles fan out from the axis, so their length per volume is
/// N / (2 pi rho dh sin(phi)) and their coverage of their cone N r / (pi rho), capped at 1
/// where they overlap near the apex; its mean over the cone is the paper's A = 2 N r / (pi R).
/// A band ends where g crosses a band's edge (g = (j +- 1/2) dh, in closed form) and where g
/// turns (ConeLine), so that a line crossing a cone twice meets its needles twice; sigma is
/// integrated over each band by two-point Gauss-Legendre panels a quarter of a band's g
/// apart at the steepest, finer near the axis (tested against a fine march). Inside the bark
/// (insideBark) the needles' roots are hidden: nothing is counted within it, unless
/// !hiddenInBark (level 1 looks for whole needles, whose roots the branch's own fragment
/// hides). `Packed` false evaluates each Gauss-Legendre point alone, as targets without SSE2
/// do: the same bits, which the tests check.
template <bool Packed = true, class Visit>
void forEachConeBand(const TracedBough& b, const Vec3& o, const Vec3& d, double tIn, double tOut,
                     Visit&& visit, bool hiddenInBark = true)
{
    if (!(tOut > tIn) || !std::isfinite(tIn) || !std::isfinite(tOut)) return;
    const analytic::ConeGeometry& cone = b.geometry.cone;
    const double dh = b.geometry.coneSpacing_cm;
    const ApertureTrig trig = apertureTrig(cone.aperture_rad);
    const double sinPhi = trig.sinPhi, cosPhi = trig.cosPhi, cotPhi = trig.cosOverSin;
    const long jMax = long(std::floor(b.length_cm / dh));
    const double panel = dh / (1.0 + cotPhi);  // |dg/dt| <= 1 + cot(phi)
    const double coverageTimesRho = cone.needlesPerCone * cone.needleRadius_cm / analytic::kPi;
    const double layersPerCm = 1.0 / (dh * sinPhi);  // |grad g| / dh
    const ConeLine line(b, o, d);
    // sigma at o + t d; the needle direction a = cos(phi) axis + sin(phi) radial.
    const auto sigma = [&](double t) {
        const double rho = line.rho(t);
        const double dNeedle =
            rho > 0.0 ? cosPhi * line.along() + sinPhi * line.radialRate(t) / rho : line.along();
        const double coverage = rho > coverageTimesRho ? coverageTimesRho / rho : 1.0;
        return coverage * std::sqrt(std::max(0.0, 1.0 - dNeedle * dNeedle)) * layersPerCm;
    };
    // sigma at a Gauss-Legendre panel's two points at once: each lane the same operations in
    // the same order, so the same bits (a packed square root or division costs what one does,
    // and they are most of the bands' work).
    const auto sigmaPair = [&](double t1, double t2, double out[2]) {
#if defined(PINE_CONE_BANDS_SSE2)
        if constexpr (Packed) {
            const __m128d t = _mm_set_pd(t2, t1), zero = _mm_setzero_pd(), one = _mm_set1_pd(1.0);
            const auto select = [](__m128d mask, __m128d yes, __m128d no) {
                return _mm_or_pd(_mm_and_pd(mask, yes), _mm_andnot_pd(mask, no));
            };
            const __m128d q1 = _mm_set1_pd(line.q1()), q2 = _mm_set1_pd(line.q2());
            // rho(t); std::max(0.0, x) is maxpd(x, 0): 0 for a NaN or -0 x, as it is.
            const __m128d rho = _mm_sqrt_pd(_mm_max_pd(
                _mm_add_pd(
                    _mm_set1_pd(line.q0()),
                    _mm_mul_pd(t, _mm_add_pd(_mm_set1_pd(2.0 * line.q1()), _mm_mul_pd(t, q2)))),
                zero));
            const __m128d rate = _mm_add_pd(q1, _mm_mul_pd(q2, t));  // radialRate(t)
            const __m128d along = _mm_set1_pd(line.along());
            const __m128d dNeedle =
                select(_mm_cmpgt_pd(rho, zero),
                       _mm_add_pd(_mm_set1_pd(cosPhi * line.along()),
                                  _mm_div_pd(_mm_mul_pd(_mm_set1_pd(sinPhi), rate), rho)),
                       along);
            const __m128d cover = _mm_set1_pd(coverageTimesRho);
            const __m128d coverage = select(_mm_cmpgt_pd(rho, cover), _mm_div_pd(cover, rho), one);
            const __m128d across =
                _mm_sqrt_pd(_mm_max_pd(_mm_sub_pd(one, _mm_mul_pd(dNeedle, dNeedle)), zero));
            _mm_storeu_pd(out, _mm_mul_pd(_mm_mul_pd(coverage, across), _mm_set1_pd(layersPerCm)));
            return;
        }
#endif
        out[0] = sigma(t1);
        out[1] = sigma(t2);
    };
    double barkIn = 0.0, barkOut = 0.0;
    if (hiddenInBark) barkInterval(b, o, d, barkIn, barkOut);
    // Where sigma has kinks, panels end: where the line passes the axis (the radial
    // direction turns over) and where the needles' coverage reaches 1 near it.
    double kinks[3] = {line.closest(), 0.0, 0.0};
    int nKinks = 1;
    if (line.within(coverageTimesRho, kinks[1], kinks[2])) nKinks = 3;
    double needles = 0.0, weightedT = 0.0;
    // Adds sigma's integral (and t sigma's) over [x, y], outside the bark.
    const auto integrate = [&](double x, double y) {
        // Panels no wider than half the distance from the axis at their near end, where
        // sigma goes as 1 / rho (two-point Gauss-Legendre then errs by 1.4e-4 at most).
        const auto smooth = [&](double lo, double hi) {
            double rho0 = line.rho(lo);
            for (double t0 = lo; t0 < hi;) {
                double h = std::min(panel, hi - t0);
                if (rho0 < 2.0 * panel) {  // |d rho / dt| <= 1
                    const double nearest = std::min(rho0, line.rho(t0 + h));
                    h = std::min(h, std::max(0.5 * nearest, 0.05 * coverageTimesRho));
                    if (hi - (t0 + h) < 1e-9 * h) h = hi - t0;
                }
                const double mid = t0 + 0.5 * h, offset = 0.5 * h / std::sqrt(3.0);
                const double points[2] = {mid - offset, mid + offset};
                double sigmas[2];
                sigmaPair(points[0], points[1], sigmas);
                for (int k = 0; k < 2; ++k) {
                    const double s = 0.5 * h * sigmas[k];
                    needles += s;
                    weightedT += s * points[k];
                }
                t0 += h;
                rho0 = rho0 < 3.0 * panel ? line.rho(t0) : rho0 - h;  // a bound below
            }
        };
        const auto panels = [&](double lo, double hi) {
            for (int i = 0; i < nKinks; ++i) {
                if (kinks[i] > lo && kinks[i] < hi) {
                    smooth(lo, kinks[i]);
                    lo = kinks[i];
                }
            }
            smooth(lo, hi);
        };
        if (barkOut > barkIn && barkIn < y && barkOut > x) {
            panels(x, std::min(y, barkIn));
            panels(std::max(x, barkOut), y);
        } else {
            panels(x, y);
        }
    };
    // Ends the current band; false when the visitor wants no more.
    long band = long(std::floor(line.g(tIn) / dh + 0.5));
    const auto finish = [&]() {
        bool more = true;
        if (needles > 0.0 && band >= 0 && band <= jMax) {
            more = visit(ConeBand{band, weightedT / needles, needles});
        }
        needles = weightedT = 0.0;
        return more;
    };
    // The monotone pieces of g: rising up to its turn, falling after.
    const double turn = line.turn();
    const double cut = std::clamp(turn, tIn, tOut);
    for (const auto& [from, to, direction] : {std::tuple{tIn, cut, 1}, std::tuple{cut, tOut, -1}}) {
        if (!(to > from)) continue;
        double t0 = from;
        const double gEnd = line.g(to);
        for (int guard = 0; guard < 1000000; ++guard) {
            const double edge = (double(band) + 0.5 * direction) * dh;
            if ((gEnd - edge) * direction < 0.0) {  // the piece ends within this band
                integrate(t0, to);
                break;
            }
            const double t1 = line.level(edge, t0, to);
            integrate(t0, t1);
            if (!finish()) return;
            band += direction;
            t0 = t1;
        }
        if (!finish()) return;  // g turned, or the line ends
    }
}

}  // namespace pine::vdbtrace
