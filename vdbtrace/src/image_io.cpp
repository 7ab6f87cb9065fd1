// Writing and reading frames through OpenImageIO (image_codec.h): EXR with AOV layers and
// metadata, PNG previews, the level map of the paper's Figure 12. Every write goes to a
// temporary name in the destination folder and is renamed into place, so a crash or an error
// never leaves a half-written file under the final name (a rename within one folder is atomic
// on POSIX).
#include "pine/vdbtrace/image.h"

#include "image_codec.h"
#include "pine/support/atomic_file.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <string_view>
#include <system_error>
#include <vector>

namespace pine::vdbtrace {
namespace {

namespace fs = std::filesystem;

// An AOV's channel is "<aov>.Y": viewers (and OpenEXR's layer convention) show each AOV as a
// single-channel layer. Z, OpenEXR's depth, keeps its bare name, which compositors look for.
constexpr std::string_view kAovSuffix = ".Y";
constexpr std::string_view kDepthChannel = "Z";

std::string channelOf(const std::string& aov)
{
    return aov == kDepthChannel ? aov : aov + std::string(kAovSuffix);
}

// Camera matrices, stored as pbrt-v4 stores them (m44f).
bool isCameraMatrix(std::string_view key) { return key == "worldToCamera" || key == "worldToNDC"; }

using codec::oneLine;

[[noreturn]] void fail(const char* what, const fs::path& path, const std::string& why)
{
    throw ImageError(std::string(what) + ": cannot write '" + path.string() + "': " +
                     oneLine(why));
}

void checkShape(const Image& image, const char* what, const fs::path& path)
{
    if (image.width <= 0 || image.height <= 0) {
        fail(what, path, "image size " + std::to_string(image.width) + " x " +
                             std::to_string(image.height) + " is empty");
    }
    const std::size_t pixels = std::size_t(image.width) * std::size_t(image.height);
    if (image.rgba.size() != pixels * 4) {
        fail(what, path, "rgba holds " + std::to_string(image.rgba.size()) + " floats, " +
                             std::to_string(pixels * 4) + " expected");
    }
    for (const auto& [name, values] : image.aovs) {
        if (name.empty()) fail(what, path, "an AOV has an empty name");
        if (values.size() != pixels) {
            fail(what, path, "AOV '" + name + "' holds " + std::to_string(values.size()) +
                                 " floats, " + std::to_string(pixels) + " expected");
        }
    }
}

// Header attributes that OpenEXR or OIIO interpret, rename or drop: user metadata under these
// names would change the file's meaning (compression, windows, colour space) or not come back
// from readExr, so writeExr refuses them rather than lose them silently.
bool isReservedKey(std::string_view key)
{
    static constexpr std::string_view kReserved[] = {
        "compression", "name", "type", "view", "channels", "chromaticities", "dataWindow",
        "displayWindow", "lineOrder", "pixelAspectRatio", "PixelAspectRatio",
        "screenWindowCenter", "screenWindowWidth", "tiles", "version", "chunkCount",
        "capDate", "DateTime", "comments", "owner", "multiView", "tiledesc", "envmap",
        "worldToCamera", "worldToNDC", "xDensity", "XResolution", "YResolution",
        "ResolutionUnit", "Orientation", "wrapmodes", "maxSamplesPerPixel",
    };
    if (key.starts_with("oiio:") || key.starts_with("openexr:")) return true;
    return std::find(std::begin(kReserved), std::end(kReserved), key) != std::end(kReserved);
}

// Standard attributes readExr leaves out of the metadata: OIIO reports them for every EXR
// (its writer stamps "DateTime" on every file, stored as the EXR attribute capDate).
bool isStandardAttribute(std::string_view key)
{
    return key.starts_with("oiio:") || key.starts_with("openexr:") || key == "compression" ||
           key == "name" || key == "type" || key == "view" || key == "DateTime";
}

/// Writes pixels as `format` through the shared atomic writer (support/atomic_file.h): never
/// half-written under `path`.
void writeAtomically(const char* what, const char* format, const fs::path& path,
                     const codec::Header& header, const void* pixels,
                     const std::function<void()>& beforeRename = {})
{
    const codec::Codec& codec = codec::imageCodec();
    try {
        io::writeAtomically(path, [&](const fs::path& temporary) {
            std::vector<unsigned char> bytes;
            if (codec.write(format, header, pixels, temporary, bytes)) {
                io::writeBytes(temporary,
                               {reinterpret_cast<const char*>(bytes.data()), bytes.size()});
            }
        }, beforeRename);
    } catch (const ImageError&) {
        throw;  // another image's, written by beforeRename
    } catch (const InputError& e) {
        throw ImageError(std::string(what) + ": " + e.what());
    }
}

std::uint8_t toByte(float value)
{
    // NaN and negatives go to 0; written this way because std::clamp passes NaN through.
    if (!(value > 0.0f)) return 0;
    if (value >= 1.0f) return 255;
    return static_cast<std::uint8_t>(std::lround(value * 255.0f));
}

/// The sRGB transfer function (IEC 61966-2-1) of a linear value, clamped to [0, 1] first.
float encodeSrgb(float linear)
{
    if (!(linear > 0.0f)) return 0.0f;
    if (linear >= 1.0f) return 1.0f;
    return linear <= 0.0031308f ? 12.92f * linear
                                : 1.055f * std::pow(linear, 1.0f / 2.4f) - 0.055f;
}

/// Figure 12's colour of a coverage-weighted level: 1 red (needle), 2 green (cone), 3 blue
/// (bough), linear in between; black for 0 (nothing hit) and NaN.
void levelColour(float level, float rgb[3])
{
    rgb[0] = rgb[1] = rgb[2] = 0.0f;
    if (!(level > 0.0f)) return;
    const float v = std::clamp(level, 1.0f, 3.0f);
    if (v <= 2.0f) {
        rgb[0] = 2.0f - v;
        rgb[1] = v - 1.0f;
    } else {
        rgb[1] = 3.0f - v;
        rgb[2] = v - 2.0f;
    }
}

void writeBytesPng(const char* what, const fs::path& path, int width, int height,
                   const std::vector<std::uint8_t>& rgb)
{
    codec::Header header;
    header.width = width;
    header.height = height;
    header.bytes = true;
    header.channels = {"R", "G", "B"};
    header.attributes = {{"oiio:ColorSpace", std::string("sRGB")}};
    writeAtomically(what, "png", path, header, rgb.data());
}

}  // namespace

void writeExr(const Image& image, const std::filesystem::path& path, const Metadata& metadata,
              const std::function<void()>& beforeRename)
{
    constexpr const char* what = "writeExr";
    checkShape(image, what, path);

    const int channels = 4 + int(image.aovs.size());
    codec::Header header;
    header.width = image.width;
    header.height = image.height;
    header.channels = {"R", "G", "B", "A"};
    for (const auto& entry : image.aovs) header.channels.push_back(channelOf(entry.first));
    header.alphaChannel = 3;
    if (image.frameWidth > 0 && image.frameHeight > 0) {
        header.x = image.originX;
        header.y = image.originY;
        header.fullWidth = image.frameWidth;
        header.fullHeight = image.frameHeight;
    }
    // Lossless: float values come back bit-exact.
    header.attributes = {{"compression", std::string("zip")}};
    for (std::size_t i = 0; i < metadata.size(); ++i) {
        const auto& [key, value] = metadata[i];
        if (key.empty()) fail(what, path, "a metadata key is empty");
        const Matrix44* matrix = std::get_if<Matrix44>(&value);
        if (isCameraMatrix(key) ? !matrix : isReservedKey(key)) {
            fail(what, path, "metadata key '" + key + "' is reserved by OpenEXR/OpenImageIO" +
                                 (isCameraMatrix(key) ? " for a matrix" : ""));
        }
        for (std::size_t j = 0; j < i; ++j) {
            if (metadata[j].first == key) {
                fail(what, path, "metadata key '" + key + "' is given twice");
            }
        }
        header.attributes.push_back(metadata[i]);
    }

    const std::size_t pixels = std::size_t(image.width) * std::size_t(image.height);
    std::vector<float> interleaved(pixels * std::size_t(channels));
    for (std::size_t p = 0; p < pixels; ++p) {
        float* out = &interleaved[p * std::size_t(channels)];
        std::copy_n(&image.rgba[p * 4], 4, out);
        std::size_t c = 4;
        for (const auto& entry : image.aovs) out[c++] = entry.second[p];
    }
    writeAtomically(what, "openexr", path, header, interleaved.data(), beforeRename);
}

void writePng(const Image& image, const std::filesystem::path& path)
{
    constexpr const char* what = "writePng";
    checkShape(image, what, path);
    const std::size_t pixels = std::size_t(image.width) * std::size_t(image.height);
    std::vector<std::uint8_t> rgb(pixels * 3);
    for (std::size_t p = 0; p < pixels; ++p) {
        // Premultiplied RGB over black is RGB itself: alpha is not needed here.
        for (std::size_t c = 0; c < 3; ++c) {
            rgb[p * 3 + c] = toByte(encodeSrgb(image.rgba[p * 4 + c]));
        }
    }
    writeBytesPng(what, path, image.width, image.height, rgb);
}

void writeLevelPng(const Image& image, const std::filesystem::path& path)
{
    constexpr const char* what = "writeLevelPng";
    checkShape(image, what, path);
    const auto found = image.aovs.find("level");
    if (found == image.aovs.end()) fail(what, path, "the image has no 'level' AOV");

    const std::size_t pixels = std::size_t(image.width) * std::size_t(image.height);
    std::vector<std::uint8_t> rgb(pixels * 3);
    for (std::size_t p = 0; p < pixels; ++p) {
        float colour[3];
        levelColour(found->second[p], colour);
        // Weighted by coverage so that the background stays black, as in Figure 12. The
        // colours are a false-colour code, not radiance: stored as is, not sRGB-encoded.
        const float alpha = image.rgba[p * 4 + 3];
        const float coverage = alpha > 0.0f ? std::min(alpha, 1.0f) : 0.0f;
        for (std::size_t c = 0; c < 3; ++c) rgb[p * 3 + c] = toByte(colour[c] * coverage);
    }
    writeBytesPng(what, path, image.width, image.height, rgb);
}

void loadImageIo() { codec::imageCodec(); }

Image readExr(const std::filesystem::path& path, Metadata* metadata)
{
    auto refuse = [&](const std::string& why) -> Image {
        throw ImageError("readExr: cannot read '" + path.string() + "': " + oneLine(why));
    };
    codec::Decoded decoded;
    try {
        decoded = codec::imageCodec().read(path, "openexr", "OpenEXR");
    } catch (const ImageError&) {
        throw;  // the module is missing
    } catch (const std::exception& e) {
        return refuse(e.what());
    }
    const codec::Header& spec = decoded.header;

    auto channelIndex = [&](const std::string& name) {
        const auto& names = spec.channels;
        const auto it = std::find(names.begin(), names.end(), name);
        return it == names.end() ? -1 : int(it - names.begin());
    };
    int rgbaIndex[4];
    const char* rgbaNames[4] = {"R", "G", "B", "A"};
    for (int c = 0; c < 4; ++c) {
        rgbaIndex[c] = channelIndex(rgbaNames[c]);
        if (rgbaIndex[c] < 0 && c < 3) {
            return refuse(std::string("it has no channel ") + rgbaNames[c]);
        }
    }

    const int channels = int(spec.channels.size());
    const std::size_t pixels = std::size_t(spec.width) * std::size_t(spec.height);
    const std::vector<float>& interleaved = decoded.pixels;

    Image image(spec.width, spec.height);
    if (spec.x != 0 || spec.y != 0 || spec.fullWidth != spec.width ||
        spec.fullHeight != spec.height) {
        image.originX = spec.x;
        image.originY = spec.y;
        image.frameWidth = spec.fullWidth;
        image.frameHeight = spec.fullHeight;
    }
    for (std::size_t p = 0; p < pixels; ++p) {
        const float* src = &interleaved[p * std::size_t(channels)];
        for (int c = 0; c < 4; ++c) {
            // No alpha channel means fully covered.
            image.rgba[p * 4 + c] = rgbaIndex[c] < 0 ? 1.0f : src[rgbaIndex[c]];
        }
    }
    for (int c = 0; c < channels; ++c) {
        const std::string& name = spec.channels[c];
        const bool suffixed = name.size() > kAovSuffix.size() && name.ends_with(kAovSuffix);
        if (!suffixed && name != kDepthChannel) continue;
        std::vector<float>& values =
            image.aov(suffixed ? name.substr(0, name.size() - kAovSuffix.size()) : name);
        for (std::size_t p = 0; p < pixels; ++p) {
            values[p] = interleaved[p * std::size_t(channels) + c];
        }
    }

    if (metadata) {
        metadata->clear();
        for (const auto& [key, value] : spec.attributes) {
            if (!isCameraMatrix(key) && (isStandardAttribute(key) || isReservedKey(key))) {
                continue;
            }
            metadata->emplace_back(key, value);
        }
        // The EXR header keeps no order of its own: sort so results are reproducible.
        std::sort(metadata->begin(), metadata->end(),
                  [](const auto& a, const auto& b) { return a.first < b.first; });
    }
    return image;
}

}  // namespace pine::vdbtrace
