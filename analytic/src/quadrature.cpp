#include "pine/analytic/quadrature.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace pine::analytic {
namespace {

// Kronrod 15-point nodes (positive half, descending) and weights; the Gauss 7-point rule
// uses every other node.
constexpr double kXgk[8] = {0.991455371120812639206854697526329, 0.949107912342758524526189684047851,
                            0.864864423359769072789712788640926, 0.741531185599394439863864773280788,
                            0.586087235467691130294144845693013, 0.405845151377397166906606412076961,
                            0.207784955007898467600689403773245, 0.000000000000000000000000000000000};
constexpr double kWgk[8] = {0.022935322010529224963732008058970, 0.063092092629978553290700663189204,
                            0.104790010322250183839876322541518, 0.140653259715525918745189590510238,
                            0.169004726639267902826583426598550, 0.190350578064785409913256402421014,
                            0.204432940075298892414161999234649, 0.209482141084727828012999174891714};
constexpr double kWg[4] = {0.129484966168869693270611432679082, 0.279705391489276667901467771423780,
                           0.381830050505118944950369775488975, 0.417959183673469387755102040816327};

struct Segment {
    double value;
    double error;
};

Segment kronrod(const std::function<double(double)>& f, double a, double b)
{
    const double c = 0.5 * (a + b), h = 0.5 * (b - a);
    const double fc = f(c);
    double k = fc * kWgk[7];
    double g = fc * kWg[3];
    for (int i = 0; i < 7; ++i) {
        const double dx = h * kXgk[i];
        const double s = f(c - dx) + f(c + dx);
        k += kWgk[i] * s;
        if (i % 2 == 1) g += kWg[i / 2] * s;
    }
    return {k * h, std::abs((k - g) * h)};
}

double recurse(const std::function<double(double)>& f, double a, double b, Segment whole,
               double absTol, int depth)
{
    if (!std::isfinite(whole.value)) return std::numeric_limits<double>::quiet_NaN();
    if (whole.error <= absTol || depth <= 0) return whole.value;
    const double m = 0.5 * (a + b);
    const Segment left = kronrod(f, a, m), right = kronrod(f, m, b);
    return recurse(f, a, m, left, 0.5 * absTol, depth - 1) +
           recurse(f, m, b, right, 0.5 * absTol, depth - 1);
}

}  // namespace

double integrateAdaptive(const std::function<double(double)>& f, double a, double b,
                         double absTol, double relTol, int maxDepth)
{
    if (a == b) return 0.0;
    const Segment whole = kronrod(f, a, b);
    // A first estimate sets the scale of the relative tolerance.
    const double tol = std::max(absTol, relTol * std::abs(whole.value));
    return recurse(f, a, b, whole, tol, maxDepth);
}

double integrateAdaptive(const std::function<double(double)>& f, std::vector<double> points,
                         double absTol, double relTol)
{
    std::sort(points.begin(), points.end());
    double sum = 0.0;
    for (std::size_t i = 0; i + 1 < points.size(); ++i) {
        if (points[i + 1] > points[i]) sum += integrateAdaptive(f, points[i], points[i + 1], absTol, relTol);
    }
    return sum;
}

}  // namespace pine::analytic
