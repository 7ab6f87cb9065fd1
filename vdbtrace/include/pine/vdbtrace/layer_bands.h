// Evenly spaced needles along a line through a baked field (the "fibre" extinction law, errata
// E13): a line meets one cone's needles over a band, the part of it within one layer of that
// cone on which the layer coordinate g / dh moves one way (cone_crossings.h draws the same
// bands on the true cones). If it meets n needles on average there, evenly spaced thin needles
// stop it with probability min(1, n), where a Poisson medium would let exp(-n) through.
//
// A voxel's field does not say where its cones lie: a line entering a bough meets its layers at
// an unknown phase, the same all through the bough (on its way back past the axis it meets the
// same layers). So the bands lie between whole numbers of layers plus a phase psi, a band also
// ends where d . G changes sign (the line turns back through the layers, as where it grazes a
// cone), and the transmittance is the mean over psi. Bands begun where the line enters, as
// this class drew them until 2026-12-06, put a layer's boundary there: K layers crossed at n
// needles each let (1 - n)^K through where the mean over the phase is (1 - n)^(K - 1)
// (1 - n + n^2 / 6), so each entry and each turn stopped about n^2 / 6 too much (lines across
// a paper bough side-on let through 0.877 of what its needles do at 0.25 cm where they now
// let through 0.911, and 0.918 at 0.125 cm where they now let through 0.952; docs/models.md).
// A line that starts on a layer (from a needle) knows where its layers lie: LayersFromALayer.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>

namespace pine::vdbtrace {

class LayerBands {
public:
    /// The phases averaged: the midpoint rule over psi in [0, 1), whose error on one layer's
    /// (1 - n psi)(1 - n (1 - psi)) is n^2 / (12 P^2) for P phases, n^2 / 768 here. Needles
    /// met along the layers (d . G = 0) join the band a phase is in, which moves with psi: there
    /// the mean jumps, and the rule errs by up to an eighth of the jump.
    static constexpr int kPhases = 8;

    /// The transmittance of the next span of the line, over which it meets `needles` needles
    /// on average (the law's rate times the span's length) and crosses `layers` layers (signed:
    /// d . G times the length), both uniform along the span. Spans must follow one another.
    /// `needles` 0 (outside the medium, or between boughs): the layers met after it are
    /// another bough's, at a phase of their own.
    double span(double needles, double layers)
    {
        if (!(needles > 0.0)) {
            leaveBough();
            return 1.0;
        }
        const double before = mMean;
        if (!(before > 0.0)) return 0.0;
        const double crossings = std::abs(layers);
        if (!(crossings > 0.0) || !std::isfinite(crossings)) {
            // Along the layers, or a gradient read from elsewhere that is not finite: the
            // needles add up in the bands begun, which keep their places.
            for (Phase& p : mPhases) p.open += needles;
        } else {
            const double sign = layers < 0.0 ? -1.0 : 1.0;
            if (sign != mSign) {
                // Entering the layers, the phase psi's next boundary lies psi ahead (1 - psi
                // going down); turning back through them (every band ends there), 1 - left.
                for (int k = 0; k < kPhases; ++k) {
                    Phase& p = mPhases[k];
                    if (mSign == 0.0) {
                        const double psi = (k + 0.5) / kPhases;
                        p.left = sign > 0.0 ? psi : 1.0 - psi;
                    } else {
                        p.close();
                        p.left = p.left < 1.0 ? 1.0 - p.left : 1.0;
                    }
                }
                mSign = sign;
            }
            cross(needles, crossings);
        }
        mMean = mean();
        return std::min(1.0, mMean / before);
    }

private:
    struct Phase {
        double closed = 1.0;  ///< the transmittance of the bands this phase has ended
        double open = 0.0;    ///< needles met in its current band so far
        double left = 1.0;    ///< layers from here to its current band's end, in (0, 1]
        /// (open NaN, as inf * 0 for infinitely many needles: opaque)
        double value() const { return open < 1.0 ? closed * (1.0 - open) : 0.0; }
        void close()
        {
            closed = value();
            open = 0.0;
        }
    };

    /// Layers crossed one way, `needles` met evenly over them: in each phase the band it is
    /// in goes on to its end, whole bands follow, and the last is left begun.
    void cross(double needles, double crossings)
    {
        const double rate = needles / crossings;  // a whole band's needles
        // Whole bands: (1 - min(1, rate))^m, m one of two values in every phase.
        const double whole = 1.0 - std::min(1.0, rate);
        const double wholeBands = std::floor(crossings);
        const double stopped = wholeBands >= 2.0 ? std::pow(whole, wholeBands - 1.0) : 1.0;
        for (Phase& p : mPhases) {
            if (crossings < p.left) {  // within its band, as most spans of fine voxels are
                p.open += needles;
                p.left -= crossings;
                continue;
            }
            p.open += rate * p.left;  // (needles * (left / crossings): no overflow)
            p.close();
            const double rest = crossings - p.left;
            const double m = std::floor(rest);
            if (m >= 1.0) {
                p.closed *= m == wholeBands - 1.0 ? stopped
                            : m == wholeBands     ? stopped * whole
                                                  : std::pow(whole, m);
            }
            p.open = rate * (rest - m);
            p.left = 1.0 - (rest - m);
        }
    }

    void leaveBough()
    {
        mCarried = mMean;
        mPhases = {};
        mSign = 0.0;
    }

    double mean() const
    {
        double sum = 0.0;
        for (const Phase& p : mPhases) sum += p.value();
        return mCarried * (sum / kPhases);
    }

    std::array<Phase, kPhases> mPhases{};
    double mCarried = 1.0;  ///< the transmittance of the boughs the line has left
    double mMean = 1.0;     ///< mean(), as the last span left it
    double mSign = 0.0;     ///< of d . G in the current bands; 0: none begun
};

/// The layers of a line that starts on one of them (a needle's point): where they lie is known,
/// at every whole number of layers crossed from the start, counted signed, so that a line
/// turning back through the layers (g, concave along a line, rises to a maximum near where it
/// passes the axis, then falls) meets the same layer positions on its way back, and its own layer
/// again. Bands begun at the turn would spread a layer over the band: from a needle, each turn
/// would count half a layer more than the line meets on average.
class LayersFromALayer {
public:
    /// As LayerBands::span: the next span, `needles` met on average, `layers` crossed (signed).
    double span(double needles, double layers)
    {
        // A field read from elsewhere may hold a non-finite gradient: its needles stop the
        // line as one layer's would, and where the layers lie stays known.
        if (!std::isfinite(layers)) return needles > 0.0 ? 1.0 - std::min(1.0, needles) : 1.0;
        const double from = mCrossed;
        mCrossed += layers;
        // Layer positions passed: integers in (from, to] rising, [to, from) falling; the
        // start's own layer, 0, is not met leaving it either way.
        const double met = layers > 0.0   ? std::floor(mCrossed) - std::floor(from)
                           : layers < 0.0 ? std::ceil(from) - std::ceil(mCrossed)
                                          : 0.0;
        if (!(met > 0.0) || !(needles > 0.0)) return 1.0;
        return std::pow(1.0 - std::min(1.0, needles / std::abs(layers)), met);
    }

private:
    double mCrossed = 0.0;  ///< layers crossed from the start, signed
};

}  // namespace pine::vdbtrace
