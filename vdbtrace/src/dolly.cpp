#include "pine/vdbtrace/dolly.h"

#include "pine/vdbtrace/flicker.h"
#include "pine/vdbtrace/methods.h"

#include <algorithm>

namespace pine::vdbtrace {

DollyFlicker measureDollyFlicker(const scenes::Scene& base, const CompareSettings& s,
                                 const CompareLog& log)
{
    DollyFlicker out;
    scenes::Scene scene = base;
    out.width = scene.camera.width = std::max(8, base.camera.width / s.frameDivisor);
    out.height = scene.camera.height = std::max(8, base.camera.height / s.frameDivisor);
    const scenes::Vec3 offset = base.camera.position_cm - base.camera.lookAt_cm;
    struct Sequence {
        const char* label;
        const char* method;
        int samples;
    };
    const Sequence sequences[] = {
        {"multiscale_auto", "multiscale", 0}, {"geometry_1spp", "geometry", 1},
        {"geometry_4spp", "geometry", 4}};
    std::vector<std::vector<Image>> frames(std::size(sequences));
    for (const Sequence& q : sequences) out.rows.push_back({q.label});
    for (int f = 0; f < s.frames; ++f) {
        const double t = s.frames > 1 ? double(f) / double(s.frames - 1) : 0.0;
        scene.camera.position_cm = base.camera.lookAt_cm + offset * (1.0 + (s.dollyEnd - 1.0) * t);
        const TracedScene traced = buildTracedScene(scene);
        for (std::size_t m = 0; m < std::size(sequences); ++m) {
            MethodSettings settings;
            settings.geometry.samples = std::max(1, sequences[m].samples);
            RenderResult r = renderMethod(sequences[m].method).render(traced, settings, {});
            out.rows[m].secondsPerFrame += r.seconds / double(s.frames);
            r.image.aovs.clear();  // only RGB is measured; 16 frames of AOVs would be memory
            frames[m].push_back(std::move(r.image));
        }
        if (log) log("dolly frame " + std::to_string(f + 1) + "/" + std::to_string(s.frames));
    }
    for (std::size_t m = 0; m < out.rows.size(); ++m)
        out.rows[m].flicker = temporalFlicker(frames[m]);
    return out;
}

}  // namespace pine::vdbtrace
