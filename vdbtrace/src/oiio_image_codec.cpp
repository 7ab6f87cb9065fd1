// The image module (image_codec.h): images written and read through OpenImageIO. Built as its
// own shared module so that only the commands that touch an image load OpenImageIO.
#include "image_codec.h"

#include <OpenImageIO/filesystem.h>
#include <OpenImageIO/imageio.h>

#include <algorithm>
#include <stdexcept>
#include <string_view>

namespace pine::vdbtrace::codec {
namespace {

[[noreturn]] void fail(const std::string& why) { throw std::runtime_error(oneLine(why)); }

OIIO::ImageSpec specOf(const Header& header)
{
    OIIO::ImageSpec spec(header.width, header.height, int(header.channels.size()),
                         header.bytes ? OIIO::TypeDesc::UINT8 : OIIO::TypeDesc::FLOAT);
    spec.channelnames = header.channels;
    spec.alpha_channel = header.alphaChannel;
    if (header.fullWidth > 0 && header.fullHeight > 0) {
        spec.x = header.x;
        spec.y = header.y;
        spec.full_width = header.fullWidth;
        spec.full_height = header.fullHeight;
    }
    for (const auto& [key, value] : header.attributes) {
        if (const auto* text = std::get_if<std::string>(&value)) {
            spec.attribute(key, *text);
        } else if (const auto* number = std::get_if<int>(&value)) {
            spec.attribute(key, *number);
        } else if (const auto* real = std::get_if<float>(&value)) {
            spec.attribute(key, *real);
        } else {
            spec.attribute(key, OIIO::TypeDesc::TypeMatrix44,
                           &std::get<Matrix44>(value).m[0][0]);
        }
    }
    return spec;
}

class OiioCodec final : public Codec {
public:
    bool write(const char* format, const Header& header, const void* pixels,
               const std::filesystem::path& file,
               std::vector<unsigned char>& memory) const override
    {
        const OIIO::ImageSpec spec = specOf(header);
        // The memory outlives `out`, whose destructor may still close into it.
        OIIO::Filesystem::IOVecOutput proxy(memory);
        // The plugin by name, not by the file's extension: a temporary's name says nothing.
        auto out = OIIO::ImageOutput::create(format);
        if (!out) fail(OIIO::geterror());
        const bool viaMemory = std::string_view(format) == "png" && out->supports("ioproxy");
        if (viaMemory && !out->set_ioproxy(&proxy)) fail(out->geterror());
        if (!out->open(file.string(), spec)) fail(out->geterror());
        if (!out->write_image(spec.format, pixels)) {
            const std::string why = out->geterror();
            out->close();
            fail(why);
        }
        if (!out->close()) fail(out->geterror());
        return viaMemory;
    }

    Decoded read(const std::filesystem::path& file, const char* format,
                 const char* formatName) const override
    {
        auto in = OIIO::ImageInput::open(file.string());
        if (!in) fail(OIIO::geterror());
        if (std::string_view(in->format_name()) != format) {
            fail(std::string("it is ") + in->format_name() + ", not " + formatName);
        }
        const OIIO::ImageSpec& spec = in->spec();
        if (spec.width <= 0 || spec.height <= 0 || spec.depth != 1 || spec.deep) {
            fail("not a flat 2D image");
        }
        Decoded decoded;
        Header& h = decoded.header;
        h.width = spec.width;
        h.height = spec.height;
        h.channels = spec.channelnames;
        h.alphaChannel = spec.alpha_channel;
        h.x = spec.x;
        h.y = spec.y;
        h.fullWidth = spec.full_width;
        h.fullHeight = spec.full_height;
        const int channels = spec.nchannels;
        decoded.pixels.resize(std::size_t(spec.width) * std::size_t(spec.height) *
                              std::size_t(channels));
        if (!in->read_image(0, 0, 0, channels, OIIO::TypeDesc::FLOAT, decoded.pixels.data())) {
            fail(in->geterror());
        }
        for (const auto& attribute : spec.extra_attribs) {
            const std::string key = attribute.name().string();
            const OIIO::TypeDesc type = attribute.type();
            if (type == OIIO::TypeDesc::TypeMatrix44) {
                Matrix44 matrix;
                std::copy_n(static_cast<const float*>(attribute.data()), 16, &matrix.m[0][0]);
                h.attributes.emplace_back(key, matrix);
            } else if (type == OIIO::TypeDesc::STRING) {
                h.attributes.emplace_back(key, attribute.get_string());
            } else if (type == OIIO::TypeDesc::INT) {
                h.attributes.emplace_back(key, attribute.get_int());
            } else if (type == OIIO::TypeDesc::FLOAT) {
                h.attributes.emplace_back(key, attribute.get_float());
            }
        }
        return decoded;
    }
};

}  // namespace
}  // namespace pine::vdbtrace::codec

extern "C" __attribute__((visibility("default"))) const pine::vdbtrace::codec::Codec*
pine_image_codec()
{
    static const pine::vdbtrace::codec::OiioCodec codec;
    return &codec;
}
