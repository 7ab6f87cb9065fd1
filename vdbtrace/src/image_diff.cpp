#include "pine/vdbtrace/image_diff.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>
#include <vector>

namespace pine::vdbtrace {
namespace {

// A mean over no pixels.
constexpr double kUndefined = std::numeric_limits<double>::quiet_NaN();

double luminance(const float* p) { return 0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2]; }

// `image`'s AOV `name`, or null if it has none of its size.
const std::vector<float>* aovOrNull(const Image& image, const char* name)
{
    const auto found = image.aovs.find(name);
    const std::size_t n = std::size_t(image.width) * std::size_t(image.height);
    return found != image.aovs.end() && found->second.size() == n ? &found->second : nullptr;
}

// The sum over each whole k x k block of `plane` (`width` values a row), block by block in
// rows; a partial block at the right or bottom edge is left out.
template <class T>
std::vector<double> blockSums(const std::vector<T>& plane, int width, int height, int k)
{
    const int bw = width / k, bh = height / k;
    std::vector<double> sums(std::size_t(std::max(bw, 0)) * std::size_t(std::max(bh, 0)), 0.0);
    for (int by = 0; by < bh; ++by) {
        for (int bx = 0; bx < bw; ++bx) {
            double& sum = sums[std::size_t(by) * std::size_t(bw) + std::size_t(bx)];
            for (int y = by * k; y < (by + 1) * k; ++y) {
                for (int x = bx * k; x < (bx + 1) * k; ++x) {
                    sum += plane[std::size_t(y) * std::size_t(width) + std::size_t(x)];
                }
            }
        }
    }
    return sums;
}

// ImageErrors::blackFoliage of `image` against `reference`.
std::vector<ImageErrors::BlackFoliage> blackFoliage(const Image& image, const Image& reference)
{
    const std::vector<float>* planes[4] = {
        aovOrNull(image, "foliage"), aovOrNull(image, "foliage_luminance"),
        aovOrNull(reference, "foliage"), aovOrNull(reference, "foliage_luminance")};
    std::vector<ImageErrors::BlackFoliage> out;
    if (std::find(std::begin(planes), std::end(planes), nullptr) != std::end(planes)) return out;
    for (const int k : kErrorScales) {
        if (image.width / k < 1 || image.height / k < 1) continue;
        // The ratios below do not need the blocks' means.
        const auto sums = [&](int p) { return blockSums(*planes[p], image.width, image.height, k); };
        const std::vector<double> coverage = sums(0), own = sums(1), truthCoverage = sums(2),
                                  truthOwn = sums(3);
        const double covered = kBlackFoliageCoverage * k * k;
        std::vector<std::pair<std::size_t, double>> both;  // the reference's own luminance
        double mean = 0.0;
        for (std::size_t i = 0; i < coverage.size(); ++i) {
            if (!(coverage[i] >= covered && truthCoverage[i] >= covered)) continue;
            both.emplace_back(i, truthOwn[i] / truthCoverage[i]);
            mean += both.back().second;
        }
        mean /= double(std::max<std::size_t>(both.size(), 1));
        ImageErrors::BlackFoliage scale{k, 0, 0};
        for (const auto& [i, truth] : both) {
            if (!(truth >= kBlackFoliageFraction * mean) || !(truth > 0.0)) continue;
            ++scale.blocks;
            if (own[i] / coverage[i] < kBlackFoliageFraction * truth) ++scale.black;
        }
        out.push_back(scale);
    }
    return out;
}

// A perceptually ordered ramp: black, blue, green, yellow, white at 0, .25, .5, .75, 1.
void ramp(double v, float* rgb)
{
    static const float stops[5][3] = {
        {0, 0, 0}, {0.1f, 0.2f, 1}, {0.1f, 0.8f, 0.2f}, {1, 0.9f, 0.1f}, {1, 1, 1}};
    v = std::isnan(v) ? 0.0 : std::clamp(v, 0.0, 1.0) * 4.0;  // int(NaN) is undefined
    const int i = std::min(3, int(v));
    const double f = v - i;
    for (int c = 0; c < 3; ++c) rgb[c] = float((1 - f) * stops[i][c] + f * stops[i + 1][c]);
}

}  // namespace

nlohmann::json ImageErrors::toJson() const
{
    nlohmann::json levels;
    const char* names[4] = {"none", "needle", "cone", "bough"};
    for (std::size_t k = 0; k < byLevel.size(); ++k) {
        levels[names[k]] = {{"rmse", byLevel[k].rmse},
                            {"mean_relative", byLevel[k].meanRelative},
                            {"pixels", byLevel[k].pixels},
                            {"relative_pixels", byLevel[k].relativePixels}};
    }
    nlohmann::json scales = nlohmann::json::array();
    for (const AtScale& a : byScale) {
        scales.push_back({{"k", a.k}, {"rmse", a.rmse}, {"mae", a.mae}, {"blocks", a.blocks}});
    }
    nlohmann::json black = nlohmann::json::array();
    for (const BlackFoliage& b : blackFoliage) {
        black.push_back({{"k", b.k},
                         {"blocks", b.blocks},
                         {"black", b.black},
                         {"fraction", b.blocks ? double(b.black) / double(b.blocks) : kUndefined}});
    }
    return {{"rmse", rmse},
            {"by_level", levels},
            {"by_scale", scales},
            {"mean_relative", meanRelative},
            {"max_absolute", maxAbsolute},
            {"relative_floor", relativeFloor},
            {"pixels", pixels},
            {"relative_pixels", relativePixels},
            {"black_foliage", black},
            {"quantity", "linear luminance of premultiplied RGB"}};
}

const ImageErrors::AtScale* ImageErrors::atScale(int k) const
{
    for (const AtScale& a : byScale) {
        if (a.k == k) return &a;
    }
    return nullptr;
}

ImageErrors compareImages(const Image& image, const Image& reference, const std::string& imageName,
                          const std::string& referenceName)
{
    if (image.width != reference.width || image.height != reference.height) {
        throw ImageError("images differ in size: " + std::to_string(image.width) + "x" +
                         std::to_string(image.height) + " against " +
                         std::to_string(reference.width) + "x" + std::to_string(reference.height));
    }
    if (image.originX != reference.originX || image.originY != reference.originY ||
        image.frameWidth != reference.frameWidth || image.frameHeight != reference.frameHeight) {
        const auto window = [](const Image& i) {
            if (i.frameWidth == 0) return std::string("the whole frame");
            return "[" + std::to_string(i.originX) + ", " + std::to_string(i.originX + i.width) +
                   ") x [" + std::to_string(i.originY) + ", " +
                   std::to_string(i.originY + i.height) + ") of " + std::to_string(i.frameWidth) +
                   "x" + std::to_string(i.frameHeight);
        };
        throw ImageError("images show different windows of the frame: " + window(image) +
                         " against " + window(reference));
    }
    for (const auto& [what, i] : {std::pair{&imageName, &image}, {&referenceName, &reference}}) {
        std::size_t bad = 0;
        for (std::size_t k = 0; k < i->rgba.size(); ++k) {
            bad += k % 4 != 3 && !std::isfinite(i->rgba[k]) ? 1 : 0;
        }
        if (bad > 0) {
            throw ImageError(*what + ": " + std::to_string(bad) +
                             (bad == 1 ? " colour value is" : " colour values are") +
                             " not finite (NaN or infinity)");
        }
    }
    ImageErrors e;
    e.error = Image(image.width, image.height);
    auto& lum = e.error.aov("error");
    double meanRef = 0.0, sumSq = 0.0;
    const std::size_t n = std::size_t(image.width) * image.height;
    for (std::size_t i = 0; i < n; ++i) meanRef += luminance(&reference.rgba[4 * i]);
    meanRef /= double(std::max<std::size_t>(n, 1));
    e.relativeFloor = 0.01 * meanRef;
    double sumRelative = 0.0;
    const std::vector<float>* levels = aovOrNull(image, "level");  // null: none to split by
    std::vector<double> levelSq(4, 0.0), levelRel(4, 0.0);
    std::vector<double> signedError(n);  // for the scales below
    if (levels) e.byLevel.resize(4);
    for (std::size_t i = 0; i < n; ++i) {
        const float* a = &image.rgba[4 * i];
        const float* b = &reference.rgba[4 * i];
        float* out = &e.error.rgba[4 * i];
        for (int c = 0; c < 3; ++c) out[c] = std::abs(a[c] - b[c]);
        out[3] = 1.0f;
        const double ref = luminance(b);
        signedError[i] = luminance(a) - ref;
        const double d = std::abs(signedError[i]);
        lum[i] = float(d);
        sumSq += d * d;
        e.maxAbsolute = std::max(e.maxAbsolute, d);
        const bool relative = ref > e.relativeFloor && ref > 0.0;
        if (relative) {
            sumRelative += d / ref;
            ++e.relativePixels;
        }
        if (levels) {
            const int k = std::clamp(int(std::lround((*levels)[i])), 0, 3);
            levelSq[k] += d * d;
            ++e.byLevel[k].pixels;
            if (relative) {
                levelRel[k] += d / ref;
                ++e.byLevel[k].relativePixels;
            }
        }
    }
    for (std::size_t k = 0; k < e.byLevel.size(); ++k) {
        auto& l = e.byLevel[k];
        l.rmse = l.pixels ? std::sqrt(levelSq[k] / double(l.pixels)) : 0.0;
        l.meanRelative = l.relativePixels ? levelRel[k] / double(l.relativePixels) : kUndefined;
    }
    // Luminance is linear in RGB, so a block's mean error is the error of the blocks' means.
    for (const int k : kErrorScales) {
        if (image.width / k < 1 || image.height / k < 1) continue;
        double sq = 0.0, abs = 0.0;
        const std::vector<double> sums = blockSums(signedError, image.width, image.height, k);
        for (const double sum : sums) {
            const double mean = sum / double(k * k);
            sq += mean * mean;
            abs += std::abs(mean);
        }
        const std::size_t blocks = sums.size();
        e.byScale.push_back({k, std::sqrt(sq / double(blocks)), abs / double(blocks), blocks});
    }
    e.blackFoliage = blackFoliage(image, reference);
    e.pixels = n;
    e.rmse = std::sqrt(sumSq / double(std::max<std::size_t>(n, 1)));
    e.meanRelative = e.relativePixels ? sumRelative / double(e.relativePixels) : kUndefined;
    return e;
}

void writeErrorPng(const ImageErrors& errors, double scale, const std::filesystem::path& path)
{
    const Image& src = errors.error;
    const int bar = std::max(8, src.height / 20);
    Image out(src.width, src.height + bar);
    const auto& lum = src.aovs.at("error");
    for (int y = 0; y < src.height; ++y) {
        for (int x = 0; x < src.width; ++x) {
            const double v = scale > 0.0 ? lum[std::size_t(y) * src.width + x] / scale : 0.0;
            ramp(v, out.pixel(x, y));
            out.pixel(x, y)[3] = 1.0f;
        }
    }
    for (int y = src.height; y < src.height + bar; ++y) {
        for (int x = 0; x < src.width; ++x) {
            ramp(double(x) / std::max(1, src.width - 1), out.pixel(x, y));
            out.pixel(x, y)[3] = 1.0f;
        }
    }
    // The ramp's colours are a code, not light: the PNG writer encodes sRGB, so undo that here
    // by writing the linear values that encode to the ramp's.
    for (float& v : out.rgba) {
        v = v <= 0.04045f ? v / 12.92f : std::pow((v + 0.055f) / 1.055f, 2.4f);
    }
    writePng(out, path);
}

}  // namespace pine::vdbtrace
