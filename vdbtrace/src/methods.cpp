#include "pine/vdbtrace/methods.h"

#include "pine/bake/tree_boughs.h"

#include <chrono>

namespace pine::vdbtrace {
namespace {

RenderResult multiscale(const TracedScene& scene, const MethodSettings& s,
                        const RenderOptions& options)
{
    return renderMultiscale(scene, s.multiscale, options);
}

nlohmann::json describeMultiscale(const scenes::Scene& scene, const MethodSettings&)
{
    return {{"bough_law", scene.render.model.boughLaw},
            {"layer_model", scene.render.model.layerModel},
            {"shadow_origin", scene.render.model.shadowOrigin},
            {"level_blend", scene.render.model.levelBlend},
            {"bark", scene.render.model.bark},
            {"layer_correlation", scene.render.model.layerCorrelation},
            {"occluder_profile", scene.render.model.occluderProfile},
            {"needle_level_max", scene.render.needleLevelMax},
            {"cone_level_max", scene.render.model.coneLevelMax},
            {"pixel_split_q", scene.render.model.pixelSplitQ}};
}

RenderResult reference(const TracedScene& scene, const MethodSettings& s,
                       const RenderOptions& options)
{
    if (s.grids) return renderReference(scene, *s.grids, s.reference, options);
    using Clock = std::chrono::steady_clock;
    const auto start = Clock::now();
    bake::BakeSettings baking = referenceBake(s.voxelSize_cm);
    baking.extinctionLaw = scene.scene->render.model.extinctionLaw;
    const bake::TreeGrids grids = bake::bakeScene(scene.trees, baking);
    const double bakeSeconds = std::chrono::duration<double>(Clock::now() - start).count();
    RenderResult result = renderReference(scene, grids, s.reference, options);
    result.seconds += bakeSeconds;
    result.prepSeconds += bakeSeconds;
    return result;
}

nlohmann::json describeReference(const scenes::Scene& scene, const MethodSettings& s)
{
    return {{"voxel_size_cm", s.grids ? s.grids->voxelSize_cm : s.voxelSize_cm},
            {"rays_per_pixel", s.reference.subpixels * s.reference.subpixels},
            {"extinction_law",
             s.grids ? s.grids->extinctionLaw : scene.render.model.extinctionLaw}};
}

RenderResult geometry(const TracedScene& scene, const MethodSettings& s,
                      const RenderOptions& options)
{
    return renderGeometry(scene, s.geometry, options);
}

nlohmann::json describeGeometry(const scenes::Scene& scene, const MethodSettings& s)
{
    return {{"samples_per_pixel", s.geometry.samples},
            {"needle_ends", scene.render.model.needleEnds},
            {"needle_primitive",
             s.geometry.primitive == NeedlePrimitive::Curve ? "curve" : "cylinder"}};
}

int oneCone(const MethodSettings&) { return 1; }
int referenceRays(const MethodSettings& s) { return s.reference.subpixels * s.reference.subpixels; }
int geometrySamples(const MethodSettings& s) { return s.geometry.samples; }

}  // namespace

const std::vector<RenderMethod>& renderMethods()
{
    static const std::vector<RenderMethod> methods = {
        {"multiscale", "closed forms, each hit at the level its footprint calls for", multiscale,
         describeMultiscale, oneCone, true, true, TracedSceneParts{.grownTrees = false}},
        // The reference marches one set of grids merged from every tree; each voxel is the tree
        // whose fields it keeps (bake::TreeGrids::tree; -1 in files naming none).
        {"reference", "equation 7 numerically through OpenVDB grids of the boughs", reference,
         describeReference, referenceRays, false, true, TracedSceneParts{}},
        {"geometry", "explicit needle cylinders, point samples (the ground truth)", geometry,
         describeGeometry, geometrySamples, false, true,
         TracedSceneParts{.primitiveIndex = false, .boughLaws = false, .grownTrees = false}},
    };
    return methods;
}

bool computesAov(const RenderMethod& method, const std::string& aov, const EffectsPlan& plan)
{
    if (aov == "level") return method.levels;
    if (aov == "tree") return method.treeIds;
    if (aov == "diffuse") return plan.diffuse;
    if (aov == "specular") return plan.specular;
    return true;  // depth, foliage
}

const RenderMethod& renderMethod(const std::string& name)
{
    std::string known;
    for (const RenderMethod& m : renderMethods()) {
        if (m.name == name) return m;
        known += (known.empty() ? "" : ", ") + std::string(m.name);
    }
    throw InputError("method '" + name + "' is not available (" + known + ")");
}

}  // namespace pine::vdbtrace
