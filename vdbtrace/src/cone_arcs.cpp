// The arc of one passage (cone_arcs.h): psi_L and delta sampled over it.
#include "pine/vdbtrace/cone_arcs.h"

#include "pine/analytic/direction.h"

#include <glm/geometric.hpp>

#include <limits>

namespace pine::vdbtrace {
namespace {

// Points a passage first: nine evenly, then each extreme by a golden-section search between
// its best point's neighbours (a transverse crossing's delta rises as a half ellipse, with
// infinite slopes at the passage's ends; a line near the axis sweeps psi_L fast). Six steps
// place a cone's share of the period within 8e-4 of a dense search's, the search's own
// resolution (ConeArcs.EachArcIsTheNeedlesItMeets); four, 3e-3; two, 2e-2.
constexpr int kSamples = 9, kRefinements = 6;

}  // namespace

bool coneArc(const TracedBough& b, const ConeLine& line, const Vec3& o, const Vec3& d,
             const Vec3& e1, const Vec3& e2, long j, double ta, double tb, ConeArc& out)
{
    const analytic::ConeGeometry& cone = b.geometry.cone;
    const ApertureTrig trig = apertureTrig(cone.aperture_rad);
    const double r2 = cone.needleRadius_cm * cone.needleRadius_cm, l = cone.needleLength_cm;
    const double apex = double(j) * b.geometry.coneSpacing_cm;  // along the axis from the base
    // The line's offset from the axis, in the frame (e1, e2): its azimuth psi_L(t).
    const Vec3 r0 = o - b.base_cm;
    const double h0 = glm::dot(r0, b.axis);
    const Vec3 across0 = r0 - h0 * b.axis, dAcross = d - line.along() * b.axis;
    const double x0 = glm::dot(across0, e1), y0 = glm::dot(across0, e2);
    const double dx = glm::dot(dAcross, e1), dy = glm::dot(dAcross, e2);
    constexpr double kPi = analytic::kPi, kNone = -std::numeric_limits<double>::infinity();
    const double step = (tb - ta) / (kSamples - 1);
    double psiNear = std::atan2(y0 + 0.5 * (ta + tb) * dy, x0 + 0.5 * (ta + tb) * dx);
    // psi_L(t) unwrapped near psiNear, and delta(t) (< 0: no needle within r).
    const auto at = [&](double t, double& delta) {
        const double u = h0 + t * line.along() - apex, rho = line.rho(t);
        double psi = std::atan2(y0 + t * dy, x0 + t * dx);
        psi += 2.0 * kPi * std::round((psiNear - psi) / (2.0 * kPi));
        psiNear = psi;
        const double dist2 = u * u + rho * rho;
        if (dist2 <= r2) {
            delta = kPi;  // within r of the apex: every needle
            return psi;
        }
        double reach = std::sqrt(dist2 - r2);  // w_r
        if (reach > l) reach = (dist2 + l * l - r2) / (2.0 * l);
        const double num = reach - u * trig.cosPhi, den = rho * trig.sinPhi;
        delta = num >= den ? -1.0 : num <= -den ? kPi : std::acos(num / den);
        return psi;
    };
    // The arc's upper end (sign 1) or its lower end negated (-1) at t.
    const auto end = [&](double t, double sign) {
        double delta;
        const double psi = at(t, delta);
        return delta >= 0.0 ? sign * psi + delta : kNone;
    };
    double upper[kSamples], lower[kSamples], depth[kSamples], psis[kSamples];
    for (int i = 0; i < kSamples; ++i) {
        double delta;
        const double psi = at(ta + step * i, delta);
        psis[i] = psi;
        depth[i] = delta;
        upper[i] = delta >= 0.0 ? psi + delta : kNone;
        lower[i] = delta >= 0.0 ? -psi + delta : kNone;
    }
    int top = -1, bottom = -1, deepest = -1;
    for (int i = 0; i < kSamples; ++i) {
        if (depth[i] < 0.0) continue;
        if (top < 0 || upper[i] > upper[top]) top = i;
        if (bottom < 0 || lower[i] > lower[bottom]) bottom = i;
        if (deepest < 0 || depth[i] > depth[deepest]) deepest = i;
    }
    if (top < 0) return false;
    // The largest of end(., sign) between sample k's neighbours, by a golden-section search.
    const auto refined = [&](const double* f, int k, double sign) {
        double best = f[k];
        double lo = ta + step * std::max(0, k - 1), hi = ta + step * std::min(kSamples - 1, k + 1);
        constexpr double kGolden = 0.6180339887498949;
        double x1 = hi - kGolden * (hi - lo), x2 = lo + kGolden * (hi - lo);
        double f1 = end(x1, sign), f2 = end(x2, sign);
        for (int i = 0; i < kRefinements; ++i) {
            best = std::max({best, f1, f2});
            if (f1 < f2) {
                lo = x1;
                x1 = x2;
                f1 = f2;
                x2 = lo + kGolden * (hi - lo);
                f2 = end(x2, sign);
            } else {
                hi = x2;
                x2 = x1;
                f2 = f1;
                x1 = hi - kGolden * (hi - lo);
                f1 = end(x1, sign);
            }
        }
        return std::max({best, f1, f2});
    };
    psiNear = psis[top];  // the samples' branch
    const double high = refined(upper, top, 1.0);
    psiNear = psis[bottom];
    const double low = -refined(lower, bottom, -1.0);
    out.cone = j;
    // Where the line passes the arc's middle azimuth: its needles' mean position along it.
    const double middle = 0.5 * (high + low);
    int nearest = deepest;
    for (int i = 0; i < kSamples; ++i) {
        if (depth[i] >= 0.0 && std::abs(psis[i] - middle) < std::abs(psis[nearest] - middle)) {
            nearest = i;
        }
    }
    out.t = ta + step * nearest;
    out.from = low;
    out.width = std::min(2.0 * kPi, std::max(0.0, high - low));
    return true;
}

}  // namespace pine::vdbtrace
