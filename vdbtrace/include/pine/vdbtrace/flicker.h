// Temporal aliasing of an image sequence: how much each pixel's brightness jumps from frame to
// frame beyond the smooth change the camera's motion causes.
#pragma once

#include "pine/vdbtrace/image.h"

#include <cstdint>
#include <vector>

namespace pine::vdbtrace {

/// Mean over pixels of the standard deviation, over the frames, of the pixel's luminance
/// (linear, premultiplied RGB, as compareImages) about its least-squares line in the frame
/// index. A steady or steadily brightening pixel scores 0; a pixel whose needles alias in and
/// out as the camera moves scores the size of its jumps. The line is removed so that a slow
/// dolly, which changes every pixel a little, does not count as flicker.
/// Throws ImageError with fewer than 3 frames or frames of different sizes.
double temporalFlicker(const std::vector<Image>& frames);

/// Flicker taken apart: over the pixels of each band (a pixel's band from `band`, one entry per
/// pixel, each < bandCount; empty: every pixel in band 0), and frame by frame.
///
/// `window` 0: each pixel's line is fitted to the whole sequence, as temporalFlicker (the
/// same number): right for a short, slow move such as compare's dolly, whose pixels change
/// almost linearly. A longer path changes a pixel along a curve (a trunk sweeping across it),
/// which a single line would count as flicker: `window` 3 takes each frame's departure from
/// the line through its two neighbours, l(t) - (l(t-1) + l(t+1)) / 2, whose variance for
/// frames that jitter independently by sigma is 1.5 sigma^2, so the pixel's flicker is
/// sqrt(mean of its squares / 1.5): sigma itself, 0 for any motion linear over three frames.
/// The first and last frames then have no departure (NaN in residualPerFrame).
struct FlickerBreakdown {
    double flicker = 0.0;         ///< the mean over all pixels
    std::vector<double> perBand;  ///< the mean over the band's pixels (0 where none)
    std::vector<std::size_t> bandPixels;
    /// Frame t: the root mean square over pixels of the luminance's departure from each
    /// pixel's line at t, and the mean luminance. A frame that pops shows as a spike.
    std::vector<double> residualPerFrame, luminancePerFrame;
};
FlickerBreakdown flickerBreakdown(const std::vector<Image>& frames,
                                  const std::vector<std::uint8_t>& band = {}, int bandCount = 1,
                                  int window = 0);

/// The level bands of a multiscale sequence (kLevelBandNames): each pixel's band is its
/// "level" AOV (coverage-weighted, render_result.h) averaged over the frames that have foliage
/// there, rounded: 1 needles, 2 cones, 3 boughs; 0 where no frame has any. Throws ImageError
/// if a frame has no level AOV.
std::vector<std::uint8_t> levelBands(const std::vector<Image>& frames);
inline constexpr const char* kLevelBandNames[] = {"no foliage", "needles (level 1)",
                                                  "cones (level 2)", "boughs (level 3)"};
/// The same as CSV keys.
inline constexpr const char* kLevelBandKeys[] = {"none", "needles", "cones", "boughs"};

}  // namespace pine::vdbtrace
