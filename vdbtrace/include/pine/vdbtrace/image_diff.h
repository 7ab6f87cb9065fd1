// `vdbtrace diff`: how far an image is from a reference, per pixel and overall.
#pragma once

#include "pine/vdbtrace/image.h"

#include <nlohmann/json.hpp>

#include <string>
#include <vector>

namespace pine::vdbtrace {

/// Errors of `image` against `reference` (same size), on linear luminance of premultiplied RGB.
struct ImageErrors {
    Image error;             ///< RGB: |image - reference| per channel; AOV "error": luminance
    double rmse = 0.0;       ///< root mean square luminance error over all pixels
    /// mean |e| / reference over pixels where reference > floor; NaN (null in JSON) for none
    double meanRelative = 0.0;
    double maxAbsolute = 0.0;
    double relativeFloor = 0.0;  ///< 1% of the reference's mean luminance
    std::size_t pixels = 0, relativePixels = 0;
    /// The same restricted to the pixels where `image`'s "level" AOV rounds to 0 (no foliage),
    /// 1 (needle), 2 (cone) or 3 (bough): which approximation costs what. Empty without it.
    struct ByLevel {
        double rmse = 0.0, meanRelative = 0.0;
        std::size_t pixels = 0, relativePixels = 0;
    };
    std::vector<ByLevel> byLevel;
    /// The luminance error after box-downsampling both images by k (the mean of each whole k x
    /// k block; a partial block at the right or bottom edge is left out): the error a viewer
    /// sees once a block's needle texture is averaged. Noise falls as 1 / k, a bias does not,
    /// so per-pixel RMSE alone rewards a smooth biased method (issue: a fair comparison).
    struct AtScale {
        int k = 1;
        double rmse = 0.0, mae = 0.0;  ///< over the blocks
        std::size_t blocks = 0;
    };
    /// At each of kErrorScales that leaves at least one whole block, in that order.
    std::vector<AtScale> byScale;
    /// Foliage black where the reference's is lit (issue 9: no bough shadow or bough face black
    /// where the truth is not; the paper's clamped laws cast solid black shadows), after
    /// box-downsampling both images' "foliage" and "foliage_luminance" AOVs by k. Over the
    /// blocks where both images' foliage covers at least kBlackFoliageCoverage and the
    /// reference's own foliage luminance (foliage_luminance / foliage) is at least
    /// kBlackFoliageFraction of its mean over them (`blocks`): those where the image's own
    /// foliage luminance is below kBlackFoliageFraction of the reference's (`black`). A pixel
    /// of needles may be black where the truth's shadow rays passed between the needles a
    /// shadow cone reads as their mean; a few pixels' block, a bough's width, may not.
    struct BlackFoliage {
        int k = 1;
        std::size_t blocks = 0, black = 0;
    };
    /// At each of kErrorScales that leaves a whole block, in that order; empty unless both
    /// images have both AOVs.
    std::vector<BlackFoliage> blackFoliage;
    /// The entry of byScale at k, or null.
    const AtScale* atScale(int k) const;
    nlohmann::json toJson() const;
};

/// The box-downsampling factors ImageErrors::byScale is measured at.
inline constexpr int kErrorScales[] = {1, 2, 4, 8, 16};
/// ImageErrors::BlackFoliage's: the foliage coverage a pixel needs, and the fraction of the
/// reference's foliage luminance below which foliage counts as unlit (the reference's) or black
/// (the image's). A quarter: far below the spread of lit foliage, far above what a solid
/// shadow lets through.
inline constexpr double kBlackFoliageCoverage = 0.5, kBlackFoliageFraction = 0.25;

/// Throws ImageError if the sizes differ, if the two are crops of different windows of a frame
/// (Image::originX...), or if either has a colour that is not finite (NaN or infinity: no
/// error can be measured against it), naming each as `imageName` and `referenceName`.
ImageErrors compareImages(const Image& image, const Image& reference,
                          const std::string& imageName = "the image",
                          const std::string& referenceName = "the reference");

/// False colours (black - blue - green - yellow - white) of the luminance error from 0 to
/// `scale`, with a colour bar along the bottom (0 at the left, `scale` at the right; the scale is
/// also in the file's metadata), as 8-bit PNG, atomically.
void writeErrorPng(const ImageErrors& errors, double scale, const std::filesystem::path& path);

}  // namespace pine::vdbtrace
