#include "pine/vdbtrace/dolly.h"

#include "pine/vdbtrace/animation_flicker.h"

#include <algorithm>

namespace pine::vdbtrace {

DollyFlicker measureDollyFlicker(const scenes::Scene& base, const CompareSettings& s,
                                 const CompareLog& log)
{
    DollyFlicker out;
    scenes::Camera still = base.camera;
    out.width = still.width = std::max(8, base.camera.width / s.frameDivisor);
    out.height = still.height = std::max(8, base.camera.height / s.frameDivisor);
    // The camera backs away from its look-at, to dollyEnd times its distance.
    const scenes::Vec3 offset = still.position_cm - still.lookAt_cm;
    std::vector<scenes::Camera> cameras;
    for (int f = 0; f < s.frames; ++f) {
        const double t = s.frames > 1 ? double(f) / double(s.frames - 1) : 0.0;
        scenes::Camera c = still;
        c.position_cm = still.lookAt_cm + offset * (1.0 + (s.dollyEnd - 1.0) * t);
        cameras.push_back(c);
    }
    const AnimationFlicker measured =
        measureAnimationFlicker(base, cameras, {}, 0, 0, [&log](const std::string& line) {
            if (log) log("dolly " + line);
        });
    for (const AnimationRow& row : measured.rows) {
        out.rows.push_back({row.method, row.flicker.flicker, row.secondsPerFrame});
    }
    return out;
}

}  // namespace pine::vdbtrace
