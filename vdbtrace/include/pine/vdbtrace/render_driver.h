// The render loop every method shares (pbrt-v4's ImageTileIntegrator: one loop, one hook).
// The driver owns the camera, the tiles, the samples of each pixel, compositing, the AOVs,
// progress, timing and stats; a method supplies only what a camera ray meets (its fragments).
#pragma once

#include "pine/vdbtrace/cone_camera.h"
#include "pine/vdbtrace/fragment.h"
#include "pine/vdbtrace/render_result.h"
#include "pine/vdbtrace/traced_scene.h"

#include <memory>

namespace pine::vdbtrace {

/// One way to shade what a camera ray meets: multiscale, reference or geometry.
class ShadingMethod {
public:
    /// Per-thread state of a method: it traces one camera ray at a time.
    class RayTracer {
    public:
        virtual ~RayTracer() = default;
        /// Adds what `ray` meets to `composite`, in front-to-back order, counting into the
        /// stats it was made with.
        virtual void trace(const ConeRay& ray, FrontToBack& composite) = 0;
        /// After trace() of a pixel's one cone `pixel` (ShadingMethod::splitsPixels): how many
        /// cones along each axis the pixel calls for in its place, each as wide as its share
        /// of the pixel; 1: the one cone stands. `square` is as wide as the disc through the
        /// pixel's corners (ConeCamera::squareCone), for what lies in them alone.
        virtual int pixelSplit(const ConeRay& /*pixel*/, const ConeRay& /*square*/) const
        {
            return 1;
        }
    };

    virtual ~ShadingMethod() = default;
    /// Camera rays per pixel; their values are averaged.
    virtual int samplesPerPixel() const = 0;
    /// Camera ray `s` of pixel (x, y), s in [0, samplesPerPixel()).
    virtual ConeRay sample(const ConeCamera& camera, int x, int y, int s) const = 0;
    virtual std::unique_ptr<RayTracer> rayTracer(RenderStats& stats) const = 0;
    /// Whether, with one sample a pixel, each pixel's cone is traced first and then, where its
    /// tracer asks (RayTracer::pixelSplit), replaced by k x k narrower cones: the pixel their
    /// mean, the first cone's foliage not counted.
    virtual bool splitsPixels() const { return false; }
};

/// Renders the scene's camera with `method`: every pixel the mean of its samples' composites
/// (RGBA, diffuse, specular, foliage), its level the coverage-weighted mean level, its depth the
/// ceil(S/2)-th nearest of its S samples' depths (where the pixel's coverage passes 1/2). The
/// same image whatever the thread count. `result.seconds` is the loop's time alone. Throws
/// InputError when a pixel's value is not finite (radiance overflowing float).
RenderResult renderImage(const TracedScene& scene, const ShadingMethod& method,
                         const RenderOptions& options);

}  // namespace pine::vdbtrace
