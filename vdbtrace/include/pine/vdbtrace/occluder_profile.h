// How a bough's opacity seen from a light runs along its axis (render.occluder_profile).
//
// The exact and corrected laws give a bough's opacity across its strip as the mean over the
// strip's length, base to the cones' end (exact_bough_law.cpp). Along the axis the needles are
// not even: at h from the base the cones whose needles reach h are those with apexes in
// [h - l cos(phi), h], so their share of a long bough's rises over the first l cos(phi)
// (3.9 cm on the paper's fir), holds to the last apex and falls over the cones' reach past it.
// A fir's branch is a chain of 6 cm boughs, each reaching 3.9 cm over the next. Read "even",
// at each bough's mean, two neighbours compose as independent strips where they overlap and
// one strip lies alone between: an optical depth uneven along the chain, which lets through
// more than the long bough's even one (0.255 of the light from above against the needles'
// 0.185, FaithfulModels.AChainsShadowIsWhereItsNeedlesCastIt). Read "cones", the opacity at
// h is 1 - exp(-tau share(h)), tau chosen so that its mean over the strip is the law's:
// neighbours' shares add up to a long bough's, and their optical depths to its tau.
#pragma once

#include "pine/vdbtrace/traced_scene.h"

namespace pine::vdbtrace {

/// A bough's cones along its axis: apexes over `apexes_cm` from the base, each cone's needles
/// reaching `reach_cm` (l cos(phi)) past its apex along the axis. The apexes are taken as even
/// over the bough's length; its last one lies up to a cone spacing short of the tip, which
/// the law's mean (and so tau) takes in. Either length 0: an even strip.
struct AxialCones {
    double apexes_cm = 0.0, reach_cm = 0.0;

    static AxialCones of(const TracedBough& b) { return {b.length_cm, b.conesReach_cm}; }
    /// The strip's length, base to the cones' end.
    double length() const { return apexes_cm + reach_cm; }
    /// The largest share(): min(1, apexes / reach).
    double top() const;
    /// The share of the strip's length where share() is top().
    double flatShare() const;
    /// Whether either length is 0: the strip is read even.
    bool even() const;
    /// The share of a long bough's cones whose needles reach h (cm from the base along the
    /// axis): 0 outside [0, length()], at most min(1, apexes / reach).
    double share(double h_cm) const;
    /// The opacity at h of a strip whose mean opacity over [0, length()] is `mean` (in
    /// [0, 1]): 1 - exp(-tau share(h)), the long bough's optical depth tau solved so that
    /// the mean is kept.
    double opacityAt(double mean, double h_cm) const;
    /// The mean over the strip of 1 - exp(-tau share(h)): what opacityAt inverts.
    double meanOpacity(double tau) const;
};

}  // namespace pine::vdbtrace
