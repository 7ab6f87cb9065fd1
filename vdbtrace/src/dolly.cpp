#include "pine/vdbtrace/dolly.h"

#include "pine/vdbtrace/animation_flicker.h"

#include <algorithm>
#include <cmath>

namespace pine::vdbtrace {

DollyFlicker measureDollyFlicker(const scenes::Scene& base, const CompareSettings& s,
                                 const CompareLog& log)
{
    DollyFlicker out;
    scenes::Camera still = base.camera;
    // The frame divided by frameDivisor, but not below 8 pixels on its short side unless the
    // frame itself is; its shape kept (a 16 x 12 frame made 8 x 8 widened the view).
    const int w = base.camera.width, h = base.camera.height, shortSide = std::min(w, h);
    if (shortSide / s.frameDivisor >= 8) {
        still.width = w / s.frameDivisor;
        still.height = h / s.frameDivisor;
    } else if (shortSide > 8) {
        still.width = int(std::lround(w * 8.0 / shortSide));
        still.height = int(std::lround(h * 8.0 / shortSide));
    }
    out.width = still.width;
    out.height = still.height;
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
