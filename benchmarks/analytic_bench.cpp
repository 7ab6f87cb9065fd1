// Cost per evaluation of the closed forms of levels 1-3, and of the quadratures they replace.
// Inputs cycle through a fixed table of random directions so that no branch is always taken.
#include "pine/analytic/bough_shader.h"
#include "pine/analytic/cone_shader.h"
#include "pine/analytic/needle_shader.h"
#include "pine/analytic/reference_integrals.h"

#include <benchmark/benchmark.h>
#include <glm/geometric.hpp>

#include <random>
#include <vector>

namespace {

using namespace pine::analytic;

struct Triple {
    Vec3 axis, L, V;
};

const std::vector<Triple>& triples()
{
    static const std::vector<Triple> table = [] {
        std::mt19937 rng(5);
        std::normal_distribution<double> n;
        const auto d = [&] { return glm::normalize(Vec3(n(rng), n(rng), n(rng))); };
        std::vector<Triple> t(1024);
        for (Triple& x : t) x = {d(), d(), d()};
        return t;
    }();
    return table;
}

constexpr double kExponent = 200.0;

// Runs `shade` on each triple of the table in turn.
template <class Shade>
void overTriples(benchmark::State& state, Shade&& shade)
{
    std::size_t i = 0;
    for (auto _ : state) benchmark::DoNotOptimize(shade(triples()[i++ & 1023]));
}

void NeedleDiffuse_Eq1(benchmark::State& state)
{
    overTriples(state, [](const Triple& t) { return needleDiffuse(t.axis, t.L, t.V); });
}
BENCHMARK(NeedleDiffuse_Eq1);

void NeedleSpecular_Eq2(benchmark::State& state)
{
    overTriples(state, [](const Triple& t) { return needleSpecular(t.axis, t.L, t.V, kExponent); });
}
BENCHMARK(NeedleSpecular_Eq2);

void NeedleDiffuse_Quadrature(benchmark::State& state)
{
    overTriples(state, [](const Triple& t) { return reference::needleDiffuse(t.axis, t.L, t.V); });
}
BENCHMARK(NeedleDiffuse_Quadrature);

void Cone_Eqs4to6(benchmark::State& state)
{
    overTriples(
        state, [](const Triple& t) { return coneIntegrals(kPi / 8, t.axis, t.L, t.V, kExponent); });
}
BENCHMARK(Cone_Eqs4to6);

void Cone_PrintedLambdaFit(benchmark::State& state)
{
    overTriples(state, [](const Triple& t) {
        return coneDiffuseLambdaFit(kPi / 8, t.axis, t.L, t.V, true);
    });
}
BENCHMARK(Cone_PrintedLambdaFit);

void Cone_Quadrature(benchmark::State& state)
{
    overTriples(state, [](const Triple& t) {
        return reference::coneIntegrals(kPi / 8, t.axis, t.L, t.V, kExponent);
    });
}
BENCHMARK(Cone_Quadrature);

void Bough_LinearLaw(benchmark::State& state)
{
    const BoughGeometry b = paperBough();
    overTriples(state, [&](const Triple& t) {
        return boughLinearLaw(b, boughView(b.cone.aperture_rad, t.axis, t.L, t.V));
    });
}
BENCHMARK(Bough_LinearLaw);

void Bough_ExactTransmittance(benchmark::State& state)
{
    const BoughGeometry b = paperBough();
    overTriples(state, [&](const Triple& t) {
        return boughExact(b, boughView(b.cone.aperture_rad, t.axis, t.L, t.V));
    });
}
BENCHMARK(Bough_ExactTransmittance);

void Bough_ExactQuadrature(benchmark::State& state)
{
    // The reference needs finite layer rates: none of the table's random triples lies on the
    // axis exactly.
    const BoughGeometry b = paperBough();
    overTriples(state, [&](const Triple& t) {
        return reference::boughExact(b, boughView(b.cone.aperture_rad, t.axis, t.L, t.V));
    });
}
BENCHMARK(Bough_ExactQuadrature)->Unit(benchmark::kMicrosecond);

}  // namespace

BENCHMARK_MAIN();
