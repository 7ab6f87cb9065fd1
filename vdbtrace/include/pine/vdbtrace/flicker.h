// Temporal aliasing of an image sequence: how much each pixel's brightness jumps from frame to
// frame beyond the smooth change the camera's motion causes.
#pragma once

#include "pine/vdbtrace/image.h"

#include <vector>

namespace pine::vdbtrace {

/// Mean over pixels of the standard deviation, over the frames, of the pixel's luminance
/// (linear, premultiplied RGB, as compareImages) about its least-squares line in the frame
/// index. A steady or steadily brightening pixel scores 0; a pixel whose needles alias in and
/// out as the camera moves scores the size of its jumps. The line is removed so that a slow
/// dolly, which changes every pixel a little, does not count as flicker.
/// Throws ImageError with fewer than 3 frames or frames of different sizes.
double temporalFlicker(const std::vector<Image>& frames);

}  // namespace pine::vdbtrace
