// Tree by tree, what a render's foliage covers and how bright it is, against a truth: the bias
// of a method per tree (docs/models.md, "Whole scenes"). The trees are segmented by the
// truth's "tree" AOV, and every pixel belongs to one tree's region (the nearest pixel that
// names one), so that a method's foliage where the truth has none still counts, and every
// method is measured over the same regions.
#pragma once

#include "pine/vdbtrace/image.h"

#include <cstddef>
#include <vector>

namespace pine::vdbtrace {

/// Per pixel (scanline order) the tree of the nearest pixel, in 4-neighbour steps, whose
/// "tree" AOV names one (>= 0; of two as near, the earlier in scanline order); all -1 if none
/// does. Throws ImageError without a "tree" AOV.
std::vector<int> treeRegions(const Image& segmentation);

/// One tree's foliage in an image, over its region.
struct TreeFoliage {
    int tree = -1;
    std::size_t pixels = 0;  ///< in its region
    double coverage = 0.0;   ///< the "foliage" AOV summed over the region, in pixels
    /// The foliage-weighted mean luminance of the region's pixels (sum of luminance x foliage
    /// over the sum of foliage); 0 without foliage.
    double luminance = 0.0;
};

/// Per tree of `regions` (as treeRegions gives them, for an image of the same size), by
/// increasing tree index. Throws ImageError for another size or an image without "foliage".
std::vector<TreeFoliage> foliageByTree(const Image& image, const std::vector<int>& regions);

/// A tree's foliage in an image over the truth's: coverage and luminance as ratios - 1.
struct TreeBias {
    TreeFoliage image, truth;
    double coverageBias = 0.0, luminanceBias = 0.0;
};

/// Every tree of the truth's "tree" AOV, `image` against `truth`; trees whose truth covers
/// fewer than `minCoverage` pixels (or none) are left out (their ratios are noise).
std::vector<TreeBias> treeBiases(const Image& image, const Image& truth, double minCoverage = 20.0);

}  // namespace pine::vdbtrace
