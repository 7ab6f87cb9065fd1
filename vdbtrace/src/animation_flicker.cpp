#include "pine/vdbtrace/animation_flicker.h"

#include "pine/support/process_clock.h"
#include "pine/vdbtrace/methods.h"

#include <algorithm>

namespace pine::vdbtrace {

AnimationFlicker measureAnimationFlicker(const scenes::Scene& base,
                                         const std::vector<scenes::Camera>& cameras,
                                         const std::vector<int>& keep, int window,
                                         const CompareLog& log)
{
    if (cameras.size() < 3) {
        throw ImageError("flicker needs at least 3 frames, got " + std::to_string(cameras.size()));
    }
    AnimationFlicker out;
    out.width = cameras.front().width;
    out.height = cameras.front().height;
    scenes::Scene scene = base;
    constexpr std::size_t kSequences = std::size(kAnimationSequences);
    std::vector<std::vector<Image>> frames(kSequences);
    for (const AnimationSequence& q : kAnimationSequences) {
        AnimationRow row;
        row.method = q.label;
        out.rows.push_back(std::move(row));
    }
    const double count = double(cameras.size());
    for (std::size_t f = 0; f < cameras.size(); ++f) {
        scene.camera = cameras[f];
        const TracedScene traced = buildTracedScene(scene);
        for (std::size_t m = 0; m < kSequences; ++m) {
            MethodSettings settings;
            settings.geometry.samples = std::max(1, kAnimationSequences[m].samples);
            const double cpu0 = io::processCpuSeconds();
            RenderResult r =
                renderMethod(kAnimationSequences[m].method).render(traced, settings, {});
            out.rows[m].cpuSecondsPerFrame += (io::processCpuSeconds() - cpu0) / count;
            out.rows[m].secondsPerFrame += r.seconds / count;
            // Only RGB is measured (and the multiscale levels, for the bands): the other AOVs
            // of every frame of three sequences would be memory.
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
    for (std::size_t m = 0; m < kSequences; ++m) {
        out.rows[m].flicker =
            flickerBreakdown(frames[m], bands, int(std::size(kLevelBandNames)), window);
    }
    return out;
}

}  // namespace pine::vdbtrace
