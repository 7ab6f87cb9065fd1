// Numerical integration: fixed Gauss-Legendre rules (cheap, used inside shaders where the
// paper's integral has no elementary antiderivative) and an adaptive Gauss-Kronrod rule
// (accurate, used only for reference values: tests and the sweep).
#pragma once

#include <array>
#include <cmath>
#include <cstddef>
#include <functional>
#include <vector>

namespace pine::analytic {

/// Nodes and weights of the 8-point Gauss-Legendre rule on [-1, 1] (positive half; the rule
/// is symmetric). Exact for polynomials of degree 15.
struct GaussLegendre8 {
    static constexpr std::array<double, 4> node = {
        0.1834346424956498049394761, 0.5255324099163289858177390,
        0.7966664774136267395915539, 0.9602898564975362316835609};
    static constexpr std::array<double, 4> weight = {
        0.3626837833783619829651504, 0.3137066458778872873379622,
        0.2223810344533744705443560, 0.1012285362903762591525314};
};

/// Integral of f over [a, b] by the fixed 8-point Gauss-Legendre rule.
template <class F>
double gaussLegendre8(F&& f, double a, double b)
{
    const double mid = 0.5 * (a + b), half = 0.5 * (b - a);
    double sum = 0.0;
    for (std::size_t i = 0; i < GaussLegendre8::node.size(); ++i) {
        const double dx = half * GaussLegendre8::node[i];
        sum += GaussLegendre8::weight[i] * (f(mid - dx) + f(mid + dx));
    }
    return sum * half;
}

/// Integral of f over [a, b] by adaptive Gauss-Kronrod (7/15 points), to an absolute
/// tolerance `absTol` or a relative tolerance `relTol` of the result, whichever is looser.
/// For reference values only: it is slow by design. Returns NaN when f is not finite.
double integrateAdaptive(const std::function<double(double)>& f, double a, double b,
                         double absTol = 1e-12, double relTol = 1e-10, int maxDepth = 40);

/// The same over consecutive `points` (sorted ascending): a known kink or peak at a point
/// never sits inside a panel, where Gauss-Kronrod's error estimate can be fooled.
double integrateAdaptive(const std::function<double(double)>& f, std::vector<double> points,
                         double absTol = 1e-12, double relTol = 1e-10);

}  // namespace pine::analytic
