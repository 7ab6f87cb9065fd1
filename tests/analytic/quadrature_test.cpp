// The reference integrator is what every closed form is judged by: it is tested first, on
// integrals known exactly, including a kink and a narrow peak.
#include "pine/analytic/direction.h"
#include "pine/analytic/quadrature.h"

#include <gtest/gtest.h>

#include <cmath>

namespace pine::analytic {
namespace {

TEST(Quadrature, AdaptiveMatchesKnownIntegrals)
{
    EXPECT_NEAR(integrateAdaptive([](double x) { return std::sin(x); }, 0.0, kPi), 2.0, 1e-12);
    EXPECT_NEAR(integrateAdaptive([](double x) { return std::abs(x - 0.3); }, -1.0, 1.0),
                0.5 * (1.3 * 1.3 + 0.7 * 0.7), 1e-11);  // a kink off the nodes
    // A narrow Gaussian: sigma 1e-3, integral sqrt(2 pi) sigma.
    const double sigma = 1e-3;
    EXPECT_NEAR(integrateAdaptive([&](double x) { return std::exp(-0.5 * x * x / (sigma * sigma)); },
                                  -0.01, 0.01),
                std::sqrt(2.0 * kPi) * sigma * std::erf(10.0 / std::sqrt(2.0)), 1e-12);
}

TEST(Quadrature, AdaptiveReportsNonFiniteIntegrand)
{
    EXPECT_TRUE(std::isnan(integrateAdaptive([](double) { return std::nan(""); }, 0.0, 1.0)));
}

TEST(Quadrature, GaussLegendre8IsExactToDegree15)
{
    const double exact = (std::pow(2.0, 16) - std::pow(-1.0, 16)) / 16.0;  // int x^15 on [-1, 2]
    EXPECT_NEAR(gaussLegendre8([](double x) { return std::pow(x, 15); }, -1.0, 2.0), exact,
                1e-10 * exact);
}

}  // namespace
}  // namespace pine::analytic
