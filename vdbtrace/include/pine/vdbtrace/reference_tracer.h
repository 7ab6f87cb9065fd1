// `vdbtrace render --method reference`: equation (7) evaluated numerically through baked
// OpenVDB grids of the layer field (bake/layer_field.h), with no approximation beyond the
// voxelization: extinction sigma(d) = -ln(1 - A) |d . G| of the local layer gradient G, exact
// exponential transmittance, each voxel's needles lit by eqs. (1)-(2) of its needle direction.
//
// Integration: the fields are piecewise constant on voxels, so the march walks the ray voxel by
// voxel (a DDA, no fixed step, hence no banding) and integrates each span exactly:
// alpha = 1 - exp(-sigma dt), emission (1 - A_before) alpha J. What remains is the
// voxelization's error, O(h) at the boughs' boundaries (bake tests), and the light's
// transmittance, sampled once per voxel at its centre (O(h) too).
#pragma once

#include "pine/bake/tree_grids.h"
#include "pine/vdbtrace/multiscale_tracer.h"
#include "pine/vdbtrace/traced_scene.h"

namespace pine::vdbtrace {

struct ReferenceOptions {
    int subpixels = 2;  ///< rays per pixel along each axis, stratified: the cone's footprint
    std::function<void(double)> progress;
};

/// All boughs of all trees of `scene` in one set of grids at `voxelSize_cm`.
bake::TreeGrids bakeScene(const TracedScene& scene, double voxelSize_cm);

/// Renders `scene` (branches and ground as in the multiscale method, boughs through `grids`).
/// Light is attenuated through the grids when the scene asks for shadows or self-shadowing
/// (the grids hold every bough: the two are not told apart), and by branches with shadows.
RenderResult renderReference(const TracedScene& scene, const bake::TreeGrids& grids,
                             const ReferenceOptions& options = {});

}  // namespace pine::vdbtrace
