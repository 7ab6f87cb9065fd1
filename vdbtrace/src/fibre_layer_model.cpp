// The fibre layer model (errata E13): a layer is cone j's N needles, evenly spaced in azimuth
// from a roll of their own. A line meets them over a band (cone_crossings.h); if it would hit
// n of them on average there, it hits one with probability min(1, n): evenly spaced thin
// needles do not overlap until they cover the cone, unlike a Poisson medium's 1 - exp(-n).
// n is the needles' projected width across the line where they are: A s_v / |n . d| at an
// oblique crossing with the local coverage N r / (pi rho) for A, finite where a line grazes
// a cone. On one long paper bough seen side-on, 60 and 30 degrees from its branch, level 2
// covers 1.020, 1.009, 0.993 of the explicit needles, the paper's model 0.81, 0.82, 0.91
// (FaithfulModels.EveryLevelCoversWhatTheNeedlesCover; docs/models.md).
//
// Self-shadowing with layer_correlation "needles": a band's hits are an arc of azimuths, of
// width min(1, n) times the needles' period P = 2 pi / N, about where the line passes the cone;
// the line misses the cone's needles when no needle azimuth (roll + k P) falls in it. The line
// from a needle the camera sees towards the light crosses many of the cones the view's line
// crossed on its way in, near where it crossed them when the light is near the view: the same
// gaps let both through (the hot spot of canopies). So the light's transmittance is
// conditioned, cone by cone, on the view's line having missed that cone's needles: over the
// cone's uniform roll, P(light misses | view missed) = (1 - |V u L| / P) / (1 - |V| / P) for
// the arcs V of the view's line and L of the light's on the circle of circumference P. (Arcs
// of one cone that do not overlap make the lines' misses anti-correlated: evenly spaced
// needles leave one gap a period.) Without it (layer_correlation "independent", the paper's
// section 6) every band is independent. One long bough lit from 3 degrees off the camera gets
// 0.84 of the needles' self-shadowed light at level 1 with "independent", 0.98 with "needles"
// (FaithfulModels.ALoneBoughUnderEveryLight; docs/models.md "Layer correlation").
//
// The "arcs" model is the same needles without the bands: each passage of a line near a
// cone's sheet meets the arc of needle azimuths that cone_arcs.h finds from the needles'
// geometry, and the passages of one cone share its roll (the union of their arcs), in a
// line's own layers as in its self-shadowing. Near the axis the bands are 20-50% too opaque
// (scripts/fibre_middle_study.py); the arcs are what the needles let through on average.
#include "pine/vdbtrace/cone_arcs.h"
#include "pine/vdbtrace/cone_crossings.h"
#include "pine/vdbtrace/layer_model.h"

#include "pine/analytic/direction.h"

#include <algorithm>
#include <cmath>
#include <memory>
#include <vector>

namespace pine::vdbtrace {
namespace {

// One band of a line through a bough, as an arc of needle azimuths (radians).
struct Arc {
    long cone;
    double from, width;  ///< the arc [from, from + width], width in [0, P]
};

// The length of the union of arcs on a circle of circumference `period`, each taken modulo it.
double unionLength(std::vector<std::pair<double, double>>& pieces, const std::vector<Arc>& arcs,
                   double period)
{
    pieces.clear();
    for (const Arc& a : arcs) {
        if (a.width >= period) return period;
        double from = std::fmod(a.from, period);
        if (from < 0.0) from += period;
        const double to = from + a.width;
        if (to > period) {
            pieces.emplace_back(from, period);
            pieces.emplace_back(0.0, to - period);
        } else {
            pieces.emplace_back(from, to);
        }
    }
    std::sort(pieces.begin(), pieces.end());
    double total = 0.0, lo = 0.0, hi = 0.0;
    bool open = false;
    for (const auto& [from, to] : pieces) {
        if (!open || from > hi) {
            if (open) total += hi - lo;
            lo = from;
            hi = to;
            open = true;
        } else {
            hi = std::max(hi, to);
        }
    }
    return open ? total + hi - lo : 0.0;
}

// Calls visit(band) -> bool (false stops) for the bands of the line from x along d (d unit)
// through b's layers, the band of its own cone that x lies in left out: a needle is not
// shadowed by the band it lies in.
template <class Visit>
void forEachBandFrom(const TracedBough& b, const Vec3& x, const Vec3& d, long ownCone,
                     Visit&& visit)
{
    double tIn, tOut;
    if (!layeredInterval(b, x, d, tIn, tOut)) return;
    const bool inside = tIn <= 0.0;
    bool first = true;
    forEachConeBand(b, x, d, std::max(tIn, 0.0), tOut, [&](const ConeBand& band) {
        const bool own = first && inside && band.cone == ownCone;
        first = false;
        return own || visit(band);
    });
}

// Azimuths about b's axis, in one frame for every line through b: made once for all the lines
// a call walks (its frame is most of what making it costs).
class Azimuths {
public:
    explicit Azimuths(const TracedBough& b)
        : mBough(b),
          mCotPhi(apertureTrig(b.geometry.cone.aperture_rad).oneOverTan),
          mE1(analytic::anyPerpendicular(b.axis)),
          mE2(glm::cross(b.axis, mE1))
    {
    }
    const TracedBough& bough() const { return mBough; }
    const Vec3& e1() const { return mE1; }
    const Vec3& e2() const { return mE2; }
    // The azimuth of x about the axis (0 on it).
    double of(const Vec3& x) const
    {
        Vec3 radial;
        coneHeight(mBough, mCotPhi, x, nullptr, &radial);
        return std::atan2(glm::dot(radial, mE2), glm::dot(radial, mE1));
    }
    // The arc of cone `cone`'s needles a line meets about x, stopped there with
    // probability `opacity` (min(1, n) of its band).
    Arc arc(long cone, const Vec3& x, double opacity, double period) const
    {
        const double azimuth = of(x);
        const double width = opacity * period;
        return {cone, azimuth - 0.5 * width, width};
    }

private:
    const TracedBough& mBough;
    double mCotPhi;
    Vec3 mE1, mE2;
};

// Bits of the neighbours of a needle of cone `ownCone` at x (at x's azimuth psi_x) that the
// line from x along d (d unit) passes within r of in the passage x lies in: 1 the one at
// psi_x + P, 2 the one at psi_x - P (P the needle period); 0 where x lies in no passage of it.
// That cone's roll is known from the needle: a line from a needle near the axis stays within
// r of its cone's sheet while it sweeps a period, and meets the neighbours that independent
// rolls would miss (docs/models.md "Crossing arcs").
int neighboursReached(const Azimuths& azimuths, const ConeArc& own, const Vec3& x, double period)
{
    const double twoPi = 2.0 * analytic::kPi;
    double psi = azimuths.of(x);
    psi += twoPi * std::round((own.from + 0.5 * own.width - psi) / twoPi);
    return (own.from + own.width >= psi + period ? 1 : 0) | (own.from <= psi - period ? 2 : 0);
}

// Calls visit(arc) -> bool (false stops) for the passages of the line from x along d (d unit)
// through b's cones but the passage of cone `ownCone` that x, on one of its needles, lies in.
// That one, with `seen` >= 0 (the light's line, `seen` the neighbours the view's line from x
// reached), stops the line where it reaches a neighbour the view's line did not (a view that
// reached one was not of this needle: it says nothing) and is visited as a whole period.
// `reached`, if given, gets the neighbours the line reached (neighboursReached).
template <class Visit>
void forEachArcFrom(const Azimuths& azimuths, const Vec3& x, const Vec3& d, long ownCone,
                    double period, int seen, Visit&& visit, int* reached = nullptr)
{
    const TracedBough& b = azimuths.bough();
    if (reached) *reached = 0;
    double tIn, tOut;
    if (!layeredInterval(b, x, d, tIn, tOut)) return;
    const bool inside = tIn <= 0.0;
    bool first = true;
    forEachConeArc(b, x, d, std::max(tIn, 0.0), tOut, azimuths.e1(), azimuths.e2(),
                   [&](const ConeArc& arc) {
                       const bool own = first && inside && arc.cone == ownCone;
                       first = false;
                       if (!own) return visit(Arc{arc.cone, arc.from, arc.width});
                       const int neighbours = neighboursReached(azimuths, arc, x, period);
                       if (reached) *reached = neighbours;
                       if (seen < 0 || !(neighbours & ~seen)) return true;
                       return visit(Arc{arc.cone, arc.from, period});
                   });
}

// How a line meets a cone's needles: over smeared bands, or over the exact arcs.
enum class Crossings { Bands, Arcs };

class FibreLayerModel final : public LayerModel {
public:
    FibreLayerModel(bool correlated, Crossings crossings)
        : mCorrelated(correlated), mArcs(crossings == Crossings::Arcs)
    {
    }

    void layers(const TracedBough& b, const Vec3& o, const Vec3& d, double tIn, double tOut,
                const std::function<bool(const LayerHit&)>& visit) const override
    {
        if (mArcs) return arcLayers(b, o, d, tIn, tOut, visit);
        forEachConeBand(b, o, d, tIn, tOut, [&](const ConeBand& band) {
            return visit(LayerHit{band.cone, band.t, std::min(1.0, band.needles)});
        });
    }

    double transmittance(const TracedBough& b, const Vec3& x, const Vec3& towardsLight,
                         long ownCone, const Vec3& towardsViewer) const override
    {
        if (mCorrelated && glm::dot(towardsViewer, towardsViewer) > 0.0) {
            return walkedBoth(Azimuths(b), x, towardsLight, ownCone, towardsViewer);
        }
        if (mArcs) {  // each cone's passages share its roll
            thread_local std::vector<Arc> light;
            const Azimuths azimuths(b);
            const double period = needlePeriod(b);
            const int seen = seenNeighbours(azimuths, x, towardsViewer, ownCone, period);
            arcsAlong(azimuths, x, towardsLight, ownCone, period, light, seen);
            return light.empty() ? 1.0 : conditioned(light, nullptr, 0, period);
        }
        double transmittance = 1.0;
        forEachBandFrom(b, x, towardsLight, ownCone, [&](const ConeBand& band) {
            transmittance *= 1.0 - std::min(1.0, band.needles);
            return transmittance > 1e-6;
        });
        return transmittance;
    }

    // The view's arcs are the layers the line met in front of each needle: each layer's arc
    // once, where walking the view's line back from every needle took a walk a needle.
    void transmittancesAlong(const TracedBough& b, const Vec3& o, const Vec3& d,
                             const std::vector<LayerHit>& hits, const Vec3& towardsLight,
                             std::vector<double>& out) const override
    {
        if (!mCorrelated) return LayerModel::transmittancesAlong(b, o, d, hits, towardsLight, out);
        thread_local std::vector<Arc> view;
        thread_local std::vector<std::size_t> arcsBefore;
        const double period = needlePeriod(b);
        const Azimuths azimuths(b);
        viewArcs(azimuths, o, d, hits, period, view, arcsBefore);
        out.resize(hits.size());
        for (std::size_t k = 0; k < hits.size(); ++k) {
            out[k] = seenThrough(azimuths, o + hits[k].t * d, towardsLight, hits[k].cone, -d,
                                 view.data(), arcsBefore[k], period);
        }
    }

    // A needle's band is found by its index and g's monotone piece (cone_crossings.h); the
    // walk back from the needle would first meet what is left of that band before it, and
    // leave it out as the needle's own if it is its cone's and the needle lies inside the
    // bough. Where it would not (a needle's passage past its cone's sheet, beyond the bough,
    // or with the rest of its band hidden in the bark) the needle walks back.
    void transmittancesAt(const TracedBough& b, const Vec3& o, const Vec3& d, double tIn,
                          double tOut, const std::vector<LayerHit>& hits,
                          const std::vector<NeedleOnLine>& needles, const Vec3& towardsLight,
                          std::vector<double>& out) const override
    {
        if (mArcs) {  // from each needle's axis, which knows its azimuth
            out.resize(needles.size());
            for (std::size_t n = 0; n < needles.size(); ++n) {
                out[n] = transmittance(b, needles[n].onAxis, towardsLight, needles[n].cone, -d);
            }
            return;
        }
        if (!mCorrelated) {
            return LayerModel::transmittancesAt(b, o, d, tIn, tOut, hits, needles, towardsLight,
                                                out);
        }
        thread_local std::vector<Arc> view;
        thread_local std::vector<std::size_t> arcsBefore;
        const double period = needlePeriod(b), dh = b.geometry.coneSpacing_cm;
        const Azimuths azimuths(b);
        viewArcs(azimuths, o, d, hits, period, view, arcsBefore);
        const ConeLine line(b, o, d);
        const double turn = line.turn();
        double barkIn, barkOut;  // as forEachConeBand hides it
        barkInterval(b, o, d, barkIn, barkOut);
        // Where needle t's band begins along the line: the edge below it on the rising piece,
        // above it on the falling one, or the piece's start.
        const auto bandStart = [&](double t, long band) {
            const bool rising = t < turn;
            const double from = rising ? tIn : std::max(tIn, turn);
            const double edge = (double(band) + (rising ? -0.5 : 0.5)) * dh;
            const bool beyond = rising ? line.g(from) < edge : line.g(from) > edge;
            return beyond ? line.level(edge, from, t) : from;
        };
        out.resize(needles.size());
        for (std::size_t n = 0; n < needles.size(); ++n) {
            const NeedleOnLine& needle = needles[n];
            const Vec3 x = o + needle.t * d;
            const long band = long(std::floor(line.g(needle.t) / dh + 0.5));
            std::size_t own = hits.size();
            if (band == needle.cone && needle.t > tIn && needle.t < tOut) {
                const bool rising = needle.t < turn;
                for (std::size_t k = 0; k < hits.size(); ++k) {
                    if (hits[k].cone == band && (hits[k].t < turn) == rising) own = k;
                }
            }
            if (own < hits.size() && barkOut > barkIn) {
                const double start = bandStart(needle.t, band);
                if (!(start < barkIn || needle.t > barkOut)) own = hits.size();  // all in bark
            }
            if (own == hits.size()) {  // transmittance() towards the light, seen from -d
                out[n] = walkedBoth(azimuths, x, towardsLight, needle.cone, -d);
                continue;
            }
            out[n] = seenThrough(azimuths, x, towardsLight, needle.cone, -d, view.data(),
                                 arcsBefore[own], period);
        }
    }

private:
    // layers() over the arcs: a passage of a cone the line passed before adds what its arc
    // adds to theirs, so that the product of the layers' transmittances is the cones'.
    void arcLayers(const TracedBough& b, const Vec3& o, const Vec3& d, double tIn, double tOut,
                   const std::function<bool(const LayerHit&)>& visit) const
    {
        thread_local std::vector<Arc> before, cone;
        thread_local std::vector<std::pair<double, double>> pieces;
        before.clear();
        const Azimuths azimuths(b);
        const double period = needlePeriod(b);
        forEachConeArc(b, o, d, tIn, tOut, azimuths.e1(), azimuths.e2(), [&](const ConeArc& a) {
            const Arc arc{a.cone, a.from, a.width};
            cone.clear();
            for (const Arc& e : before) {
                if (e.cone == a.cone) cone.push_back(e);
            }
            double opacity = std::min(1.0, a.width / period);
            if (!cone.empty()) {
                const double seen = unionLength(pieces, cone, period);
                cone.push_back(arc);
                const double both = unionLength(pieces, cone, period);
                opacity = seen < period * (1.0 - 1e-9) ? (both - seen) / (period - seen) : 0.0;
            }
            before.push_back(arc);
            return visit(LayerHit{a.cone, a.t, std::clamp(opacity, 0.0, 1.0), a.from, a.width});
        });
    }

    // The light from `towardsLight` reaching x on a needle of cone `ownCone`, seen from
    // `towardsViewer`: both lines walked from x through the bough's layers.
    double walkedBoth(const Azimuths& azimuths, const Vec3& x, const Vec3& towardsLight,
                      long ownCone, const Vec3& towardsViewer) const
    {
        thread_local std::vector<Arc> light, view;
        const double period = needlePeriod(azimuths.bough());
        // The arcs' light reads the neighbours the view reached; the bands' need no view
        // where the light meets nothing.
        int seen = 0;
        if (mArcs) arcsAlong(azimuths, x, towardsViewer, ownCone, period, view, -1, &seen);
        arcsAlong(azimuths, x, towardsLight, ownCone, period, light, seen);
        if (light.empty()) return 1.0;
        if (!mArcs) arcsAlong(azimuths, x, towardsViewer, ownCone, period, view);
        return conditioned(light, view.data(), view.size(), period);
    }

    // The view's arcs of a line's layers `hits`, each once, in order; arcsBefore[k] of them
    // lie before hits[k].
    static void viewArcs(const Azimuths& azimuths, const Vec3& o, const Vec3& d,
                         const std::vector<LayerHit>& hits, double period, std::vector<Arc>& view,
                         std::vector<std::size_t>& arcsBefore)
    {
        view.clear();
        arcsBefore.resize(hits.size());
        for (std::size_t k = 0; k < hits.size(); ++k) {
            arcsBefore[k] = view.size();
            if (hits[k].arcWidth > 0.0) {
                view.push_back({hits[k].cone, hits[k].arcFrom, hits[k].arcWidth});
            } else if (hits[k].opacity > 0.0) {
                view.push_back(
                    azimuths.arc(hits[k].cone, o + hits[k].t * d, hits[k].opacity, period));
            }
        }
    }

    // The neighbours of a needle of cone `ownCone` at x that the view's line from x reached
    // (forEachArcFrom; none for no view, or the bands).
    int seenNeighbours(const Azimuths& azimuths, const Vec3& x, const Vec3& towardsViewer,
                       long ownCone, double period) const
    {
        int seen = 0;
        if (!mArcs || !(glm::dot(towardsViewer, towardsViewer) > 0.0)) return seen;
        forEachArcFrom(
            azimuths, x, towardsViewer, ownCone, period, -1, [](const Arc&) { return false; },
            &seen);
        return seen;
    }

    // The light from `towardsLight` reaching x on a needle of cone `ownCone`, seen from
    // `towardsViewer` through the view's `views` arcs from `view`.
    double seenThrough(const Azimuths& azimuths, const Vec3& x, const Vec3& towardsLight,
                       long ownCone, const Vec3& towardsViewer, const Arc* view, std::size_t views,
                       double period) const
    {
        thread_local std::vector<Arc> light;
        const int seen = seenNeighbours(azimuths, x, towardsViewer, ownCone, period);
        arcsAlong(azimuths, x, towardsLight, ownCone, period, light, seen);
        return light.empty() ? 1.0 : conditioned(light, view, views, period);
    }

    // The period of a cone's needles in azimuth (radians).
    static double needlePeriod(const TracedBough& b)
    {
        return 2.0 * analytic::kPi / scenes::wholeNeedles(b.geometry.cone.needlesPerCone);
    }

    // The arcs of the line from x along d (forEachArcFrom's, or forEachBandFrom's bands').
    // With the arcs, `seen` and `reached` as forEachArcFrom has them.
    void arcsAlong(const Azimuths& azimuths, const Vec3& x, const Vec3& d, long ownCone,
                   double period, std::vector<Arc>& out, int seen = 0, int* reached = nullptr) const
    {
        out.clear();
        if (mArcs) {
            forEachArcFrom(
                azimuths, x, d, ownCone, period, seen,
                [&](const Arc& arc) {
                    if (arc.width > 0.0) out.push_back(arc);
                    return true;
                },
                reached);
            return;
        }
        forEachBandFrom(azimuths.bough(), x, d, ownCone, [&](const ConeBand& band) {
            if (!(band.needles > 0.0)) return true;
            out.push_back(
                azimuths.arc(band.cone, x + band.t * d, std::min(1.0, band.needles), period));
            return true;
        });
    }

    // The light's transmittance along its arcs `light` (reordered), conditioned cone by cone
    // on the view's line, whose `views` arcs from `view` missed every needle.
    static double conditioned(std::vector<Arc>& light, const Arc* view, std::size_t views,
                              double period)
    {
        thread_local std::vector<Arc> cone;
        thread_local std::vector<std::pair<double, double>> pieces;
        std::sort(light.begin(), light.end(),
                  [](const Arc& a, const Arc& c) { return a.cone < c.cone; });
        double transmittance = 1.0;
        for (std::size_t i = 0; i < light.size() && transmittance > 1e-6;) {
            const long c = light[i].cone;
            std::size_t end = i;
            while (end < light.size() && light[end].cone == c) ++end;
            cone.clear();
            for (std::size_t v = 0; v < views; ++v) {
                if (view[v].cone == c) cone.push_back(view[v]);
            }
            const double seen = unionLength(pieces, cone, period);
            cone.insert(cone.end(), light.begin() + long(i), light.begin() + long(end));
            const double both = unionLength(pieces, cone, period);
            if (seen < period * (1.0 - 1e-9)) {
                transmittance *= std::max(0.0, period - both) / (period - seen);
            } else {  // the view cannot have passed: nothing to condition on
                for (std::size_t k = i; k < end; ++k) {
                    transmittance *= 1.0 - light[k].width / period;
                }
            }
            i = end;
        }
        return transmittance;
    }

    bool mCorrelated, mArcs;
};

}  // namespace

std::unique_ptr<LayerModel> makeFibreLayerModel(bool correlated)
{
    return std::make_unique<FibreLayerModel>(correlated, Crossings::Bands);
}

std::unique_ptr<LayerModel> makeArcsLayerModel(bool correlated)
{
    return std::make_unique<FibreLayerModel>(correlated, Crossings::Arcs);
}

}  // namespace pine::vdbtrace
