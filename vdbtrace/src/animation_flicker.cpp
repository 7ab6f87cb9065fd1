#include "pine/vdbtrace/animation_flicker.h"

#include "pine/support/process_clock.h"
#include "pine/vdbtrace/methods.h"

#include <algorithm>

namespace pine::vdbtrace {

namespace {

// The error's frames: each method's luminance less the truth's, as grey RGB (flicker reads
// luminance, which is linear in RGB).
std::vector<Image> errorFrames(const std::vector<Image>& frames, const std::vector<Image>& truth)
{
    std::vector<Image> out;
    for (std::size_t t = 0; t < frames.size(); ++t) {
        Image e(frames[t].width, frames[t].height);
        for (std::size_t i = 0; i < e.rgba.size(); i += 4) {
            for (std::size_t c = 0; c < 3; ++c) {
                e.rgba[i + c] = frames[t].rgba[i + c] - truth[t].rgba[i + c];
            }
        }
        out.push_back(std::move(e));
    }
    return out;
}

}  // namespace

AnimationFlicker measureAnimationFlicker(const scenes::Scene& base,
                                         const std::vector<scenes::Camera>& cameras,
                                         const std::vector<int>& keep, int window, int truthSamples,
                                         const CompareLog& log)
{
    if (cameras.size() < 3) {
        throw ImageError("flicker needs at least 3 frames, got " + std::to_string(cameras.size()));
    }
    AnimationFlicker out;
    out.width = cameras.front().width;
    out.height = cameras.front().height;
    scenes::Scene scene = base;
    struct Sequence {
        std::string label;
        const char* method;
        int samples;
        unsigned seed;  ///< geometry's sample seed: the truth's own, independent of the others'
    };
    std::vector<Sequence> sequences;
    for (const AnimationSequence& q : kAnimationSequences) {
        sequences.push_back({q.label, q.method, q.samples, 0});
    }
    if (truthSamples > 0) {
        sequences.push_back({"truth_geometry_" + std::to_string(truthSamples) + "spp", "geometry",
                             truthSamples, 1});
    }
    std::vector<std::vector<Image>> frames(sequences.size());
    for (const Sequence& q : sequences) {
        AnimationRow row;
        row.method = q.label;
        row.truth = &q == &sequences.back() && truthSamples > 0;
        out.rows.push_back(std::move(row));
    }
    const double count = double(cameras.size());
    for (std::size_t f = 0; f < cameras.size(); ++f) {
        scene.camera = cameras[f];
        const TracedScene traced = buildTracedScene(scene);
        for (std::size_t m = 0; m < sequences.size(); ++m) {
            MethodSettings settings;
            settings.geometry.samples = std::max(1, sequences[m].samples);
            settings.geometry.sampleSeed = sequences[m].seed;
            const double cpu0 = io::processCpuSeconds();
            RenderResult r = renderMethod(sequences[m].method).render(traced, settings, {});
            out.rows[m].cpuSecondsPerFrame += (io::processCpuSeconds() - cpu0) / count;
            out.rows[m].secondsPerFrame += r.seconds / count;
            // Only RGB is measured (and the multiscale levels, for the bands): the other AOVs
            // of every frame of every sequence would be memory.
            for (auto it = r.image.aovs.begin(); it != r.image.aovs.end();) {
                it = m == 0 && it->first == "level" ? std::next(it) : r.image.aovs.erase(it);
            }
            if (std::find(keep.begin(), keep.end(), int(f)) != keep.end()) {
                Image rgba = r.image;
                rgba.aovs.clear();
                out.rows[m].kept.push_back(std::move(rgba));
            }
            frames[m].push_back(std::move(r.image));
        }
        if (log) log("frame " + std::to_string(f + 1) + "/" + std::to_string(cameras.size()));
    }
    const std::vector<std::uint8_t> bands = levelBands(frames.front());
    const int bandCount = int(std::size(kLevelBandNames));
    for (std::size_t m = 0; m < sequences.size(); ++m) {
        out.rows[m].flicker = flickerBreakdown(frames[m], bands, bandCount, window);
        if (truthSamples > 0 && !out.rows[m].truth) {
            out.rows[m].errorFlicker =
                flickerBreakdown(errorFrames(frames[m], frames.back()), bands, bandCount, window);
        }
    }
    return out;
}

}  // namespace pine::vdbtrace
