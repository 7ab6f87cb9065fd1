// A render as its EXR holds it (docs/vdbtrace.md, "Outputs"): what compositors and other
// renderers expect of the file, the same for `render` and `compare`.
#pragma once

#include "pine/vdbtrace/cone_camera.h"
#include "pine/vdbtrace/image.h"
#include "pine/vdbtrace/methods.h"

namespace pine::vdbtrace {

/// RGBA, the AOVs `method` computes for a scene of these effects (computesAov), and depth as
/// OpenEXR's Z: the distance along the view axis of the pixel centre's ray, +infinity where
/// nothing covers the pixel's middle. A crop keeps its place in the frame.
Image exrImage(const Image& rendered, const ConeCamera& camera, const RenderMethod& method,
               const EffectsPlan& plan);

/// The camera's matrices as OpenEXR's worldToCamera and worldToNDC attributes (m44f, row
/// vectors: ConeCamera's matrices transposed).
Metadata cameraMetadata(const ConeCamera& camera);

}  // namespace pine::vdbtrace
