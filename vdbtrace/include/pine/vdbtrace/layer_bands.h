// Evenly spaced needles along a line through a baked field (the "fibre" extinction law, errata
// E13): a line meets one cone's needles over a band, the part of it within one layer of that
// cone on which the layer coordinate g / dh moves one way (cone_crossings.h draws the same
// bands on the true cones). If it meets n needles on average there, evenly spaced thin needles
// stop it with probability min(1, n), where a Poisson medium would let exp(-n) through.
//
// A voxel's field does not say where its cone lies, so the bands are drawn from where the line
// enters the medium: a band ends where d . G changes sign (the line turns back through the
// layers, as where it grazes a cone) or once it has crossed one whole layer.
// A line that starts on a layer (from a needle) knows where its layers lie: LayersFromALayer.
#pragma once

#include <algorithm>
#include <cmath>

namespace pine::vdbtrace {

class LayerBands {
public:
    /// The transmittance of the next span of the line, over which it meets `needles` needles
    /// on average (the law's rate times the span's length) and crosses `layers` layers (signed:
    /// d . G times the length), both uniform along the span. Spans must follow one another.
    double span(double needles, double layers)
    {
        if (!(needles > 0.0)) {
            mCrossed = 1.0;  // outside the medium, or between boughs: the next span begins one
            return 1.0;
        }
        const double crossings = std::abs(layers);
        if (!(crossings > 0.0)) {  // along the layers: within the band, whichever way it runs
            if (mCrossed >= 1.0) begin();
            return stretch(needles);
        }
        const double sign = layers < 0.0 ? -1.0 : 1.0;
        if (sign != mSign) {
            mSign = sign;
            mCrossed = 1.0;  // the line turned back through the layers: a new band
        }
        double left = crossings, T = 1.0;
        if (mCrossed < 1.0) {  // the band begun before this span, finished first
            const double step = std::min(left, 1.0 - mCrossed);
            T *= stretch(needles * (step / crossings));  // no overflow for tiny crossings
            mCrossed += step;
            left -= step;
        }
        if (left >= 1.0) {
            // Whole bands, each met from its start by needles / crossings needles: at once, as
            // a layer spacing of 1e-6 cm puts a million in one voxel.
            const double whole = std::floor(left);
            T *= std::pow(1.0 - std::min(1.0, needles / crossings), whole);
            mCrossed = 1.0;
            left -= whole;
        }
        if (left > 0.0) {  // the band this span leaves begun
            begin();
            T *= stretch(needles * (left / crossings));
            mCrossed = left;
        }
        return T;
    }

private:
    void begin()
    {
        mCrossed = 0.0;
        mNeedles = 0.0;
    }
    /// The band's transmittance from mNeedles to mNeedles + more, then mNeedles advanced.
    double stretch(double more)
    {
        const double before = 1.0 - std::min(1.0, mNeedles);
        mNeedles += more;
        const double after = 1.0 - std::min(1.0, mNeedles);
        return before > 0.0 ? after / before : 0.0;
    }

    double mNeedles = 0.0;  ///< met in the current band so far
    double mCrossed = 1.0;  ///< layers crossed in the current band; 1: none begun
    double mSign = 0.0;     ///< of d . G in the current band
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
