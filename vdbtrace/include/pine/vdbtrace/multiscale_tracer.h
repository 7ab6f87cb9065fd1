// `vdbtrace render --method multiscale`: one cone per pixel, each hit shaded by the closed
// form whose scale fits the footprint (paper section 3.2), partial coverages composited
// front to back.
#pragma once

#include "pine/vdbtrace/render_result.h"
#include "pine/vdbtrace/traced_scene.h"

namespace pine::vdbtrace {

/// The level a bough hit is shaded at, from q = footprint width / cone spacing (RenderSettings).
enum class Level { Needle = 1, Cone = 2, Bough = 3 };
Level chooseLevel(double footprint_cm, double coneSpacing_cm, const scenes::RenderSettings& s);

/// Two neighbouring levels and the weight of the upper one: within a band about a threshold
/// the bough is shaded at both and the results mixed, so that nothing steps where q crosses it.
struct LevelBlend {
    Level lower, upper;
    double upperWeight;  ///< 0: lower alone, 1: upper alone
};
LevelBlend blendLevels(double footprint_cm, double coneSpacing_cm,
                       const scenes::RenderSettings& s);

struct MultiscaleOptions {
    /// Forces every bough hit to this level (0: choose by footprint) - for comparisons.
    int forceLevel = 0;
};

/// No fragment of primitive `index` (a branch, or a bough: its needles within its cones'
/// reach of the axis, base to the cones' end) lies nearer along the cone `ray` than this;
/// -infinity where the cone misses the cylinder holding them grown by half its footprint: the
/// tracer never visits such a primitive, which can give no fragment.
double primitiveEntry(const ConeRay& ray, const TracedScene& scene, std::uint32_t index);

/// Renders with the closed forms: needles (level 1) as anti-aliased cylinders, cones (level 2)
/// by eqs. (4)-(6) at each crossing of the true cones, boughs (level 3) as section 6's volume
/// under the scene's bough law (render.bough_law), lit through cone shadow rays.
RenderResult renderMultiscale(const TracedScene& scene, const MultiscaleOptions& method = {},
                              const RenderOptions& options = {});

}  // namespace pine::vdbtrace
