// A rendered frame: premultiplied RGBA plus named single-channel AOVs, and how it is written.
#pragma once

#include "pine/support/input_error.h"

#include <cstddef>
#include <filesystem>
#include <functional>
#include <map>
#include <stdexcept>
#include <string>
#include <array>
#include <utility>
#include <variant>
#include <vector>

namespace pine::vdbtrace {

/// Linear, premultiplied RGBA in scanline order (row 0 at the top), and AOVs of one float per
/// pixel each (e.g. "level": coverage-weighted level in [1, 3], 0 where nothing was hit;
/// "depth": distance in cm to the first hit, +infinity where none).
struct Image {
    int width = 0, height = 0;
    /// A crop of a larger frame: where its top-left pixel lies in that frame, and the frame's
    /// size (0: the image is the whole frame). EXR's data and display windows.
    int originX = 0, originY = 0, frameWidth = 0, frameHeight = 0;
    std::vector<float> rgba;                         ///< 4 floats per pixel
    std::map<std::string, std::vector<float>> aovs;  ///< 1 float per pixel each

    Image() = default;
    Image(int w, int h) : width(w), height(h), rgba(std::size_t(w) * h * 4, 0.0f) {}
    float* pixel(int x, int y) { return &rgba[(std::size_t(y) * width + x) * 4]; }
    const float* pixel(int x, int y) const { return &rgba[(std::size_t(y) * width + x) * 4]; }
    std::vector<float>& aov(const std::string& name)  ///< created zero-filled on first use
    {
        auto& v = aovs[name];
        if (v.empty()) v.assign(std::size_t(width) * height, 0.0f);
        return v;
    }
};

/// A 4 x 4 matrix as OpenEXR's m44f attributes hold it (Imath): for row vectors, p' = p m,
/// its translation in the last row.
struct Matrix44 {
    std::array<std::array<float, 4>, 4> m{};
    bool operator==(const Matrix44&) const = default;
};

/// A header attribute's value: text, or typed (an EXR int, float or m44f attribute).
using MetaValue = std::variant<std::string, int, float, Matrix44>;

/// Key/value pairs stored in the file's header (render time, scene, method, settings, ...).
using Metadata = std::vector<std::pair<std::string, MetaValue>>;

/// What image reading and writing throw: about the user's input or output.
class ImageError : public InputError {
public:
    using InputError::InputError;
};

/// OpenEXR, float: a crop's pixels as the data window inside its frame's display window;
/// channels R, G, B, A and one channel per AOV named "<aov>.Y" (so that
/// viewers show each AOV as a layer), except an AOV named "Z", OpenEXR's depth channel, written
/// as is; metadata as attributes of their types. Written to a temporary name in the same
/// folder, then renamed: never half-written. Throws ImageError, also for an empty or repeated
/// metadata key and for keys that OpenEXR/OIIO interpret themselves ("compression", "name",
/// "owner", "DateTime", "oiio:*", ...), which would not come back; "worldToCamera" and
/// "worldToNDC" are taken as matrices only.
/// beforeRename, if given, runs once the EXR is written and synced, before it is renamed into
/// place: what it writes (the previews) is in place first, and if it throws the EXR is not.
void writeExr(const Image& image, const std::filesystem::path& path, const Metadata& metadata,
              const std::function<void()>& beforeRename = {});

/// 8-bit sRGB PNG preview of RGB (alpha composited over black, clamped), atomically.
void writePng(const Image& image, const std::filesystem::path& path);

/// The paper's Figure 12: each pixel coloured by the coverage-weighted level of the "level"
/// AOV (red: needle, green: cone, blue: bough, blended between; black where nothing was hit),
/// as 8-bit PNG, atomically. Throws ImageError if the image has no "level" AOV.
void writeLevelPng(const Image& image, const std::filesystem::path& path);

/// Loads what reads and writes images (OpenImageIO, in a module loaded on first use) now, once;
/// throws ImageError (one line) if it cannot. A command that will write images calls this
/// before its work, so that a broken build or install fails at once, not after the render.
void loadImageIo();

/// Reads an EXR written by writeExr back (tests, and `vdbtrace diff` later). `metadata`
/// receives the string, int, float and matrix attributes other than OpenEXR/OIIO's own,
/// sorted by key (EXR headers keep no order). A missing A channel reads as 1. Throws
/// ImageError naming the path.
Image readExr(const std::filesystem::path& path, Metadata* metadata = nullptr);

}  // namespace pine::vdbtrace
