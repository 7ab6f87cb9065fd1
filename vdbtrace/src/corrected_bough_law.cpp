// The corrected bough law (issue "faithful models": the paper's conclusion asks for a better
// law than section 6.6's linear one): the exact law (exact_bough_law.cpp) tabulated once per
// needle geometry and read by multilinear interpolation, in place of the exact law's chords
// for every bough.
//
// What the exact law gives depends on a bough only through its needle geometry (N, r, l, phi,
// dh), specular exponent and length, and on the directions only through the angle theta_v
// between the view and the axis, the light's angle theta_l to the axis and the light's
// azimuth about the axis from the view's, Delta: the cones and the layer models are symmetric
// about the axis. Mirroring through the plane of the axis and the view maps Delta to -Delta and
// the strip's offset xi to -xi, so |Delta| is tabulated and a light on the other side reads
// the cells in reverse.
//
// The length L enters through the number of cones n = floor(L / dh) + 1: a cone's needles
// appear whole, and the paper bough's coverage jumps by 10-17% at each new cone. What the law
// integrates along the strip, Q = profile x (L + l cos(phi)), barely moves between two cones
// (1-3%) and grows nearly linearly in n (ends + interior). So the table holds Q at the two ends
// of a cone count's range of lengths, at every n up to 6 and at spaced n beyond, interpolated
// linearly in n and in the place within the range, and a profile is Q / (L + l cos(phi)).
//
// Tables per scene and geometry, filled lazily node by node: a forest whose boughs share one
// geometry evaluates the exact law at the nodes its boughs' directions touch (a surface in
// the three angles, for one light and a far camera), not once per bough. Three tables: the
// view's opacity (theta_v, L) split by the needles' azimuth, the opacity from a light
// (theta_l, L) and, with self-shadowing only, each light's transfer and reflectances
// (theta_v, theta_l, |Delta|, L). How far this is from the exact law over the parameter space
// is measured by CorrectedBoughLaw.AgreesWithTheExactLaw; with self-shadowing the paper forest
// at 320 x 240 fills 21,596 light nodes (over the bark radii its boughs span) for the 24,675
// boughs it meets at level 3, and so costs more than the exact law there (docs/models.md).
#include "exact_bough_law.h"

#include "pine/analytic/direction.h"
#include "pine/analytic/needle_shader.h"
#include "pine/vdbtrace/bough_law.h"
#include "pine/vdbtrace/layer_model.h"
#include "pine/vdbtrace/traced_scene.h"

#include <glm/geometric.hpp>

#include <algorithm>
#include <array>
#include <cmath>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <stdexcept>
#include <tuple>

namespace pine::vdbtrace {
namespace {

constexpr double kPi = analytic::kPi;
constexpr int kCells = kExactLawCells;

// Knots per angle, evenly spaced: theta_v and theta_l over [0, pi], |Delta| over [0, pi]. 7.5,
// 7.5 and 15 degrees.
constexpr int kViewKnots = 25, kLightKnots = 25, kAzimuthKnots = 13;
// Cone counts: every one up to 6, then spaced (Q is nearly linear in n); beyond the last,
// extrapolated.
constexpr std::array<int, 22> kConeCounts{1,  2,  3,  4,  5,   6,   8,   10,  12,   16,   20,
                                          24, 32, 48, 64, 96, 128, 256, 512, 1024, 2048, 4096};
constexpr int kCountKnots = int(kConeCounts.size());
// Lengths within one cone count's range: its start and its end.
constexpr int kWithinKnots = 2;

// The table's nodes are paid for once per geometry, not per bough: their chords are this many
// times the exact law's, whose own quadrature is off by up to 5% on short boughs (the same
// bough's view and light opacities, 6 and 10 chords a cell, differ by that much), so that the
// table is nearer the converged law than the exact law is.
constexpr int kChordDensity = 2;
// Bins of the needles' azimuth about the axis in the view's table (7.5 degrees): without
// self-shadowing a light's reflectances are the bins' shares times eqs. 1-2 at each bin's
// needle, so the light's two angles need no table.
constexpr int kAzimuthBins = 48;

// A coordinate's place among knots: the knot below and the fraction to the next (beyond the
// last two for a count past the last knot).
struct Place {
    int below;
    double t;
};
Place place(double x, double range, int n)
{
    const double u = std::clamp(x / range, 0.0, 1.0) * double(n - 1);
    const int below = std::min(int(u), n - 2);
    return {below, u - double(below)};
}
Place placeCount(int n)
{
    const auto above = std::lower_bound(kConeCounts.begin(), kConeCounts.end(), n);
    const int k = std::clamp(int(above - kConeCounts.begin()) - 1, 0, kCountKnots - 2);
    return {k, double(n - kConeCounts[k]) / double(kConeCounts[k + 1] - kConeCounts[k])};
}

// A table of D coordinates, each node a vector of `width` values computed on first use, once,
// from any thread.
template <int D>
class LazyTable {
public:
    using Knots = std::array<int, D>;
    using Fill = std::function<std::vector<double>(const Knots&)>;
    LazyTable(const Knots& knots, std::size_t width, Fill fill)
        : mKnots(knots), mWidth(width), mFill(std::move(fill))
    {
        std::size_t n = 1;
        for (int k : knots) n *= std::size_t(k);
        mNodes = std::make_unique<Node[]>(n);
    }
    /// The multilinear interpolation at `places` (one per coordinate), times `scale`.
    std::vector<double> at(const std::array<Place, D>& places, double scale) const
    {
        std::vector<double> out(mWidth, 0.0);
        for (int corner = 0; corner < (1 << D); ++corner) {
            double w = 1.0;
            Knots index{};
            for (int i = 0; i < D; ++i) {
                const bool up = (corner >> i) & 1;
                w *= up ? places[i].t : 1.0 - places[i].t;
                index[i] = places[i].below + (up ? 1 : 0);
            }
            if (w == 0.0) continue;  // a node that does not count is not computed
            const std::vector<double>& v = node(index);
            for (std::size_t k = 0; k < mWidth; ++k) out[k] += w * v[k];
        }
        for (double& v : out) v *= scale;
        return out;
    }

private:
    struct Node {
        std::once_flag once;
        std::vector<double> values;
    };
    const std::vector<double>& node(const Knots& index) const
    {
        std::size_t flat = 0;
        for (int i = 0; i < D; ++i) flat = flat * std::size_t(mKnots[i]) + std::size_t(index[i]);
        Node& n = mNodes[flat];
        std::call_once(n.once, [&] {
            std::vector<double> v = mFill(index);
            if (v.size() != mWidth) throw std::logic_error("a table node of another width");
            n.values = std::move(v);
        });
        return n.values;
    }
    Knots mKnots;
    std::size_t mWidth;
    Fill mFill;
    std::unique_ptr<Node[]> mNodes;
};

double knot(int i, int n, double range) { return range * double(i) / double(n - 1); }

std::vector<double> cellsOf(const StripProfile& p)
{
    std::vector<double> cells = p.cellValues();
    if (cells.empty()) throw std::logic_error("the exact law gave a constant profile");
    return cells;
}

// The bark's radius is a coordinate of the tables: knots every kBarkStep_cm, read linearly
// between the two about a bough's radius, so that a forest's boughs, whose branches thin
// continuously, share a few tables. What the bark hides grows about linearly with its radius
// (needle length per area falls as 1 / rho), so the reading is near the exact law's.
constexpr double kBarkStep_cm = 0.125;
struct BarkPlace {
    double below_cm, above_cm, t;  ///< the knots about the radius, and its place between
};
BarkPlace barkPlace(double radius_cm)
{
    const double u = std::max(0.0, radius_cm) / kBarkStep_cm, below = std::floor(u);
    return {below * kBarkStep_cm, (below + 1.0) * kBarkStep_cm, u - below};
}
// (1 - t) a + t b, element by element.
std::vector<double> mixed(std::vector<double> a, const std::vector<double>& b, double t)
{
    for (std::size_t i = 0; i < a.size(); ++i) a[i] += t * (b[i] - a[i]);
    return a;
}

// Everything the exact law's profiles depend on besides the directions, the length and what a
// render needs of it, with the bark at one of its knots.
using Kind =
    std::tuple<double, double, double, double, double, double, double, const LayerModel*>;
Kind kindOf(const TracedBough& b, double bark_cm, const LayerModel& layers)
{
    const analytic::ConeGeometry& c = b.geometry.cone;
    return {c.aperture_rad, c.needleLength_cm, c.needleRadius_cm, c.needlesPerCone,
            b.geometry.coneSpacing_cm, b.exponent, bark_cm, &layers};
}

// The exact law tabulated for one kind of bough.
class Tables {
public:
    Tables(const BoughLaw& exact, const TracedBough& like, double bark_cm,
           const LayerModel& layers)
        : mExact(exact), mGeometry(like.geometry), mExponent(like.exponent), mBark_cm(bark_cm),
          mLayers(layers),
          mReach(like.geometry.cone.needleLength_cm * std::cos(like.geometry.cone.aperture_rad)),
          mView({kViewKnots, kCountKnots, kWithinKnots}, 2 * kCells * kAzimuthBins,
                [this](const auto& i) {
                    const Vec3 V = view(i[0]);
                    const TracedBough b = bough(i[1], i[2], V);
                    return integrated(
                        b, {exactSeenByAzimuth(b, V, mLayers, kChordDensity, kAzimuthBins)});
                }),
          mFromLight({kLightKnots, kCountKnots, kWithinKnots}, kCells, [this](const auto& i) {
              const Vec3 L = light(i[0], 0);
              const TracedBough b = bough(i[1], i[2], L);
              return integrated(b, {cellsOf(mExact.opacityFromLight(b, L, mLayers))});
          })
    {
    }

    /// Where a bough of `length_cm` falls among the lengths, and what turns an integral over
    /// its strip into its profile.
    struct Length {
        Place count, within;
        double perStrip;  // 1 / (L + l cos(phi)), 1/cm
    };
    Length length(double length_cm) const
    {
        const double dh = mGeometry.coneSpacing_cm, u = length_cm / dh;
        const double n = std::floor(u) + 1.0;
        const int count = n < double(1 << 30) ? int(n) : 1 << 30;
        return {placeCount(count), {0, std::clamp(u - (n - 1.0), 0.0, 1.0)},
                1.0 / (length_cm + mReach)};
    }

    /// What each half shows: [half][cell][azimuth bin].
    std::vector<double> viewSeen(double thetaV, const Length& l) const
    {
        return mView.at({place(thetaV, kPi, kViewKnots), l.count, l.within}, l.perStrip);
    }
    std::vector<double> fromLight(double thetaL, const Length& l) const
    {
        return mFromLight.at({place(thetaL, kPi, kLightKnots), l.count, l.within}, l.perStrip);
    }
    /// Each light's transfer, diffuse and specular profiles, front and rear, in that order.
    std::vector<double> lightValues(double thetaV, double thetaL, double azimuth,
                                    const Length& l, const BoughLawNeeds& needs) const
    {
        return lightTable(needs).at({place(thetaV, kPi, kViewKnots),
                                     place(thetaL, kPi, kLightKnots),
                                     place(azimuth, kPi, kAzimuthKnots), l.count, l.within},
                                    l.perStrip);
    }

private:
    // The canonical frame: the axis along z, the view in the x-z plane (e_v = x), the strip
    // across y.
    static Vec3 view(int i)
    {
        const double theta = knot(i, kViewKnots, kPi);
        return {std::sin(theta), 0.0, std::cos(theta)};
    }
    static Vec3 light(int i, int j)
    {
        const double theta = knot(i, kLightKnots, kPi), azimuth = knot(j, kAzimuthKnots, kPi);
        return {std::sin(theta) * std::cos(azimuth), std::sin(theta) * std::sin(azimuth),
                std::cos(theta)};
    }
    // A bough of kConeCounts[count] cones, as short as they allow (within 0) or as long.
    TracedBough bough(int count, int within, const Vec3& V) const
    {
        constexpr double kInside = 1e-6;  // of dh: floor(L / dh) must give the count's
        const double cones = double(kConeCounts[count]) - 1.0 + kInside +
                             double(within) * (1.0 - 2.0 * kInside);
        BoughDescription d;
        d.spec.tip_cm = Vec3(0.0, 0.0, cones * mGeometry.coneSpacing_cm);
        d.spec.needles = mGeometry;
        d.exponent = mExponent;
        d.barkRadius_cm = mBark_cm;
        TracedBough b =
            makeTracedBough(d, d.spec.tip_cm * 0.5 + 1e4 * V, {}, mExact, mLayers, {});
        b.across = Vec3(0.0, 1.0, 0.0);
        return b;
    }
    // Profiles of b, integrated along its strip (Q): what the table holds.
    std::vector<double> integrated(const TracedBough& b,
                                   std::initializer_list<std::vector<double>> parts) const
    {
        std::vector<double> out;
        for (const auto& p : parts) out.insert(out.end(), p.begin(), p.end());
        for (double& v : out) v *= b.length_cm + mReach;
        return out;
    }
    const LazyTable<5>& lightTable(const BoughLawNeeds& needs) const
    {
        const int which = (needs.transfer ? 1 : 0) | (needs.diffuse ? 2 : 0) |
                          (needs.specular ? 4 : 0);
        std::call_once(mLightOnce[which], [&] {
            mLight[which] = std::make_unique<LazyTable<5>>(
                LazyTable<5>::Knots{kViewKnots, kLightKnots, kAzimuthKnots, kCountKnots,
                                    kWithinKnots},
                6 * kCells, [this, needs](const auto& i) {
                    const Vec3 V = view(i[0]);
                    const TracedBough b = bough(i[3], i[4], V);
                    const BoughShading s =
                        mExact.shade(b, V, {light(i[1], i[2])}, mLayers, needs);
                    const BoughLightTransfer& t = s.lights.at(0);
                    return integrated(
                        b, {cellsOf(t.transfer.front), cellsOf(t.transfer.rear),
                            cellsOf(t.diffuse.front), cellsOf(t.diffuse.rear),
                            cellsOf(t.specular.front), cellsOf(t.specular.rear)});
                });
        });
        return *mLight[which];
    }

    const BoughLaw& mExact;
    analytic::BoughGeometry mGeometry;
    double mExponent;
    double mBark_cm;  ///< the boughs' bark radius: a knot
    const LayerModel& mLayers;
    double mReach;  // l cos(phi), cm: how far the cones reach past the tip
    LazyTable<3> mView, mFromLight;
    // One per combination of what a render needs.
    mutable std::array<std::once_flag, 8> mLightOnce;
    mutable std::array<std::unique_ptr<LazyTable<5>>, 8> mLight;
};

// Each part's cells (kCells of them, one part after another) in reverse order: the values for
// a light on the other side of the plane of the axis and the view.
std::vector<double> reversedCells(std::vector<double> v)
{
    for (auto from = v.begin(); from != v.end(); from += kCells) std::reverse(from, from + kCells);
    return v;
}

FrontRearProfile profiles(const std::vector<double>& v, int part)
{
    const auto cells = [&](int p) {
        return std::vector<double>(v.begin() + p * kCells, v.begin() + (p + 1) * kCells);
    };
    return {StripProfile::sampled(cells(part)), StripProfile::sampled(cells(part + 1))};
}

double angleTo(const Vec3& axis, const Vec3& u)
{
    return std::acos(std::clamp(glm::dot(axis, u), -1.0, 1.0));
}

class CorrectedBoughLaw final : public BoughLaw {
public:
    CorrectedBoughLaw() : mExact(makeExactBoughLaw(kChordDensity)) {}

    BoughLawTraits traits() const override { return mExact->traits(); }
    std::shared_ptr<const BoughLaw> fresh() const override
    {
        return std::make_shared<CorrectedBoughLaw>();
    }

    BoughShading shade(const TracedBough& b, const Vec3& V,
                       const std::vector<Vec3>& towardsLights, const LayerModel& layers,
                       const BoughLawNeeds& needs) const override
    {
        // Each table's values at the bough, mixed between the bark's two knots.
        const BarkPlace bark = barkPlace(b.barkRadius_cm);
        const Tables& t = tables(b, layers, bark.below_cm);
        const Tables* above = bark.t > 0.0 ? &tables(b, layers, bark.above_cm) : nullptr;
        const auto read = [&](auto&& value) {
            return above ? mixed(value(t), value(*above), bark.t) : value(t);
        };
        const Tables::Length length = t.length(b.length_cm);
        const double thetaV = angleTo(b.axis, V);
        const std::vector<double> seen =
            read([&](const Tables& at) { return at.viewSeen(thetaV, length); });
        std::vector<double> alpha(2 * kCells, 0.0);
        for (std::size_t i = 0; i < seen.size(); ++i) alpha[i / kAzimuthBins] += seen[i];
        std::vector<std::vector<double>> lights;
        const Vec3 ev = glm::cross(b.across, b.axis);
        for (const Vec3& L : towardsLights) {
            if (needs.transfer) {
                const double azimuth = std::atan2(glm::dot(L, b.across), glm::dot(L, ev));
                lights.push_back(read([&](const Tables& at) {
                    return at.lightValues(thetaV, angleTo(b.axis, L), std::abs(azimuth), length,
                                          needs);
                }));
                if (azimuth < 0.0) lights.back() = reversedCells(lights.back());
            } else {
                lights.push_back(unshadowed(b, V, L, seen, alpha, ev, needs));
            }
        }
        // As the exact law: a cell whose halves add up past 1 (oblique chords past the strip's
        // ends) is scaled back to a coverage.
        for (int k = 0; k < kCells; ++k) {
            const double total = alpha[k] + alpha[kCells + k];
            if (!(total > 1.0)) continue;
            for (int part = 0; part < 2; ++part) alpha[part * kCells + k] /= total;
            for (auto& v : lights) {
                for (int part = 0; part < 6; ++part) v[part * kCells + k] /= total;
            }
        }
        BoughShading out;
        out.alpha = profiles(alpha, 0);
        for (const auto& v : lights) {
            out.lights.push_back({profiles(v, 0), profiles(v, 2), profiles(v, 4)});
        }
        return out;
    }

    StripProfile opacityFromLight(const TracedBough& b, const Vec3& towardsLight,
                                  const LayerModel& layers) const override
    {
        const BarkPlace bark = barkPlace(b.barkRadius_cm);
        const auto read = [&](double bark_cm) {
            const Tables& t = tables(b, layers, bark_cm);
            return t.fromLight(angleTo(b.axis, towardsLight), t.length(b.length_cm));
        };
        std::vector<double> cells = read(bark.below_cm);
        if (bark.t > 0.0) cells = mixed(cells, read(bark.above_cm), bark.t);
        for (double& c : cells) c = std::clamp(c, 0.0, 1.0);
        return StripProfile::sampled(cells);
    }

private:
    // Without self-shadowing: the transfer is the opacity, and each half reflects its bins'
    // shares times eqs. 1-2 at each bin's needle direction, in the layout of
    // Tables::lightValues.
    static std::vector<double> unshadowed(const TracedBough& b, const Vec3& V, const Vec3& L,
                                          const std::vector<double>& seen,
                                          const std::vector<double>& alpha, const Vec3& ev,
                                          const BoughLawNeeds& needs)
    {
        const double phi = b.geometry.cone.aperture_rad;
        std::array<double, kAzimuthBins> diffuse{}, specular{};
        for (int i = 0; i < kAzimuthBins; ++i) {
            const double psi = -kPi + (i + 0.5) * 2.0 * kPi / kAzimuthBins;
            const Vec3 needle =
                std::cos(phi) * b.axis +
                std::sin(phi) * (std::cos(psi) * ev + std::sin(psi) * b.across);
            if (needs.diffuse) diffuse[i] = analytic::needleDiffuse(needle, L, V);
            if (needs.specular) specular[i] = analytic::needleSpecular(needle, L, V, b.exponent);
        }
        std::vector<double> v(6 * kCells, 0.0);
        for (int hk = 0; hk < 2 * kCells; ++hk) {
            v[hk] = alpha[hk];
            for (int i = 0; i < kAzimuthBins; ++i) {
                const double share = seen[std::size_t(hk) * kAzimuthBins + i];
                v[2 * kCells + hk] += share * diffuse[i];
                v[4 * kCells + hk] += share * specular[i];
            }
        }
        return v;
    }

    // The tables of b's kind with the bark at the knot bark_cm.
    const Tables& tables(const TracedBough& b, const LayerModel& layers, double bark_cm) const
    {
        std::lock_guard<std::mutex> lock(mMutex);
        auto& slot = mTables[kindOf(b, bark_cm, layers)];
        if (!slot) slot = std::make_unique<Tables>(*mExact, b, bark_cm, layers);
        return *slot;
    }

    std::unique_ptr<BoughLaw> mExact;
    mutable std::mutex mMutex;
    mutable std::map<Kind, std::unique_ptr<Tables>> mTables;
};

}  // namespace

std::unique_ptr<BoughLaw> makeCorrectedBoughLaw() { return std::make_unique<CorrectedBoughLaw>(); }

}  // namespace pine::vdbtrace
