// The fibre extinction law's bands (layer_bands.h) against what they stand for: evenly spaced
// needles stop a line at each layer it crosses with probability n, the needles' projected
// width there, however the line is cut into voxel spans; a band ends where the line turns
// back through the layers, and the layers lie at a phase the field does not know, the same
// through one bough and its own in the next.
#include "pine/vdbtrace/layer_bands.h"
#include "pine/bake/extinction_law.h"
#include "pine/bake/layer_field.h"

#include <gtest/gtest.h>
#include <glm/geometric.hpp>

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

namespace pine::vdbtrace {
namespace {

using bake::Vec3;
constexpr double kPi = 3.14159265358979323846;

/// The transmittance of `layers` layers crossed one way at n needles a layer, cut into
/// random spans.
double acrossLayers(LayerBands& bands, double layers, double n, std::mt19937& rng, double sign)
{
    std::uniform_real_distribution<double> cut(0.0, 1.0);
    std::vector<double> at{0.0, layers};
    for (int i = 0; i < 7; ++i) at.push_back(layers * cut(rng));
    std::sort(at.begin(), at.end());
    double T = 1.0;
    for (std::size_t i = 1; i < at.size(); ++i) {
        const double k = at[i] - at[i - 1];
        T *= bands.span(n * k, sign * k);
    }
    return T;
}

/// One leg of a line through a bough: `layers` crossed (signed; 0 along them), `needles` met
/// evenly over it.
struct Leg {
    double needles, layers;
};

/// What LayerBands stands for, by brute force: layers at psi + integers for each of `phases`
/// phases psi, each leg walked in steps of 1e-4 of a layer, a band being the steps in one
/// interval between layers moving one way; its needles stop the line with probability
/// min(1, n). The mean over the phases (the midpoint rule: 400 err by under 1e-5 n^2).
double meanOverPhases(const std::vector<Leg>& legs, int phases = 400)
{
    double sum = 0.0;
    for (int k = 0; k < phases; ++k) {
        const double psi = (k + 0.5) / phases;
        double T = 1.0, band = 0.0, g = 0.0;
        long index = 0;
        int direction = 0;
        bool begun = false;
        for (const Leg& leg : legs) {
            if (leg.layers == 0.0) {
                band += leg.needles;
                continue;
            }
            const int steps = std::max(1, int(std::ceil(std::abs(leg.layers) / 1e-4)));
            const double dg = leg.layers / steps, dn = leg.needles / steps;
            const int dir = leg.layers > 0.0 ? 1 : -1;
            for (int i = 0; i < steps; ++i) {
                const double mid = g + 0.5 * dg;
                const long at = long(std::floor(mid - psi));
                if (begun && (at != index || dir != direction)) {
                    T *= 1.0 - std::min(1.0, band);
                    band = 0.0;
                }
                begun = true;
                index = at;
                direction = dir;
                band += dn;
                g += dg;
            }
        }
        sum += T * (1.0 - std::min(1.0, band));
    }
    return sum / phases;
}

/// The same legs through LayerBands, each cut into `pieces` spans.
double throughBands(const std::vector<Leg>& legs, int pieces = 1)
{
    LayerBands bands;
    double T = 1.0;
    for (const Leg& leg : legs) {
        for (int i = 0; i < pieces; ++i) T *= bands.span(leg.needles / pieces, leg.layers / pieces);
    }
    return T;
}

TEST(LayerBands, WholeLayersStopALineAsEvenlySpacedNeedlesAtAnUnknownPhaseDo)
{
    // K whole layers crossed one way, n needles met in each, the layers' phase unknown:
    // int_0^1 (1 - n psi) (1 - n)^(K - 1) (1 - n (1 - psi)) dpsi = (1 - n)^(K - 1) (1 - n +
    // n^2 / 6), where bands begun at the line's start gave (1 - n)^K and a Poisson medium
    // exp(-n K); 8 phases err by n^2 / 768 at most; the cut into spans changes nothing.
    std::mt19937 rng(3);
    for (const double n : {0.05, 0.3, 0.75, 0.99}) {
        for (const int K : {1, 2, 5}) {
            const double exact = std::pow(1.0 - n, K - 1) * (1.0 - n + n * n / 6.0);
            for (const double sign : {1.0, -1.0}) {
                LayerBands bands;
                const double T = acrossLayers(bands, K, n, rng, sign);
                EXPECT_NEAR(T, exact, n * n / 768.0 + 1e-12) << "n " << n << " K " << K;
                EXPECT_NEAR(T, throughBands({{n * K, sign * K}}), 1e-12) << "n " << n;
            }
        }
    }
}

TEST(LayerBands, AMillionLayersInOneSpanCostOneStep)
{
    // A layer spacing of 1e-6 cm puts a million layers in a voxel: the whole ones are taken at
    // once, as (1 - n)^K, and agree with a span cut layer by layer where that is affordable.
    std::mt19937 rng(11);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    for (int trial = 0; trial < 200; ++trial) {
        const double n = 1e-4 + 0.01 * u(rng), start = u(rng), layers = 2.0 + 300.0 * u(rng);
        LayerBands whole, cut;
        whole.span(n * start, start);  // bands begun before
        cut.span(n * start, start);
        const double T = whole.span(n * layers, layers);
        double byLayer = 1.0;
        for (double done = 0.0; done < layers;) {
            const double step = std::min(0.37, layers - done);
            byLayer *= cut.span(n * step, step);
            done += step;
        }
        EXPECT_NEAR(T, byLayer, 1e-12) << trial;
        // and the bands they leave begun go on alike
        EXPECT_NEAR(whole.span(n * 0.5, 0.5), cut.span(n * 0.5, 0.5), 1e-12) << trial;
    }
    LayerBands bands;
    EXPECT_NEAR(bands.span(1e6 * 1e-7, 1e6), std::pow(1.0 - 1e-7, 1e6), 1e-12);
}

TEST(LayerBands, TheMeanOverThePhaseOfLinesThatTurnAndLeave)
{
    // Random lines through a bough: legs up and down through the layers (a line passing the
    // axis turns back through the same layers, at the same phase) and along them, each leg's
    // needles its own: the brute force at the same 8 phases to its steps' error, and over 400
    // phases the midpoint rule's (along the layers the mean over the phase jumps, and 8
    // phases err by up to 0.009 there, so those lines are held to the first only).
    std::mt19937 rng(17);
    std::uniform_real_distribution<double> u(0.0, 1.0);
    for (int trial = 0; trial < 100; ++trial) {
        std::vector<Leg> legs;
        double sign = u(rng) < 0.5 ? 1.0 : -1.0;
        const int count = 1 + int(4 * u(rng));
        for (int i = 0; i < count; ++i) {
            const double layers = u(rng) < 0.15 ? 0.0 : 3.0 * u(rng) * u(rng);
            legs.push_back({layers > 0.0 ? layers * 1.2 * u(rng) : 0.2 * u(rng), sign * layers});
            if (u(rng) < 0.5) sign = -sign;
        }
        EXPECT_NEAR(throughBands(legs), meanOverPhases(legs, LayerBands::kPhases), 5e-4) << trial;
        const bool along =
            std::any_of(legs.begin(), legs.end(), [](const Leg& g) { return g.layers == 0.0; });
        if (!along) {
            EXPECT_NEAR(throughBands(legs), meanOverPhases(legs), 4e-3) << trial;
        }
        EXPECT_NEAR(throughBands(legs, 3), throughBands(legs), 1e-12) << trial;
    }
}

TEST(LayerBands, ABandEndsWhereTheLineTurnsBackAndTheNextBoughHasItsOwnPhase)
{
    std::mt19937 rng(5);
    const double n = 0.6;
    {
        // Half a layer up and back down: the same layers both ways, two bands each way where a
        // layer lies within the half layer, one otherwise.
        LayerBands bands;
        const double T =
            acrossLayers(bands, 0.5, n, rng, 1.0) * acrossLayers(bands, 0.5, n, rng, -1.0);
        EXPECT_NEAR(T, meanOverPhases({{n / 2, 0.5}, {n / 2, -0.5}}), 2e-3);
    }
    {
        // Half a layer, out of the medium, half a layer of another bough at its own phase:
        // the two means multiply.
        LayerBands bands;
        double T = acrossLayers(bands, 0.5, n, rng, 1.0);
        EXPECT_EQ(bands.span(0.0, 0.0), 1.0);
        T *= acrossLayers(bands, 0.5, n, rng, 1.0);
        const double half = meanOverPhases({{n / 2, 0.5}});
        EXPECT_NEAR(T, half * half, 2e-3);
    }
    {
        // Along the layers (grazing) the needles add up in one band until it is opaque.
        LayerBands bands;
        EXPECT_NEAR(bands.span(0.3, 0.0) * bands.span(0.3, 0.0), 0.4, 1e-12);
        EXPECT_EQ(bands.span(0.5, 0.0), 0.0);
    }
    {
        // A grazing span inside a band running either way stays in the bands begun.
        for (const double sign : {1.0, -1.0}) {
            LayerBands bands;
            const double T = bands.span(0.2, 0.5 * sign) * bands.span(0.2, 0.0) *
                             bands.span(0.2, 0.5 * sign);
            EXPECT_NEAR(T, meanOverPhases({{0.2, 0.5 * sign}, {0.2, 0.0}, {0.2, 0.5 * sign}}), 2e-3)
                << sign;
        }
        // A span barely crossing the layers meets its needles, not infinitely many.
        LayerBands bands;
        EXPECT_NEAR(bands.span(0.01, 1e-320), 0.99, 1e-12);  // 0.01 / 1e-320 overflows
    }
    {
        // More needles than one band can hold: opaque, never negative or NaN.
        LayerBands bands;
        EXPECT_EQ(bands.span(3.0, 0.2), 0.0);
        EXPECT_EQ(bands.span(1e300, 1e-300), 0.0);
    }
    {
        // A gradient read from elsewhere that is not finite: its needles join the bands begun,
        // and the layers keep their places.
        LayerBands broken, clean;
        EXPECT_NEAR(broken.span(0.3, 0.4) * broken.span(0.1, std::nan("")),
                    clean.span(0.3, 0.4) * clean.span(0.1, 0.0), 1e-12);
        EXPECT_NEAR(broken.span(0.5, 1.0), clean.span(0.5, 1.0), 1e-12);
    }
}

/// The transmittance of a line from a layer through the layer positions `path` (signed layers
/// crossed from the start, in order), each leg cut into random spans, at n needles a layer.
double fromALayer(const std::vector<double>& path, double n, std::mt19937& rng)
{
    LayersFromALayer layers;
    std::uniform_real_distribution<double> cut(0.0, 1.0);
    double T = 1.0, at = 0.0;
    for (const double to : path) {
        std::vector<double> cuts{at, to};
        for (int i = 0; i < 5; ++i) cuts.push_back(at + (to - at) * cut(rng));
        std::sort(cuts.begin(), cuts.end());
        if (to < at) std::reverse(cuts.begin(), cuts.end());
        for (std::size_t i = 1; i < cuts.size(); ++i) {
            const double k = cuts[i] - cuts[i - 1];
            T *= layers.span(n * std::abs(k), k);
        }
        at = to;
    }
    return T;
}

TEST(LayersFromALayer, ALineFromANeedleMeetsTheLayersAtWholeCrossings)
{
    std::mt19937 rng(7);
    for (const double n : {0.1, 0.45, 0.9}) {
        // Out one way: the layers at 1, 2, ..., not its own at 0, and none in the part crossed
        // past the last (where bands spread from the start stop 0.6 n of the light).
        EXPECT_NEAR(fromALayer({2.6}, n, rng), std::pow(1.0 - n, 2), 1e-12) << n;
        EXPECT_NEAR(fromALayer({-1.5}, n, rng), 1.0 - n, 1e-12) << n;
        EXPECT_NEAR(fromALayer({0.999}, n, rng), 1.0, 1e-12) << n;
        // Turning back past the axis at 2.6: the layers at 1 and 2 on the way out, at 2, 1 and
        // its own cone's at 0 (another azimuth) on the way back to -0.5. Bands begun at the
        // turn would meet 0.6 + 3.1 layers' needles there in place of 3.
        EXPECT_NEAR(fromALayer({2.6, -0.5}, n, rng), std::pow(1.0 - n, 5), 1e-12) << n;
        // Turning before the first layer: none met on the way out, its own on the way back.
        EXPECT_NEAR(fromALayer({0.4, -0.2}, n, rng), 1.0 - n, 1e-12) << n;
    }
    // Ending a span on a layer's place: met once, on whichever side the line goes on.
    for (const double n : {0.2, 0.7}) {
        LayersFromALayer up;
        EXPECT_NEAR(up.span(n, 1.0) * up.span(0.5 * n, -0.5), 1.0 - n, 1e-12);
        LayersFromALayer down;  // its own layer at 0 again on the way back
        EXPECT_NEAR(down.span(n, -1.0) * down.span(1.5 * n, 1.5), (1.0 - n) * (1.0 - n), 1e-12);
    }
    // A non-finite gradient stops what its needles stop, and the layers keep their places.
    LayersFromALayer broken;
    EXPECT_NEAR(broken.span(0.4, std::nan("")), 0.6, 1e-12);
    EXPECT_NEAR(broken.span(0.5, 1.0), 0.5, 1e-12);
    // Where a line runs along the layers it meets none; needles more than a layer holds stop
    // it at a crossing, never below 0 or as NaN (a ratio overflowing to infinity).
    LayersFromALayer grazing;
    EXPECT_EQ(grazing.span(0.5, 0.0), 1.0);
    LayersFromALayer steep;
    EXPECT_EQ(steep.span(3.0, 1.2), 0.0);
    LayersFromALayer tiny;
    EXPECT_EQ(tiny.span(0.01, 1e-320), 1.0);  // 0.01 / 1e-320 overflows; no layer met
    EXPECT_NEAR(tiny.span(0.01, 1.0), 0.99, 1e-12);
}

TEST(LayerBands, OneCrossingOfAPaperBoughStopsALineWithItsNeedlesProjectedWidth)
{
    // From the bough's own geometry, not the sampled fields: the needles of the cone through x
    // point along a = cos(phi) axis + sin(phi) radial, its normal is m = sin(phi) axis -
    // cos(phi) radial, the cones are dh sin(phi) apart along m, and N needles fanning out
    // from the apex cover N r / (pi rho) of the cone. A line along d crosses one layer over a
    // path dh sin(phi) / |d . m| and meets n = coverage |d x a| / |d . m| needles there
    // (A s_v / |n . d|, errata E13); the fibre law with its bands lets 1 - n through at a
    // known phase, the Poisson law exp(-n).
    const Vec3 axis = glm::normalize(Vec3(0.2, -0.4, 0.9));
    const Vec3 radial = glm::normalize(glm::cross(axis, Vec3(1.0, 0.0, 0.0)));
    bake::BoughSpec b;
    b.base_cm = Vec3(1.0, -2.0, 0.5);
    b.tip_cm = b.base_cm + 40.0 * axis;
    b.needles.cone = {kPi / 8, 4.25, 0.05, 12};
    b.needles.coneSpacing_cm = 0.9;
    const double phi = kPi / 8, dh = 0.9;
    const Vec3 a = std::cos(phi) * axis + std::sin(phi) * radial;
    const Vec3 m = std::sin(phi) * axis - std::cos(phi) * radial;
    const bake::ExtinctionLaw& fibre = bake::extinctionLaw("fibre");
    const bake::ExtinctionLaw& poisson = bake::extinctionLaw("poisson");
    ASSERT_TRUE(fibre.banded());
    ASSERT_FALSE(poisson.banded());
    std::mt19937 rng(7);
    std::normal_distribution<double> g;
    int checked = 0;
    for (const double rho : {0.3, 0.9, 1.5}) {
        const auto s = bake::sampleBough(b, b.base_cm + 20.0 * axis + rho * radial);
        ASSERT_TRUE(s);
        const double coverage = std::min(1.0, 12 * 0.05 / (kPi * rho));
        // Both laws write the rate's mean, the needles' mean projected area per volume.
        EXPECT_EQ(fibre.meanExtinction(*s), poisson.meanExtinction(*s));
        for (int i = 0; i < 300; ++i) {
            const Vec3 d = glm::normalize(Vec3(g(rng), g(rng), g(rng)));
            const double path = dh * std::sin(phi) / std::abs(glm::dot(d, m));
            const double n = coverage * glm::length(glm::cross(d, a)) / std::abs(glm::dot(d, m));
            if (!(n < 1.0) || !(path < 100.0)) continue;
            ++checked;
            const double rate = fibre.extinction(*s, d);
            EXPECT_NEAR(rate, poisson.extinction(*s, d), 1e-12);
            LayerBands bands;
            const double layers = glm::dot(d, s->gradient) * path;
            EXPECT_NEAR(std::abs(layers), 1.0, 1e-9);
            // One layer's worth of the line at an unknown phase: 1 - n + n^2 / 6 (above).
            EXPECT_NEAR(bands.span(rate * path, layers), 1.0 - n + n * n / 6.0,
                        n * n / 768.0 + 1e-9)
                << "rho " << rho;
            EXPECT_NEAR(std::exp(-poisson.extinction(*s, d) * path), std::exp(-n), 1e-9);
        }
    }
    EXPECT_GT(checked, 500);
}

}  // namespace
}  // namespace pine::vdbtrace
