#include "pine/vdbtrace/tree_foliage.h"

#include "pine/vdbtrace/fragment.h"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <deque>
#include <limits>
#include <map>
#include <string>
#include <variant>

namespace pine::vdbtrace {
namespace {

const std::vector<float>& plane(const Image& image, const char* name)
{
    const auto it = image.aovs.find(name);
    if (it == image.aovs.end() || it->second.size() != std::size_t(image.width) * image.height) {
        throw ImageError(std::string("the image has no \"") + name + "\" AOV");
    }
    return it->second;
}

}  // namespace

std::vector<int> treeRegions(const Image& segmentation)
{
    const std::vector<float>& tree = plane(segmentation, "tree");
    const int w = segmentation.width, h = segmentation.height;
    std::vector<int> region(tree.size(), -1);
    // Breadth first from every named pixel at once, in scanline order: a pixel takes the tree
    // that reaches it first.
    std::deque<std::size_t> queue;
    for (std::size_t i = 0; i < tree.size(); ++i) {
        if (!(tree[i] < 16777216.0f)) {  // NaN or beyond float's exact integers: not an index
            throw ImageError("the \"tree\" AOV holds " + std::to_string(tree[i]) +
                             ", not a tree index");
        }
        if (tree[i] >= 0.0f) {
            region[i] = int(std::lround(tree[i]));
            queue.push_back(i);
        }
    }
    while (!queue.empty()) {
        const std::size_t i = queue.front();
        queue.pop_front();
        const int x = int(i % std::size_t(w)), y = int(i / std::size_t(w));
        const int nx[4] = {x - 1, x + 1, x, x};
        const int ny[4] = {y, y, y - 1, y + 1};
        for (int k = 0; k < 4; ++k) {
            if (nx[k] < 0 || ny[k] < 0 || nx[k] >= w || ny[k] >= h) continue;
            const std::size_t j = std::size_t(ny[k]) * std::size_t(w) + std::size_t(nx[k]);
            if (region[j] >= 0) continue;
            region[j] = region[i];
            queue.push_back(j);
        }
    }
    return region;
}

bool hasOwnFoliageLuminance(const Image& image)
{
    return image.aovs.count("foliage_luminance") > 0;
}

std::vector<TreeFoliage> foliageByTree(const Image& image, const std::vector<int>& regions,
                                       FoliageLuminance measure)
{
    const std::vector<float>& foliage = plane(image, "foliage");
    if (regions.size() != foliage.size()) {
        throw ImageError("tree regions of " + std::to_string(regions.size()) +
                         " pixels for an image of " + std::to_string(foliage.size()));
    }
    const std::vector<float>* own =
        measure == FoliageLuminance::Own ? &plane(image, "foliage_luminance") : nullptr;
    std::map<int, TreeFoliage> trees;  // luminance holds its sum over the region until the end
    for (std::size_t i = 0; i < regions.size(); ++i) {
        if (regions[i] < 0) continue;
        TreeFoliage& t = trees[regions[i]];
        t.tree = regions[i];
        ++t.pixels;
        const float* p = &image.rgba[4 * i];
        t.coverage += foliage[i];
        t.luminance += own ? (*own)[i] : luminance(Vec3(p[0], p[1], p[2])) * foliage[i];
    }
    std::vector<TreeFoliage> out;
    for (auto& [id, t] : trees) {
        t.luminance = t.coverage > 0.0 ? t.luminance / t.coverage : 0.0;
        out.push_back(t);
    }
    return out;
}

namespace {

// A ratio - 1, undefined (NaN) against a truth of 0: a black tree's luminance bias is not 0%.
double relativeBias(double image, double truth)
{
    return truth > 0.0 ? image / truth - 1.0 : std::numeric_limits<double>::quiet_NaN();
}

}  // namespace

std::vector<TreeBias> treeBiases(const Image& image, const Image& truth, double minCoverage)
{
    if (image.width != truth.width || image.height != truth.height) {
        throw ImageError("images differ in size");
    }
    const std::vector<int> regions = treeRegions(truth);
    // The same measure for both: their own where both images have it.
    const FoliageLuminance measure = hasOwnFoliageLuminance(image) && hasOwnFoliageLuminance(truth)
                                         ? FoliageLuminance::Own
                                         : FoliageLuminance::Pixels;
    const std::vector<TreeFoliage> a = foliageByTree(image, regions, measure);
    const std::vector<TreeFoliage> b = foliageByTree(truth, regions, measure);
    std::vector<TreeBias> out;
    for (std::size_t k = 0; k < b.size(); ++k) {  // the same regions, so the same trees
        if (!(b[k].coverage >= minCoverage) || !(b[k].coverage > 0.0)) continue;
        out.push_back({a[k], b[k], relativeBias(a[k].coverage, b[k].coverage),
                       relativeBias(a[k].luminance, b[k].luminance)});
    }
    return out;
}

std::string treeFoliageText(const std::vector<TreeFoliageSum>& sums)
{
    nlohmann::json rows = nlohmann::json::array();
    for (const TreeFoliageSum& t : sums) rows.push_back({t.tree, t.coverage_px, t.luminance});
    return rows.dump();
}

std::vector<TreeFoliageSum> parseTreeFoliage(const std::string& text, const std::string& where)
{
    const auto bad = [&](const std::string& why) {
        return ImageError(where + ": " + kTreeFoliageAttribute + " " + why);
    };
    const nlohmann::json rows = nlohmann::json::parse(text, nullptr, /*allow_exceptions=*/false);
    if (!rows.is_array()) throw bad("is not a JSON array");
    std::vector<TreeFoliageSum> out;
    for (const nlohmann::json& r : rows) {
        if (!r.is_array() || r.size() != 3 || !r[0].is_number_integer() || !r[1].is_number() ||
            !r[2].is_number()) {
            throw bad("holds " + r.dump() + ", not [tree, coverage, luminance]");
        }
        const std::int64_t tree = r[0].get<std::int64_t>();
        if (tree < 0 || tree > std::numeric_limits<int>::max()) {
            throw bad("holds " + r.dump() + ": no tree index");
        }
        const TreeFoliageSum t{int(tree), r[1].get<double>(), r[2].get<double>()};
        if (!std::isfinite(t.coverage_px) || !(t.coverage_px >= 0.0) ||
            !std::isfinite(t.luminance) || (!out.empty() && t.tree <= out.back().tree)) {
            throw bad("holds " + r.dump() + ": trees must increase, sums be finite");
        }
        out.push_back(t);
    }
    return out;
}

std::string frameText(int width, int height)
{
    return std::to_string(width) + "x" + std::to_string(height);
}

void addTreeFoliage(Metadata& header, const std::vector<TreeFoliageSum>& sums, int frameWidth,
                    int frameHeight)
{
    header.emplace_back(kTreeFoliageAttribute, treeFoliageText(sums));
    header.emplace_back(kTreeFoliageFrameAttribute, frameText(frameWidth, frameHeight));
}

std::optional<std::vector<TreeFoliageSum>> treeFoliageOf(const Metadata& metadata,
                                                         const std::string& where,
                                                         const Image* image)
{
    const auto text = [&](const char* name) -> const std::string* {
        for (const auto& [key, value] : metadata) {
            if (key != name) continue;
            const std::string* t = std::get_if<std::string>(&value);
            if (!t) throw ImageError(where + ": " + name + " is not text");
            return t;
        }
        return nullptr;
    };
    const std::string* sumsText = text(kTreeFoliageAttribute);
    if (!sumsText) return std::nullopt;
    std::vector<TreeFoliageSum> sums = parseTreeFoliage(*sumsText, where);
    if (!image) return sums;
    const std::string* frame = text(kTreeFoliageFrameAttribute);
    if (!frame) return sums;
    int w = 0, h = 0;
    const char* end = frame->data() + frame->size();
    const auto [x, widthError] = std::from_chars(frame->data(), end, w);
    const bool read = widthError == std::errc() && x != end && *x == 'x' &&
                      std::from_chars(x + 1, end, h).ec == std::errc();
    if (!read || w < 1 || h < 1 || *frame != frameText(w, h)) {
        throw ImageError(where + ": " + kTreeFoliageFrameAttribute + " is '" + *frame +
                         "', not WIDTHxHEIGHT");
    }
    const int W = image->frameWidth > 0 ? image->frameWidth : image->width;
    const int H = image->frameHeight > 0 ? image->frameHeight : image->height;
    if (W == w && H == h) return sums;
    // A pixel of the image holds (w h) / (W H) of the frame's: as many pixels' worth of each
    // tree's foliage, and its luminance summed over them.
    const double scale = (double(W) * double(H)) / (double(w) * double(h));
    for (TreeFoliageSum& t : sums) {
        t.coverage_px *= scale;
        t.luminance *= scale;
    }
    return sums;
}

std::vector<TreeBias> treeBiases(const std::vector<TreeFoliageSum>& image,
                                 const std::vector<TreeFoliageSum>& truth, double minCoverage)
{
    std::map<int, const TreeFoliageSum*> shown;
    for (const TreeFoliageSum& t : image) shown[t.tree] = &t;
    const auto foliage = [](const TreeFoliageSum& t) {
        return TreeFoliage{t.tree, 0, t.coverage_px,
                           t.coverage_px > 0.0 ? t.luminance / t.coverage_px : 0.0};
    };
    std::vector<TreeBias> out;
    for (const TreeFoliageSum& t : truth) {
        if (!(t.coverage_px >= minCoverage) || !(t.coverage_px > 0.0)) continue;
        const auto it = shown.find(t.tree);
        const TreeFoliage a = it != shown.end() ? foliage(*it->second) : TreeFoliage{t.tree};
        const TreeFoliage b = foliage(t);
        out.push_back(
            {a, b, relativeBias(a.coverage, b.coverage), relativeBias(a.luminance, b.luminance)});
    }
    return out;
}

TreeBiasSummary summarizeTreeBiases(const std::vector<TreeBias>& biases, double beyond)
{
    TreeBiasSummary out;
    out.trees = biases.size();
    out.beyond = beyond;
    const auto spread = [&](double TreeBias::*bias) {
        TreeBiasSummary::Spread s;
        if (biases.empty()) return s;
        std::vector<double> values;
        for (const TreeBias& t : biases) {
            const double v = t.*bias;
            if (std::isnan(v)) continue;  // undefined: its truth is 0
            values.push_back(v);
            if (s.worstTree < 0 || std::abs(v) > std::abs(s.worst)) {
                s.worst = v;
                s.worstTree = t.truth.tree;
            }
            s.beyond += std::abs(v) > beyond;
        }
        s.defined = values.size();
        if (values.empty()) {
            s.median = s.worst = std::numeric_limits<double>::quiet_NaN();
            return s;
        }
        std::sort(values.begin(), values.end());
        const std::size_t n = values.size();
        s.median = n % 2 ? values[n / 2] : 0.5 * (values[n / 2 - 1] + values[n / 2]);
        return s;
    };
    out.luminance = spread(&TreeBias::luminanceBias);
    out.coverage = spread(&TreeBias::coverageBias);
    return out;
}

}  // namespace pine::vdbtrace
