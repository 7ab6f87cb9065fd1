// The methods a user chooses by name (`vdbtrace render --method`, `vdbtrace compare`): one
// registry, so that both run a method the same way and describe its settings the same way.
#pragma once

#include "pine/bake/tree_grids.h"
#include "pine/vdbtrace/effects_plan.h"
#include "pine/vdbtrace/geometry_tracer.h"
#include "pine/vdbtrace/multiscale_tracer.h"
#include "pine/vdbtrace/reference_tracer.h"

#include <nlohmann/json.hpp>

#include <string>
#include <vector>

namespace pine::vdbtrace {

/// Every method's settings; each method reads its own.
struct MethodSettings {
    MultiscaleOptions multiscale;
    ReferenceOptions reference;
    /// reference: without `grids`, the scene's trees are baked (bake::bakeScene) at this size
    double voxelSize_cm = 0.25;
    const bake::TreeGrids* grids = nullptr;  ///< reference: grids read from files instead
    GeometryOptions geometry;
};

struct RenderMethod {
    const char* name;
    const char* description;  ///< one line, for --help
    /// Renders the scene's camera; result.seconds includes what the method prepares first
    /// (the reference's bake, the geometry's BVH), reported in result.prepSeconds.
    RenderResult (*render)(const TracedScene& scene, const MethodSettings& settings,
                           const RenderOptions& options);
    /// The settings the method reads, as the stats JSON and the EXR header record them.
    nlohmann::json (*describe)(const scenes::Scene& scene, const MethodSettings& settings);
    /// Rays (or cones) traced per pixel, as the EXR header's samplesPerPixel records them.
    int (*samplesPerPixel)(const MethodSettings& settings);
    bool levels;   ///< shades at the paper's levels (the "level" AOV means something)
    bool treeIds;  ///< knows which tree each fragment comes from (the "tree" AOV)
    TracedSceneParts parts;  ///< what it reads of the traced scene (buildTracedScene)
};

/// Whether `method` computes AOV `aov` (of kAovNames) for a scene with these effects: what an
/// output holds (the others are zero or unknown).
bool computesAov(const RenderMethod& method, const std::string& aov, const EffectsPlan& plan);

/// The registered methods: multiscale, reference, geometry.
const std::vector<RenderMethod>& renderMethods();
/// The method named `name`; throws InputError naming the registered ones.
const RenderMethod& renderMethod(const std::string& name);

}  // namespace pine::vdbtrace
