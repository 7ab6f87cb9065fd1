#include "pine/vdbtrace/preview.h"

namespace pine::vdbtrace {

Image overBackground(const Image& image, const scenes::Vec3& background)
{
    Image out = image;
    for (int y = 0; y < out.height; ++y) {
        for (int x = 0; x < out.width; ++x) {
            float* p = out.pixel(x, y);
            for (int c = 0; c < 3; ++c) p[c] += (1.0f - p[3]) * float(background[c]);
            p[3] = 1.0f;
        }
    }
    return out;
}

void writePreviewPng(const Image& image, const scenes::Vec3& background,
                     const std::filesystem::path& path)
{
    writePng(overBackground(image, background), path);
}

}  // namespace pine::vdbtrace
