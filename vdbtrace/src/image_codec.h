// What image_io.cpp asks of OpenImageIO, behind a module (libpine_image_codec.so) loaded on
// first use. Linking OpenImageIO loads about 250 shared libraries (its plugins' OpenCV, FFmpeg,
// GStreamer, DCMTK, ...): 0.3 CPU-s and 130 MiB before main() of every vdbtrace command,
// `--help` included, where the rest of the tool starts in 0.04 s (issue: a multiscale tracer
// that earns its name, start-up). Only a command that reads or writes an image pays for it.
#pragma once

#include "pine/vdbtrace/image.h"

#include <filesystem>
#include <string>
#include <vector>

namespace pine::vdbtrace::codec {

/// OpenImageIO's error text may span lines; ours are one line ("unknown error" if empty).
inline std::string oneLine(std::string text)
{
    while (!text.empty() && (text.back() == '\n' || text.back() == ' ')) text.pop_back();
    std::string out;
    for (char c : text) {
        if (c == '\n') out += "; ";
        else out += c;
    }
    return out.empty() ? std::string("unknown error") : out;
}

/// An image's layout and header, without OpenImageIO's types.
struct Header {
    int width = 0, height = 0;
    bool bytes = false;                 ///< 8-bit channels; else 32-bit float
    std::vector<std::string> channels;  ///< their names, interleaved in this order
    int alphaChannel = -1;
    /// The data window's origin in the display window, and the display window's size (0: the
    /// data window's).
    int x = 0, y = 0, fullWidth = 0, fullHeight = 0;
    Metadata attributes;  ///< written as their types; read: every one of those types
};

/// A file read back.
struct Decoded {
    Header header;
    std::vector<float> pixels;  ///< interleaved, header.channels.size() per pixel
};

/// OpenImageIO's side. Each method throws std::runtime_error with a one-line reason.
class Codec {
public:
    virtual ~Codec() = default;
    /// Writes `pixels` (interleaved as `header` says) as `format` ("openexr", "png") to
    /// `file`, or, if the format's writer can write to memory and `format` is "png", into
    /// `memory` (then `file` is left alone and the caller writes the bytes, checking each:
    /// libpng does not say when the disk is full). Returns whether it wrote into `memory`.
    virtual bool write(const char* format, const Header& header, const void* pixels,
                       const std::filesystem::path& file,
                       std::vector<unsigned char>& memory) const = 0;
    /// Reads a flat 2D image of `format` (OpenImageIO's name; `formatName` is what a message
    /// calls it), every channel as float; refuses another format or a deep or 3D image.
    virtual Decoded read(const std::filesystem::path& file, const char* format,
                         const char* formatName) const = 0;
};

/// The module's codec, loaded on first use, once, from any thread. Looked for beside the
/// executable (the build's bin/), then in ../lib/pine from it (`cmake --install`). Throws
/// ImageError (one line: where it looked and why it failed) if it cannot be loaded.
const Codec& imageCodec();

/// The module's file name, and the entry point it exports (extern "C", returning a Codec that
/// lives as long as the process).
inline constexpr const char* kModuleFile = "libpine_image_codec.so";
inline constexpr const char* kModuleEntry = "pine_image_codec";

}  // namespace pine::vdbtrace::codec
