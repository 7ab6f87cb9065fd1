#include "pine/vdbtrace/flicker.h"

#include <algorithm>
#include <cmath>
#include <string>

namespace pine::vdbtrace {

double temporalFlicker(const std::vector<Image>& frames)
{
    if (frames.size() < 3) {
        throw ImageError("flicker needs at least 3 frames, got " + std::to_string(frames.size()));
    }
    const int w = frames.front().width, h = frames.front().height;
    for (const Image& f : frames) {
        if (f.width != w || f.height != h) throw ImageError("flicker: frames differ in size");
    }
    const std::size_t n = std::size_t(w) * h, count = frames.size();
    // Frame index centred on its mean, so that slope and intercept separate.
    const double tMean = 0.5 * double(count - 1);
    double tt = 0.0;
    for (std::size_t t = 0; t < count; ++t) tt += (double(t) - tMean) * (double(t) - tMean);
    std::vector<double> lum(count);
    double sum = 0.0;
    for (std::size_t i = 0; i < n; ++i) {
        double mean = 0.0, ty = 0.0;
        for (std::size_t t = 0; t < count; ++t) {
            const float* p = &frames[t].rgba[4 * i];
            lum[t] = 0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2];
            mean += lum[t];
            ty += (double(t) - tMean) * lum[t];
        }
        mean /= double(count);
        const double slope = ty / tt;
        double residual = 0.0;
        for (std::size_t t = 0; t < count; ++t) {
            const double r = lum[t] - mean - slope * (double(t) - tMean);
            residual += r * r;
        }
        sum += std::sqrt(residual / double(count));
    }
    return sum / double(std::max<std::size_t>(n, 1));
}

}  // namespace pine::vdbtrace
