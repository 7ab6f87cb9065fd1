#include "pine/vdbtrace/stats_json.h"

#include "pine/support/atomic_file.h"


namespace pine::vdbtrace {

nlohmann::json toJson(const RenderStats& s)
{
    const char* levels[4] = {"none", "needle", "cone", "bough"};
    nlohmann::json pixels, seconds;
    for (int k = 0; k < 4; ++k) {
        pixels[levels[k]] = s.pixelsPerLevel[k];
        seconds[levels[k]] = double(s.nanosecondsPerLevel[k]) * 1e-9;
    }
    return {
        {"cone_rays", s.coneRays},
        {"shadow_rays", s.shadowRays},
        {"self_shadow_evaluations", s.selfShadowEvaluations},
        {"hits",
         {{"needle", s.needleHits},
          {"cone", s.coneHits},
          {"bough", s.boughHits},
          {"branch", s.branchHits},
          {"ground", s.groundHits}}},
        {"voxel_spans", s.voxelSpans},
        {"evaluations", {{"diffuse", s.diffuseEvaluations}, {"specular", s.specularEvaluations}}},
        {"pixels_per_level", pixels},
        {"thread_seconds_per_level", seconds}};
}

nlohmann::json toJson(const EffectsPlan& p)
{
    return {{"diffuse", p.diffuse},
            {"specular", p.specular},
            {"shadows", p.shadowRays},
            {"self_shadowing", p.selfShadowing}};
}

void writeJsonAtomically(const nlohmann::json& json, const std::filesystem::path& path)
{
    io::writeTextAtomically(path, json.dump(2) + "\n");
}

}  // namespace pine::vdbtrace
