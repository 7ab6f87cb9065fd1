// What a camera ray meets: fragments (partial coverages of its footprint, each with its
// radiance), composited front to back with Porter & Duff's "over". Every method hands its
// hits to the same compositor, so that the pixel means the same thing whichever shaded it.
#pragma once

#include "pine/vdbtrace/geometry.h"
#include "pine/vdbtrace/tree_foliage_tally.h"

#include <algorithm>
#include <limits>

namespace pine::vdbtrace {

/// Linear luminance (Rec. 709 primaries) of linear RGB: the AOVs' and the errors' measure.
inline double luminance(const Vec3& c) { return 0.2126 * c.x + 0.7152 * c.y + 0.0722 * c.z; }

struct Fragment {
    double t = 0.0;                    ///< distance along the ray, cm: where it sorts
    double alpha = 0.0;                ///< fraction of the footprint covered, in [0, 1]
    Vec3 diffuse{0.0}, specular{0.0};  ///< radiance, premultiplied by alpha
    int level = 0;                     ///< 1-3: the multiscale level that shaded it; 0: none
    bool foliage = false;              ///< needles, at any scale: the "foliage" AOV
    int tree = -1;  ///< the scene's tree (index of its placement) it belongs to; -1: none known
};

/// How much of a footprint each tree's foliage covers: a few trees, the largest kept.
template <int Slots>
struct TreeShares {
    int tree[Slots]{};
    double weight[Slots]{};
    int count = 0;

    void add(int id, double w)
    {
        if (id < 0 || !(w > 0.0)) return;
        for (int k = 0; k < count; ++k) {
            if (tree[k] == id) {
                weight[k] += w;
                return;
            }
        }
        if (count < Slots) {
            tree[count] = id;
            weight[count++] = w;
            return;
        }
        int least = 0;  // full: the new share replaces the smallest if larger
        for (int k = 1; k < Slots; ++k) least = weight[k] < weight[least] ? k : least;
        if (w > weight[least]) {
            tree[least] = id;
            weight[least] = w;
        }
    }
    template <int Other>
    void add(const TreeShares<Other>& other)
    {
        for (int k = 0; k < other.count; ++k) add(other.tree[k], other.weight[k]);
    }
    /// The tree of the largest share, -1 if none.
    int dominant() const
    {
        int best = -1;
        double most = 0.0;
        for (int k = 0; k < count; ++k) {
            if (weight[k] > most || (weight[k] == most && tree[k] < best)) {
                most = weight[k];
                best = tree[k];
            }
        }
        return best;
    }
};

/// One camera ray's fragments composited, front to back.
struct SampleValue {
    Vec3 diffuse{0.0}, specular{0.0};  ///< premultiplied
    double alpha = 0.0;                ///< accumulated coverage, at most 1
    double foliage = 0.0;              ///< the part of alpha that foliage fragments gave
    /// The luminance that foliage fragments gave (premultiplied, as seen through what lies in
    /// front): over `foliage`, the foliage's own mean luminance, whatever lies behind it.
    double foliageLuminance = 0.0;
    double levelWeight[4] = {0.0, 0.0, 0.0, 0.0};  ///< the part each level gave (0: none)
    double levelSum = 0.0;             ///< sum over fragments of their part times level
    TreeShares<4> trees;               ///< the part of foliage each tree gave
    /// Where the accumulated coverage passes 1/2 (the fragment's t), infinite if it never does.
    double depth = std::numeric_limits<double>::infinity();
};

class FrontToBack {
public:
    /// Accumulated coverage beyond which nothing behind can show.
    static constexpr double kOpaque = 0.999;

    FrontToBack() = default;
    /// Also tells `tally` each foliage fragment's part of the composite, times `sampleWeight`
    /// (the sample's share of its pixel).
    FrontToBack(TreeFoliageTally* tally, double sampleWeight)
        : mTally(tally), mSampleWeight(sampleWeight)
    {
    }

    /// Adds `f` behind everything added so far. A method stops adding once opaque(): the
    /// multiscale method before each fragment, the reference before each voxel span.
    void add(const Fragment& f)
    {
        const double weight = (1.0 - mValue.alpha) * f.alpha;
        mValue.diffuse += (1.0 - mValue.alpha) * f.diffuse;
        mValue.specular += (1.0 - mValue.alpha) * f.specular;
        if (f.foliage) {
            const double shown = (1.0 - mValue.alpha) * luminance(f.diffuse + f.specular);
            mValue.foliage += weight;
            mValue.foliageLuminance += shown;
            mValue.trees.add(f.tree, weight);
            if (mTally) mTally->add(f.tree, mSampleWeight * weight, mSampleWeight * shown);
        }
        if (f.level > 0) {
            mValue.levelSum += weight * f.level;
            mValue.levelWeight[f.level] += weight;
        }
        if (mValue.alpha < 0.5 && mValue.alpha + weight >= 0.5) mValue.depth = f.t;
        mValue.alpha += weight;
    }
    bool opaque() const { return mValue.alpha > kOpaque; }
    SampleValue value() const
    {
        SampleValue v = mValue;
        v.alpha = std::min(1.0, v.alpha);
        return v;
    }

private:
    SampleValue mValue;
    TreeFoliageTally* mTally = nullptr;
    double mSampleWeight = 1.0;
};

}  // namespace pine::vdbtrace
