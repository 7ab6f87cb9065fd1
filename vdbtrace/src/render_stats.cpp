#include "pine/vdbtrace/render_stats.h"

namespace pine::vdbtrace {

RenderStats& RenderStats::operator+=(const RenderStats& o)
{
    coneRays += o.coneRays;
    shadowRays += o.shadowRays;
    selfShadowEvaluations += o.selfShadowEvaluations;
    needleHits += o.needleHits;
    coneHits += o.coneHits;
    boughHits += o.boughHits;
    branchHits += o.branchHits;
    groundHits += o.groundHits;
    voxelSpans += o.voxelSpans;
    diffuseEvaluations += o.diffuseEvaluations;
    specularEvaluations += o.specularEvaluations;
    for (int k = 0; k < 4; ++k) {
        pixelsPerLevel[k] += o.pixelsPerLevel[k];
        nanosecondsPerLevel[k] += o.nanosecondsPerLevel[k];
    }
    return *this;
}

}  // namespace pine::vdbtrace
