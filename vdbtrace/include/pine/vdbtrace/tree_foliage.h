// Tree by tree, what a render's foliage covers and how bright it is, against a truth: the bias
// of a method per tree (docs/models.md, "Whole scenes"). The trees are segmented by the
// truth's "tree" AOV, and every pixel belongs to one tree's region (the nearest pixel that
// names one), so that a method's foliage where the truth has none still counts, and every
// method is measured over the same regions.
#pragma once

#include "pine/vdbtrace/image.h"
#include "pine/vdbtrace/tree_foliage_tally.h"

#include <cstddef>
#include <optional>
#include <string>
#include <vector>

namespace pine::vdbtrace {

/// Per pixel (scanline order) the tree of the nearest pixel, in 4-neighbour steps, whose
/// "tree" AOV names one (>= 0; of two as near, the earlier in scanline order); all -1 if none
/// does. Throws ImageError without a "tree" AOV.
std::vector<int> treeRegions(const Image& segmentation);

/// How a tree's foliage luminance is measured.
enum class FoliageLuminance {
    /// The foliage's own: the "foliage_luminance" AOV (what foliage fragments gave, as seen)
    /// summed over the region, over the "foliage" AOV summed: the foliage's mean luminance,
    /// whatever lies behind it and however its coverage is spread over the pixels.
    Own,
    /// The pixels': their luminance weighted by "foliage", over "foliage" (images written
    /// before the foliage_luminance AOV). Partly covered pixels bring in what lies behind
    /// (the sky, the ground), so two methods that cover alike but spread their coverage
    /// differently over the pixels measure differently.
    Pixels,
};

/// Whether `image` has the "foliage_luminance" AOV (every render since it was added).
bool hasOwnFoliageLuminance(const Image& image);

/// One tree's foliage in an image, over its region.
struct TreeFoliage {
    int tree = -1;
    std::size_t pixels = 0;  ///< in its region
    double coverage = 0.0;   ///< the "foliage" AOV summed over the region, in pixels
    double luminance = 0.0;  ///< the foliage's mean luminance (FoliageLuminance); 0 without
};

/// Per tree of `regions` (as treeRegions gives them, for an image of the same size), by
/// increasing tree index. Throws ImageError for another size or an image without "foliage"
/// (or, measured as Own, without "foliage_luminance").
std::vector<TreeFoliage> foliageByTree(const Image& image, const std::vector<int>& regions,
                                       FoliageLuminance measure = FoliageLuminance::Own);

/// A tree's foliage in an image over the truth's: coverage and luminance as ratios - 1, NaN
/// (undefined) where the truth's is 0.
struct TreeBias {
    TreeFoliage image, truth;
    double coverageBias = 0.0, luminanceBias = 0.0;
};

/// Every tree of the truth's "tree" AOV, `image` against `truth`, measured Own where both have
/// the AOV, else both as Pixels; trees whose truth covers
/// fewer than `minCoverage` pixels (or none) are left out (their ratios are noise).
std::vector<TreeBias> treeBiases(const Image& image, const Image& truth, double minCoverage = 20.0);

/// The EXR header attribute a render's per-tree sums (RenderResult::treeFoliage) are written
/// under, as JSON text [[tree, coverage_px, luminance], ...]: numbers written to round trip.
inline constexpr const char* kTreeFoliageAttribute = "pine:tree_foliage";
std::string treeFoliageText(const std::vector<TreeFoliageSum>& sums);
/// The EXR header attribute naming the frame the sums count pixels of, as "WxH" (the whole
/// frame, a crop's too): an image resized after it was written (oiiotool --resize, to compare
/// a fine render with a truth at the scene's resolution) keeps the sums of the pixels it was
/// rendered with, and is read in its own (treeFoliageOf).
inline constexpr const char* kTreeFoliageFrameAttribute = "pine:tree_foliage_frame";
std::string frameText(int width, int height);
/// Adds a render's per-tree sums and the frame they count pixels of (frameWidth x frameHeight,
/// the camera's whole frame) to an EXR's header: the two attributes treeFoliageOf reads.
void addTreeFoliage(Metadata& header, const std::vector<TreeFoliageSum>& sums, int frameWidth,
                    int frameHeight);
/// Throws ImageError naming `where` if `text` is not what treeFoliageText writes.
std::vector<TreeFoliageSum> parseTreeFoliage(const std::string& text, const std::string& where);
/// The sums an EXR's header carries (readExr's metadata), if it carries them. Where it names
/// the frame they were summed in (kTreeFoliageFrameAttribute) and `image` (the EXR's pixels,
/// if given) is a frame of another size, they are scaled to its pixels. Throws ImageError
/// naming `where` for sums or a frame it cannot read.
std::optional<std::vector<TreeFoliageSum>> treeFoliageOf(const Metadata& metadata,
                                                         const std::string& where,
                                                         const Image* image = nullptr);

/// Every tree of `truth`, `image` against it, from each render's own sums fragment by fragment
/// (the exact attribution; TreeBias::*.pixels is 0): coverage ratio - 1 and mean luminance
/// ratio - 1. Trees whose truth covers fewer than `minCoverage` pixels are left out; a tree
/// the image does not show counts with coverage and luminance 0 (both biases -100%).
std::vector<TreeBias> treeBiases(const std::vector<TreeFoliageSum>& image,
                                 const std::vector<TreeFoliageSum>& truth,
                                 double minCoverage = 20.0);

/// A method's per-tree biases in a few numbers, as the reports state them.
struct TreeBiasSummary {
    std::size_t trees = 0;  ///< compared (TreeBias entries)
    /// Median and worst (the largest in magnitude, with its sign) of each bias over the trees
    /// where it is defined (`defined` of them; NaN for none), and the trees whose bias exceeds
    /// `beyond` in magnitude; the worst tree's index.
    struct Spread {
        double median = 0.0, worst = 0.0;
        int worstTree = -1;
        std::size_t beyond = 0, defined = 0;
    };
    Spread luminance, coverage;
    double beyond = 0.03;
};
/// Summarises `biases`; all zero for none.
TreeBiasSummary summarizeTreeBiases(const std::vector<TreeBias>& biases, double beyond = 0.03);

}  // namespace pine::vdbtrace
