#include "pine/vdbtrace/occluder_profile.h"

#include <algorithm>
#include <cmath>

namespace pine::vdbtrace {
namespace {

// The share is a trapezoid: it rises over `ramp` at each end to its top min(1, apexes /
// reach) and holds over `flat` between (ramp = min(apexes, reach), flat = |apexes - reach|).
// Below, sigma = tau top is the optical depth at the top and `flatShare` = flat / length.

// 1 - exp(-x) for x >= 0 and e = exp(-x): exp alone (expm1 costs twice as much), the series
// where 1 - e cancels.
double oneMinusExp(double x, double e)
{
    return x < 1e-3 ? x * (1.0 - x * (0.5 - x * (1.0 / 6.0 - x / 24.0))) : 1.0 - e;
}
double oneMinusExp(double x)
{
    return oneMinusExp(x, std::exp(-x));
}

// The mean of 1 - exp(-sigma share / top) over the strip, `flatShare` of it at the top and
// the rest on the two ramps, and its derivative in sigma.
struct Mean {
    double value, slope;
};
Mean meanAt(double sigma, double flatShare)
{
    const double e = std::exp(-sigma), flat = oneMinusExp(sigma, e);
    double ramp, dRamp;  // the mean of 1 - exp(-sigma x) over x in [0, 1], and d / d sigma
    if (sigma < 1e-3) {  // by its series, where (1 - e) / sigma cancels
        ramp = sigma * (0.5 - sigma * (1.0 / 6.0 - sigma / 24.0));
        dRamp = 0.5 - sigma * (1.0 / 3.0 - sigma / 8.0);
    } else {
        ramp = 1.0 - flat / sigma;
        dRamp = (flat - sigma * e) / (sigma * sigma);
    }
    return {flatShare * flat + (1.0 - flatShare) * ramp, flatShare * e + (1.0 - flatShare) * dRamp};
}

// Newton's method on the concave, increasing mean from below its root stays below it and
// converges monotonically; from above, its first step lands below. It stops where the mean
// is met to its rounding: near an opaque mean the slope is about 1e-11, and a rounding of the
// mean moves sigma by more than any relative tolerance on sigma.
double solveSigma(double mean, double flatShare, double sigma)
{
    for (int i = 0; i < 30; ++i) {
        const Mean m = meanAt(sigma, flatShare);
        const double f = m.value - mean;
        if (!(std::abs(f) > 4e-16) || !(m.slope > 0.0)) break;
        const double next = std::max(sigma - f / m.slope, 0.5 * sigma);
        const bool done = std::abs(next - sigma) <= 1e-12 * next;
        sigma = next;
        if (done) break;
    }
    return sigma;
}

// sigma over the table's grid, as a starting point for solveSigma: rows of flatShare k / kRows,
// columns of the even strip's depth -log(1 - mean) = j kStep (what sigma is at flatShare 1).
constexpr int kRows = 32, kColumns = 128;
constexpr double kMaxMean = 1.0 - 1e-6;
constexpr double kMaxDepth = 13.815510557964274;  // -log(1 - kMaxMean) = 6 ln 10
constexpr double kStep = kMaxDepth / kColumns;
struct SigmaTable {
    double logSigma[kRows + 1][kColumns + 1];
    SigmaTable()
    {
        for (int k = 0; k <= kRows; ++k) {
            const double flatShare = double(k) / kRows;
            double sigma = 0.0;
            for (int j = 0; j <= kColumns; ++j) {
                const double depth = std::max(j, 1) * kStep;  // column 0 as column 1's
                sigma = solveSigma(-std::expm1(-depth), flatShare, std::max(sigma, depth));
                logSigma[k][j] = std::log(sigma / depth);
            }
        }
    }
};

}  // namespace

double AxialCones::share(double h_cm) const
{
    if (even()) return h_cm >= 0.0 && h_cm <= length() ? 1.0 : 0.0;
    const double reaching = std::min(h_cm, apexes_cm) - std::max(0.0, h_cm - reach_cm);
    return std::clamp(reaching / reach_cm, 0.0, 1.0);
}

double AxialCones::top() const
{
    return std::min(1.0, apexes_cm / reach_cm);
}

double AxialCones::flatShare() const
{
    return std::abs(apexes_cm - reach_cm) / length();
}

bool AxialCones::even() const
{
    return !(reach_cm > 0.0) || !(apexes_cm > 0.0);
}

double AxialCones::meanOpacity(double tau) const
{
    if (even()) return -std::expm1(-tau);
    return meanAt(tau * top(), flatShare()).value;
}

double AxialCones::opacityAt(double mean, double h_cm) const
{
    const double s = share(h_cm);
    if (!(mean > 0.0) || !(s > 0.0)) return 0.0;
    if (even()) return std::min(mean, 1.0);
    // An opaque mean is kept a hair short of 1, where sigma is finite.
    const double target = std::min(mean, kMaxMean);
    const double flat = flatShare();
    static const SigmaTable table;
    const double depth = -std::log1p(-target);
    const double x = std::clamp(depth / kStep, 1.0, double(kColumns)), y = flat * kRows;
    const int j = std::min(int(x), kColumns - 1), k = std::min(int(y), kRows - 1);
    const double fx = x - j, fy = y - k;
    const double logRatio =
        (1.0 - fy) * ((1.0 - fx) * table.logSigma[k][j] + fx * table.logSigma[k][j + 1]) +
        fy * ((1.0 - fx) * table.logSigma[k + 1][j] + fx * table.logSigma[k + 1][j + 1]);
    const double sigma = solveSigma(target, flat, depth * std::exp(logRatio));
    return oneMinusExp(sigma * s / top());
}

}  // namespace pine::vdbtrace
