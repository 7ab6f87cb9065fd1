#include "pine/vdbtrace/flicker.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

namespace pine::vdbtrace {
namespace {

void checkFrames(const std::vector<Image>& frames)
{
    if (frames.size() < 3) {
        throw ImageError("flicker needs at least 3 frames, got " + std::to_string(frames.size()));
    }
    const int w = frames.front().width, h = frames.front().height;
    for (const Image& f : frames) {
        if (f.width != w || f.height != h) throw ImageError("flicker: frames differ in size");
    }
}

}  // namespace

double temporalFlicker(const std::vector<Image>& frames)
{
    return flickerBreakdown(frames).flicker;
}

FlickerBreakdown flickerBreakdown(const std::vector<Image>& frames,
                                  const std::vector<std::uint8_t>& band, int bandCount, int window)
{
    checkFrames(frames);
    if (window != 0 && window != 3) {
        throw ImageError("flicker: window " + std::to_string(window) + " (0 or 3)");
    }
    const std::size_t n = std::size_t(frames.front().width) * frames.front().height;
    const std::size_t count = frames.size();
    if (!band.empty() && band.size() != n) throw ImageError("flicker: one band per pixel");
    FlickerBreakdown out;
    out.perBand.assign(std::size_t(std::max(1, bandCount)), 0.0);
    out.bandPixels.assign(out.perBand.size(), 0);
    out.residualPerFrame.assign(count, 0.0);
    out.luminancePerFrame.assign(count, 0.0);
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
            out.luminancePerFrame[t] += lum[t];
        }
        mean /= double(count);
        const double slope = ty / tt;
        double residual = 0.0, deviation = 0.0;
        if (window == 0) {
            for (std::size_t t = 0; t < count; ++t) {
                const double r = lum[t] - mean - slope * (double(t) - tMean);
                residual += r * r;
                out.residualPerFrame[t] += r * r;
            }
            deviation = std::sqrt(residual / double(count));
        } else {
            for (std::size_t t = 1; t + 1 < count; ++t) {
                const double r = lum[t] - 0.5 * (lum[t - 1] + lum[t + 1]);
                residual += r * r;
                out.residualPerFrame[t] += r * r;
            }
            deviation = std::sqrt(residual / double(count - 2) / 1.5);
        }
        sum += deviation;
        const std::size_t b =
            band.empty() ? 0 : std::min<std::size_t>(band[i], out.perBand.size() - 1);
        out.perBand[b] += deviation;
        ++out.bandPixels[b];
    }
    const double pixels = double(std::max<std::size_t>(n, 1));
    out.flicker = sum / pixels;
    for (std::size_t b = 0; b < out.perBand.size(); ++b) {
        if (out.bandPixels[b] > 0) out.perBand[b] /= double(out.bandPixels[b]);
    }
    for (std::size_t t = 0; t < count; ++t) {
        out.residualPerFrame[t] = std::sqrt(out.residualPerFrame[t] / pixels);
        out.luminancePerFrame[t] /= pixels;
    }
    if (window == 3) {
        // The first and last frames have one neighbour: no departure to tell.
        out.residualPerFrame.front() = out.residualPerFrame.back() =
            std::numeric_limits<double>::quiet_NaN();
    }
    return out;
}

std::vector<std::uint8_t> levelBands(const std::vector<Image>& frames)
{
    if (frames.empty()) return {};
    const std::size_t n = std::size_t(frames.front().width) * frames.front().height;
    std::vector<double> sum(n, 0.0);
    std::vector<int> seen(n, 0);
    for (const Image& f : frames) {
        const auto level = f.aovs.find("level");
        if (level == f.aovs.end() || level->second.size() != n) {
            throw ImageError("level bands: a frame has no level AOV of its size");
        }
        for (std::size_t i = 0; i < n; ++i) {
            if (level->second[i] > 0.0f) {
                sum[i] += level->second[i];
                ++seen[i];
            }
        }
    }
    std::vector<std::uint8_t> band(n, 0);
    for (std::size_t i = 0; i < n; ++i) {
        if (seen[i] > 0) band[i] = std::uint8_t(std::clamp(std::lround(sum[i] / seen[i]), 1L, 3L));
    }
    return band;
}

}  // namespace pine::vdbtrace
