// Each tree's foliage as the compositor shows it, summed over a render fragment by fragment:
// every fragment knows its tree, so a pixel two trees share gives each its own part, where the
// "tree" AOV names one tree a pixel and the truth's regions hand a method's foliage over a
// neighbour's pixels to that neighbour. The exact per-tree measure of a method's bias (issue:
// a fair comparison, "bias per tree"); `vdbtrace diff` uses it where both images carry it.
#pragma once

#include <map>
#include <vector>

namespace pine::vdbtrace {

/// One tree's foliage over a render, both summed over its pixels: its coverage (in pixels, as
/// the "foliage" AOV counts it) and its luminance as seen (premultiplied, as the
/// "foliage_luminance" AOV counts it). luminance / coverage_px is its mean foliage luminance.
struct TreeFoliageSum {
    int tree = -1;
    double coverage_px = 0.0;
    double luminance = 0.0;
    bool operator==(const TreeFoliageSum&) const = default;
};

/// Sums per tree, each in the order its parts are added: a tile's in pixel and sample order,
/// the tiles' in tile order (render_driver.cpp), so that the totals do not depend on threads.
class TreeFoliageTally {
public:
    /// Tree `tree`'s foliage showed `coverage` of a footprint with luminance `luminance`
    /// (premultiplied), each already weighted by the sample's share of its pixel. Trees < 0
    /// (none known) are not counted.
    void add(int tree, double coverage, double luminance)
    {
        if (tree < 0) return;
        TreeFoliageSum& s = mSums[tree];
        s.coverage_px += coverage;
        s.luminance += luminance;
    }
    void add(const TreeFoliageTally& other)
    {
        for (const auto& [tree, s] : other.mSums) add(tree, s.coverage_px, s.luminance);
    }
    void clear() { mSums.clear(); }
    /// By increasing tree index; trees that showed nothing are left out.
    std::vector<TreeFoliageSum> sums() const
    {
        std::vector<TreeFoliageSum> out;
        for (const auto& [tree, s] : mSums) {
            if (s.coverage_px > 0.0) out.push_back({tree, s.coverage_px, s.luminance});
        }
        return out;
    }

private:
    std::map<int, TreeFoliageSum> mSums;
};

}  // namespace pine::vdbtrace
