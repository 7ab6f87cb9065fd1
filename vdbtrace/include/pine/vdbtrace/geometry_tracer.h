// `vdbtrace render --method geometry`: the explicit-needle ground truth. Every needle of every
// bough (the same needles the multiscale level 1 draws, needle_layout.h) and every branch is
// a solid cylinder in one Embree 3 BVH (a scatter variant's needles once, instanced at each of
// its trees); each pixel takes N point samples, each hit is shaded with the per-point
// integrands of the paper's eqs. (1) and (2) (section 4), lit through shadow rays. Averaged
// over a needle's visible surface these give eqs. (1)-(2) times its projected area, so the
// multiscale and reference tracers can be measured against it.
#pragma once

#include "pine/vdbtrace/render_result.h"
#include "pine/vdbtrace/traced_scene.h"

#include <cstddef>
#include <functional>

namespace pine::vdbtrace {

/// What building the BVH cost (`vdbtrace` prints it).
struct GeometryBuild {
    std::size_t needles = 0, branches = 0;  ///< cylinders laid out one by one
    /// Scatter variants (scenes::TreePlacement::variantOf) drawn as Embree instances: their
    /// needles, laid out once per variant, and the trees that instance them.
    std::size_t variants = 0, variantNeedles = 0, instancedTrees = 0;
    double seconds = 0.0;               ///< cylinders laid out and the BVH committed
    std::size_t primitiveBytes = 0;     ///< our cylinder records
    std::size_t embreePeakBytes = 0;    ///< Embree's own allocations at their peak (the BVH)
};

/// What Embree walks for a cylinder (`--needle-primitive`).
enum class NeedlePrimitive {
    /// Embree's native RTC_GEOMETRY_TYPE_CONE_LINEAR_CURVE with equal radii: the same solid,
    /// flat-capped cylinder, found by Embree's own single-precision intersector; the hit
    /// Embree reports is then intersected again in double precision to be shaded.
    Curve,
    /// Embree user geometry: every candidate intersected in double precision, ties between
    /// equal distances broken by primitive index (slower; for tests that need it).
    Cylinder,
};

struct GeometryOptions {
    NeedlePrimitive primitive = NeedlePrimitive::Curve;
    /// Point samples per pixel, on a digitally shifted (0,2)-sequence (Sobol' dimensions 1-2):
    /// every power of two of them is stratified in every elementary interval of the pixel.
    int samples = 16;
    /// Selects another shift of the sequence: an independent render with the same error
    /// statistics (tests compare against one).
    unsigned sampleSeed = 0;
    /// Called once the BVH is built, before the first ray.
    std::function<void(const GeometryBuild&)> built;
};

/// Renders the scene with explicit needle cylinders. The image is the mean of the samples:
/// premultiplied RGBA (alpha = fraction of samples that hit anything), AOVs "depth" (where
/// the fraction of samples hit passes 0.5), "diffuse", "specular" (luminance), "foliage"
/// (fraction of samples hitting needles) and "level" (0: no scale is chosen here).
/// Stats: coneRays = samples traced, shadowRays, needle/branch/ground hits, evaluations.
/// The same image whatever the thread count: each sample's position depends only on (x, y,
/// sample index, sampleSeed), and a closest hit only on the ray and the BVH.
/// @note With explicit geometry, shadows and self-shadowing are one mechanism (a needle's
/// shadow ray meets the other needles of its own bough as it meets every other cylinder), so
/// either scene effect turns shadow rays on. The ground casts no shadow, as in the other
/// methods.
/// @throw std::runtime_error if Embree fails (device, memory).
RenderResult renderGeometry(const TracedScene& scene, const GeometryOptions& method = {},
                            const RenderOptions& options = {});

}  // namespace pine::vdbtrace
