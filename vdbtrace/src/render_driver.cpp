#include "pine/vdbtrace/render_driver.h"

#include "pine/support/input_error.h"
#include "pine/vdbtrace/tiled_render.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <iterator>
#include <limits>
#include <string>
#include <vector>

namespace pine::vdbtrace {
namespace {

// The AOV planes of kAovNames, in its order, created and looked up once per render.
struct Aovs {
    static_assert(std::size(kAovNames) == 7, "one plane per name of kAovNames");
    explicit Aovs(Image& image)
        : level(image.aov(kAovNames[0]).data()), depth(image.aov(kAovNames[1]).data()),
          diffuse(image.aov(kAovNames[2]).data()), specular(image.aov(kAovNames[3]).data()),
          foliage(image.aov(kAovNames[4]).data()), tree(image.aov(kAovNames[5]).data()),
          foliageLuminance(image.aov(kAovNames[6]).data())
    {
    }
    float *level, *depth, *diffuse, *specular, *foliage, *tree, *foliageLuminance;
};

// A pixel's samples, summed, then written as its RGBA and AOVs.
class PixelSum {
public:
    void add(const SampleValue& v)
    {
        mDiffuse += v.diffuse;
        mSpecular += v.specular;
        mAlpha += v.alpha;
        mFoliage += v.foliage;
        mFoliageLuminance += v.foliageLuminance;
        mLevelSum += v.levelSum;
        for (int k = 0; k < 4; ++k) mLevelWeight[k] += v.levelWeight[k];
        mTrees.add(v.trees);
        if (std::isfinite(v.depth)) mDepths.push_back(v.depth);
        ++mSamples;
    }

    void write(Image& image, const Aovs& aovs, int x, int y)
    {
        const double w = 1.0 / mSamples;
        const Vec3 colour = (mDiffuse + mSpecular) * w;
        float* p = image.pixel(x, y);
        p[0] = float(colour.x);
        p[1] = float(colour.y);
        p[2] = float(colour.z);
        p[3] = float(mAlpha * w);
        const std::size_t i = std::size_t(y) * std::size_t(image.width) + std::size_t(x);
        aovs.level[i] = mFoliage > 0.0 ? float(mLevelSum / mFoliage) : 0.0f;
        aovs.diffuse[i] = float(luminance(mDiffuse * w));
        aovs.specular[i] = float(luminance(mSpecular * w));
        aovs.foliage[i] = float(mFoliage * w);
        aovs.foliageLuminance[i] = float(mFoliageLuminance * w);
        aovs.tree[i] = float(mTrees.dominant());
        // The pixel's coverage passes 1/2 at the ceil(S/2)-th nearest sample depth.
        const std::size_t half = std::size_t((mSamples + 1) / 2);
        aovs.depth[i] = std::numeric_limits<float>::infinity();
        if (mDepths.size() >= half) {
            std::nth_element(mDepths.begin(), mDepths.begin() + std::ptrdiff_t(half - 1),
                             mDepths.end());
            aovs.depth[i] = float(mDepths[half - 1]);
        }
    }

    /// The level that covered most of the pixel (0: none covered more than 1e-6).
    int dominantLevel() const
    {
        int dominant = 0;
        for (int k = 1; k <= 3; ++k) {
            if (mLevelWeight[k] > 1e-6 && mLevelWeight[k] > mLevelWeight[dominant]) dominant = k;
        }
        return dominant;
    }

    void clear()
    {
        mDiffuse = mSpecular = Vec3(0.0);
        mAlpha = mFoliage = mFoliageLuminance = mLevelSum = 0.0;
        for (double& w : mLevelWeight) w = 0.0;
        mTrees = {};
        mDepths.clear();  // keeps its capacity: no allocation per pixel
        mSamples = 0;
    }

private:
    Vec3 mDiffuse{0.0}, mSpecular{0.0};
    double mAlpha = 0.0, mFoliage = 0.0, mFoliageLuminance = 0.0, mLevelSum = 0.0;
    double mLevelWeight[4] = {0.0, 0.0, 0.0, 0.0};
    TreeShares<8> mTrees;
    std::vector<double> mDepths;
    int mSamples = 0;
};

}  // namespace

RenderResult renderImage(const TracedScene& scene, const ShadingMethod& method,
                         const RenderOptions& options)
{
    using Clock = std::chrono::steady_clock;
    const auto start = Clock::now();
    const ConeCamera camera(scene.scene->camera);
    const PixelWindow all{0, 0, camera.width(), camera.height()};
    const PixelWindow w = options.window.empty() ? all : options.window;
    if (w.x0 < 0 || w.y0 < 0 || w.x1 > all.x1 || w.y1 > all.y1) {
        throw InputError("crop " + std::to_string(w.x0) + "," + std::to_string(w.y0) + "," +
                         std::to_string(w.x1) + "," + std::to_string(w.y1) + " is outside the " +
                         std::to_string(all.x1) + " x " + std::to_string(all.y1) + " frame");
    }
    RenderResult result;
    result.image = Image(w.x1 - w.x0, w.y1 - w.y0);
    Image& image = result.image;
    if (!options.window.empty()) {
        image.originX = w.x0;
        image.originY = w.y0;
        image.frameWidth = all.x1;
        image.frameHeight = all.y1;
    }
    const Aovs aovs(image);
    const int samples = std::max(1, method.samplesPerPixel());
    const bool split = samples == 1 && method.splitsPixels();
    // n cones of a pixel, cone s given by coneOf(s), each composited alone and a 1/n share of
    // the pixel and of its trees' foliage.
    const auto traceCones = [](ShadingMethod::RayTracer& tracer, int n, const auto& coneOf,
                               PixelSum& pixel, TreeFoliageTally& trees, RenderStats& stats) {
        for (int s = 0; s < n; ++s) {
            ++stats.coneRays;
            FrontToBack composite(&trees, 1.0 / n);
            tracer.trace(coneOf(s), composite);
            pixel.add(composite.value());
        }
    };
    // Into the cleared `pixel`: its cone, then, where its tracer asks, k x k narrower ones in
    // its place; the first cone's foliage joins the tile's only if it stands.
    const auto splitPixel = [&](ShadingMethod::RayTracer& tracer, int x, int y, PixelSum& pixel,
                                TreeFoliageTally& trees, RenderStats& stats) {
        thread_local TreeFoliageTally first;
        first.clear();
        const ConeRay cone = method.sample(camera, x, y, 0);
        traceCones(
            tracer, 1, [&](int) { return cone; }, pixel, first, stats);
        const int side = tracer.pixelSplit(cone, camera.squareCone(x, y));
        if (side <= 1) {
            trees.add(first);
            return;
        }
        pixel.clear();
        traceCones(
            tracer, side * side, [&](int s) { return camera.subpixelCone(x, y, s, side); }, pixel,
            trees, stats);
    };
    // Each tile's trees, summed in tile order once all are done.
    std::vector<TreeFoliageTally> tileTrees(
        std::size_t(tileCount(image.width, image.height, options.tileSize)));

    // Tiles of the window; each pixel traced at its place in the frame, so a crop holds the
    // whole frame's pixels exactly.
    forEachTile(image.width, image.height, options.tileSize, options.progress, result.stats,
                [&](int k, int tx0, int ty0, int tx1, int ty1, RenderStats& stats) {
        const std::unique_ptr<ShadingMethod::RayTracer> tracer = method.rayTracer(stats);
        TreeFoliageTally& trees = tileTrees[std::size_t(k)];
        PixelSum pixel;
        for (int y = ty0 + w.y0; y < ty1 + w.y0; ++y) {
            for (int x = tx0 + w.x0; x < tx1 + w.x0; ++x) {
                const auto t0 = Clock::now();
                pixel.clear();
                if (split) {
                    splitPixel(*tracer, x, y, pixel, trees, stats);
                } else {
                    traceCones(
                        *tracer, samples, [&](int s) { return method.sample(camera, x, y, s); },
                        pixel, trees, stats);
                }
                pixel.write(image, aovs, x - w.x0, y - w.y0);
                const int dominant = pixel.dominantLevel();
                ++stats.pixelsPerLevel[dominant];
                stats.nanosecondsPerLevel[dominant] += std::uint64_t(
                    std::chrono::duration_cast<std::chrono::nanoseconds>(Clock::now() - t0)
                        .count());
            }
        }
    });
    result.seconds = std::chrono::duration<double>(Clock::now() - start).count();
    TreeFoliageTally trees;
    for (const TreeFoliageTally& t : tileTrees) trees.add(t);
    result.treeFoliage = trees.sums();
    // Finite inputs can still overflow (a light of 1e308): an error, never a NaN pixel.
    std::size_t bad = 0;
    for (const float v : image.rgba) bad += std::isfinite(v) ? 0 : 1;
    if (bad > 0) {
        throw InputError("radiance overflowed: " + std::to_string(bad) +
                         " pixel values are not finite (a light too bright or too near a "
                         "surface for float radiance, or a NaN from the shading)");
    }
    return result;
}

}  // namespace pine::vdbtrace
