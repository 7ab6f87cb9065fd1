// `vdbtrace render --method reference`: equation (7) evaluated numerically through baked
// OpenVDB grids of the layer field (bake/layer_field.h), with no approximation beyond the
// voxelization: the extinction law the grids were baked with (bake/extinction_law.h), exact
// exponential transmittance, each voxel's needles lit by eqs. (1)-(2) of its needle direction.
//
// Integration: the fields are piecewise constant on voxels, so the march walks the ray voxel by
// voxel (a DDA, no fixed step, hence no banding) and integrates each span exactly:
// alpha = 1 - exp(-sigma dt), emission (1 - A_before) alpha J. What remains is the
// voxelization's error, O(h) at the boughs' boundaries (bake tests), and the light's
// transmittance, sampled once per voxel at its centre (O(h) too).
#pragma once

#include "pine/bake/tree_grids.h"
#include "pine/vdbtrace/render_result.h"
#include "pine/vdbtrace/traced_scene.h"

#include <memory>

namespace pine::vdbtrace {

struct ReferenceOptions {
    int subpixels = 2;  ///< rays per pixel along each axis, stratified: the cone's footprint
};

/// What the reference reads of a bake: the full-resolution fields (no density pyramid).
inline bake::BakeSettings referenceBake(double voxelSize_cm)
{
    bake::BakeSettings settings;
    settings.voxelSize_cm = voxelSize_cm;
    settings.pyramidLevels = 1;
    return settings;  // the default extinction law
}

/// Renders `scene` (branches and ground as in the multiscale method, boughs through `grids`).
/// Light is attenuated through the grids when the scene asks for shadows or self-shadowing
/// (the grids hold every bough: the two are not told apart), and by branches with shadows.
/// Each voxel's needles reflect with its tree's specular lobe (bake::TreeGrids::tree; the
/// scene's first bough's where no tree is known) and sum into its tree's foliage.
RenderResult renderReference(const TracedScene& scene, const bake::TreeGrids& grids,
                             const ReferenceOptions& method = {},
                             const RenderOptions& options = {});

/// The light a line lets through baked grids, read as the reference reads a line that starts
/// outside the boughs (layer_bands.h: the layers at an unknown phase); no branches. The
/// field's own transmittance, for tests and studies. One thread's: reading the grids for a
/// line needs an intersector of their topology, made once here.
class FieldTransmittance {
public:
    explicit FieldTransmittance(const bake::TreeGrids& grids);  ///< `grids` outlive this
    FieldTransmittance(FieldTransmittance&&) noexcept;          ///< one a thread, in a vector
    FieldTransmittance& operator=(FieldTransmittance&&) noexcept;
    ~FieldTransmittance();
    /// The line o + t d (d unit), t in [0, tMax].
    double operator()(const Vec3& o, const Vec3& d, double tMax);

private:
    struct Reader;
    std::unique_ptr<Reader> mReader;
};

}  // namespace pine::vdbtrace
