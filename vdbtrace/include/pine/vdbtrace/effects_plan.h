// What the tracer computes, decided once from the scene's effects: a switched-off effect costs
// nothing (DESIGN.md), and the stats (render_stats.h) prove it.
#pragma once

#include "pine/scenes/scene.h"

namespace pine::vdbtrace {

struct EffectsPlan {
    bool diffuse = true;
    bool specular = false;
    bool shadowRays = false;     ///< cone shadow rays to every light (scene effect "shadows")
    bool selfShadowing = false;  ///< light attenuated by the bough's own layers (section 6)

    static EffectsPlan from(const scenes::Effects& effects)
    {
        return {effects.diffuse, effects.specular, effects.shadows, effects.selfShadowing};
    }
};

}  // namespace pine::vdbtrace
