// render.shadow_origin "bough": each bough's shadow from the rest of the scene, computed once
// per bough and light for a frame and read by every hit on the bough at levels 2-3. Section 7
// factors the part of the shadow ray outside the bough out of the bough's shader; here that
// part is also shared by all the bough's pixels, so that a frame costs a few shadow cones a
// bough instead of one per bough hit (issue: a multiscale tracer that earns its name).
#pragma once

#include "pine/vdbtrace/geometry.h"
#include "pine/vdbtrace/render_stats.h"

#include <cstddef>
#include <cstdint>
#include <memory>
#include <mutex>
#include <vector>

namespace pine::vdbtrace {

struct TracedBough;
struct TracedScene;

class BoughShadows {
public:
    /// At most this many samples along one bough.
    static constexpr int kMaxSamples = 8;

    /// Nothing is computed yet. `scene` must outlive this. With `selfShadowing` a needle's
    /// share of the mean is also weighted by the light its own bough lets through to it.
    BoughShadows(const TracedScene& scene, bool selfShadowing);

    /// Samples along bough `b`, base to the cones' end: one per diameter 2R, 1 to kMaxSamples.
    static int samplesAlong(const TracedBough& b);

    /// Transmittance from light `light` through everything but bough `primitive` to where x
    /// projects on its axis: linear between the samples. Each sample is one shadow cone
    /// holding lines from points over the bough's cross-section, where its needles lie
    /// (ShadowSamples), their mean weighted by the light each needle reflects to the camera.
    /// The bough's samples for that light are traced on first use, once, from any thread;
    /// their cones are counted in `stats.shadowRays`.
    double transmittance(std::size_t primitive, std::size_t light, const Vec3& x,
                         RenderStats& stats) const;

private:
    void fill(std::size_t bough, std::size_t light, RenderStats& stats) const;

    const TracedScene& mScene;
    bool mSelfShadowing;
    std::vector<std::uint32_t> mFirst;  ///< per bough and light: its first sample in mValues
    std::vector<std::uint8_t> mCount;   ///< per bough: samples along it
    std::unique_ptr<std::once_flag[]> mOnce;  ///< per bough and light
    mutable std::vector<double> mValues;
};

}  // namespace pine::vdbtrace
