// A frame's render crossing between ranks (ranks.h): as bytes, and put together from bands of
// rows rendered apart. A band's pixels are computed as the whole frame's are (each pixel
// alone, render_driver.h), so the frame put together is the one-process frame, bit for bit.
#pragma once

#include "pine/vdbtrace/ranks.h"
#include "pine/vdbtrace/render_result.h"

#include <vector>

namespace pine::vdbtrace {

/// `render` (its image with every AOV, stats, times and tree sums) as bytes, and back.
/// unpackRender throws std::runtime_error on bytes that are not a packed render.
Bytes packRender(const RenderResult& render);
RenderResult unpackRender(const Bytes& bytes);

/// `window` cut into at most `count` bands of whole rows, top to bottom, each starting on a
/// multiple of `tileRows` rows from the window's top (so the bands' tiles are the window's):
/// fewer where the window has fewer tile rows than `count`. Empty bands are left out.
std::vector<PixelWindow> rowBands(const PixelWindow& window, int count, int tileRows);

/// The renders of `bands` (in that order, each of that band of one frame) as one render of
/// `window`: pixels and AOVs placed, stats and tree sums added (the sums in band order: equal
/// to the one-process render's to rounding), the slowest band's seconds.
/// Throws std::invalid_argument if a render's size is not its band's.
RenderResult joinBands(std::vector<RenderResult> renders, const std::vector<PixelWindow>& bands,
                       const PixelWindow& window);

}  // namespace pine::vdbtrace
