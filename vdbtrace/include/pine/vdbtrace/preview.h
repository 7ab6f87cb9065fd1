// The PNG preview of a render as a person looks at it: the scene's background shows where the
// render's alpha is not 1 (renders keep alpha, premultiplied, without a background).
#pragma once

#include "pine/scenes/scene.h"
#include "pine/vdbtrace/image.h"

#include <filesystem>

namespace pine::vdbtrace {

/// `image` (premultiplied RGBA) over an opaque `background`: RGB += (1 - A) background, A = 1.
/// AOVs are kept.
Image overBackground(const Image& image, const scenes::Vec3& background);

/// writePng of overBackground(image, background), atomically.
void writePreviewPng(const Image& image, const scenes::Vec3& background,
                     const std::filesystem::path& path);

}  // namespace pine::vdbtrace
