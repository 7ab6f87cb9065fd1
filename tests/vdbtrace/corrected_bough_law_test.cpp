// The corrected bough law and the exact law it tabulates against the converged exact law (16
// times the chords), over the parameter space, with and without self-shadowing: random
// needle geometries (aperture, needle length and radius, needles per cone, cone spacing),
// bough lengths from 0.5 to 300 cm and directions of view and light all over the sphere, with
// the paper's bough among them. Each quantity level 3 reads (the view's coverage, each half's
// transfer and reflectances, the opacity from a light) is compared as the strip's mean and
// cell by cell.
#include "pine/analytic/direction.h"
#include "pine/vdbtrace/bough_law.h"
#include "pine/vdbtrace/layer_model.h"
#include "pine/vdbtrace/traced_scene.h"

#include <glm/geometric.hpp>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <random>
#include <string>
#include <vector>

namespace pine::vdbtrace {
namespace {

constexpr double kPi = analytic::kPi;

Vec3 onSphere(std::mt19937& rng)
{
    std::normal_distribution<double> n;
    for (;;) {
        const Vec3 v(n(rng), n(rng), n(rng));
        if (glm::length(v) > 1e-6) return glm::normalize(v);
    }
}

// The paper's bough (case 0) or a random one whose needles do not cover their cone.
analytic::BoughGeometry geometryOf(int which, std::mt19937& rng)
{
    analytic::BoughGeometry g;
    g.cone = {kPi / 8, 4.25, 0.05, 12};
    g.coneSpacing_cm = 0.9;
    if (which == 0) return g;
    std::uniform_real_distribution<double> u;
    for (;;) {
        g.cone.aperture_rad = kPi * (0.06 + 0.3 * u(rng));
        g.cone.needleLength_cm = 1.0 + 5.0 * u(rng);
        g.cone.needleRadius_cm = 0.02 + 0.08 * u(rng);
        g.cone.needlesPerCone = std::round(6.0 + 14.0 * u(rng));
        g.coneSpacing_cm = 0.3 + 1.2 * u(rng);
        if (analytic::layerCoverage(g.cone) < 0.9) return g;
    }
}

// Errors against the truth, relative to its strip mean or to `floor` where that is larger: a
// back-lit bough reflects a few hundredths of what a front-lit one does, and its error counts
// against the light that reaches its needles.
struct Errors {
    std::vector<double> mean, cell;  // the strip's mean; the worst cell
    void add(const StripProfile& corrected, const StripProfile& exact, double floor = 0.0)
    {
        const double m = std::max(exact.mean(), floor);
        if (!(m > 1e-6)) return;
        mean.push_back(std::abs(corrected.mean() - exact.mean()) / m);
        const std::vector<double> a = corrected.cellValues(), b = exact.cellValues();
        double worst = 0.0;
        for (std::size_t k = 0; k < a.size(); ++k) worst = std::max(worst, std::abs(a[k] - b[k]));
        cell.push_back(worst / m);
    }
    static double quantile(std::vector<double> v, double q)
    {
        if (v.empty()) return 0.0;
        std::sort(v.begin(), v.end());
        return v[std::min(v.size() - 1, std::size_t(q * double(v.size())))];
    }
    void print(const char* name) const
    {
        std::printf("%-32s n %4zu  mean: median %.4f p90 %.4f max %.4f   cell: median %.4f p90 "
                    "%.4f max %.4f\n",
                    name, mean.size(), quantile(mean, 0.5), quantile(mean, 0.9),
                    quantile(mean, 1.0), quantile(cell, 0.5), quantile(cell, 0.9),
                    quantile(cell, 1.0));
    }
};

StripProfile sum(const FrontRearProfile& p)
{
    std::vector<double> a = p.front.cellValues();
    const std::vector<double> b = p.rear.cellValues();
    for (std::size_t k = 0; k < a.size(); ++k) a[k] += b[k];
    return StripProfile::sampled(a);
}

TEST(CorrectedBoughLaw, AgreesWithTheExactLaw)
{
    // The truth: the exact law with 16 times its chords per cell.
    const std::unique_ptr<BoughLaw> truth = makeExactBoughLaw(16);
    const BoughLaw& exact = boughLaw("exact");
    // Under the layers' independent crossings: with layer_correlation "needles" the hot spot
    // puts a sharp peak near the view into the transfer and diffuse tables, which the grids
    // resolve less well (measured: mean errors up to 0.044 and 0.066, diffuse cells' p90
    // 0.20; docs/models.md "Layer correlation").
    const LayerModel& layers = layerModel("fibre", /*correlated=*/false);
    std::mt19937 rng(2026);
    std::uniform_real_distribution<double> u;
    enum { kCoverage, kFromLight, kTransfer, kDiffuse, kSpecular, kQuantities };
    const char* names[kQuantities] = {"coverage", "opacity from a light", "transfer", "diffuse",
                                      "specular"};
    // With self-shadowing (the light's table) and without (the view's, split by azimuth).
    Errors corrected[2][kQuantities], exactLaw[2][kQuantities];
    constexpr int kGeometries = 6, kBoughs = 12;
    for (int g = 0; g < kGeometries; ++g) {
        const std::shared_ptr<const BoughLaw> table = boughLaw("corrected").fresh();
        const analytic::BoughGeometry geometry = geometryOf(g, rng);
        for (int i = 0; i < kBoughs; ++i) {
            BoughDescription d;
            d.spec.needles = geometry;
            d.exponent = 60.0;
            const double length = g == 0 && i < 6 ? 3.0 + 7.0 * u(rng)
                                                  : 0.5 * std::pow(600.0, u(rng));
            const Vec3 axis = onSphere(rng);
            d.spec.base_cm = Vec3(10.0 * u(rng), 0.0, 0.0);
            d.spec.tip_cm = d.spec.base_cm + length * axis;
            const Vec3 V = onSphere(rng), L = onSphere(rng);
            const Vec3 centre = 0.5 * (d.spec.base_cm + d.spec.tip_cm);
            const TracedBough b = makeTracedBough(d, centre + 1e4 * V, {}, exact, layers);
            const StripProfile tFrom = truth->opacityFromLight(b, L, layers);
            for (int shadowed = 0; shadowed < 2; ++shadowed) {
                BoughLawNeeds needs;
                needs.transfer = shadowed == 1;
                const BoughShading t = truth->shade(b, V, {L}, layers, needs);
                const auto add = [&](Errors* errors, const BoughLaw& law) {
                    const BoughShading s = law.shade(b, V, {L}, layers, needs);
                    const BoughLightTransfer &sl = s.lights[0], &tl = t.lights[0];
                    errors[kCoverage].add(sum(s.alpha), sum(t.alpha));
                    errors[kFromLight].add(law.opacityFromLight(b, L, layers), tFrom);
                    errors[kTransfer].add(sum(sl.transfer), sum(tl.transfer));
                    const double lit = 0.1 * sum(tl.transfer).mean();
                    errors[kDiffuse].add(sum(sl.diffuse), sum(tl.diffuse), lit);
                    errors[kSpecular].add(sum(sl.specular), sum(tl.specular), lit);
                };
                add(corrected[shadowed], *table);
                add(exactLaw[shadowed], exact);
            }
        }
    }
    // The bounds: what was measured (docs/models.md), with a margin. The corrected law is
    // nearer the truth than the exact law for the opacities and the transfer (its nodes have
    // twice the chords); with self-shadowing the reflectances, which vary faster with the
    // directions than the 7.5 and 15 degree knots follow (specular above all), are about as
    // near; without it they are nearer (eqs. 1-2 at each azimuth bin's needle).
    struct Bound {
        double meanP90, meanMax, cellP90;
    };
    const Bound bounds[kQuantities] = {{0.02, 0.04, 0.05},
                                       {0.02, 0.04, 0.05},
                                       {0.02, 0.04, 0.12},
                                       {0.03, 0.06, 0.15},
                                       {0.03, 0.10, 0.15}};
    for (int shadowed = 1; shadowed >= 0; --shadowed) {
        std::printf("%s\n", shadowed ? "with self-shadowing:" : "without self-shadowing:");
        for (int q = 0; q < kQuantities; ++q) {
            const std::string name = names[q] + std::string(shadowed ? "" : " (unshadowed)");
            const Errors& c = corrected[shadowed][q];
            c.print(("corrected " + name).c_str());
            exactLaw[shadowed][q].print(("exact " + name).c_str());
            EXPECT_LE(Errors::quantile(c.mean, 0.9), bounds[q].meanP90) << name;
            EXPECT_LE(Errors::quantile(c.mean, 1.0), bounds[q].meanMax) << name;
            EXPECT_LE(Errors::quantile(c.cell, 0.9), bounds[q].cellP90) << name;
            if (q <= kTransfer) {
                EXPECT_LE(Errors::quantile(c.mean, 0.9),
                          Errors::quantile(exactLaw[shadowed][q].mean, 0.9))
                    << name;
            }
        }
    }
}

}  // namespace
}  // namespace pine::vdbtrace
