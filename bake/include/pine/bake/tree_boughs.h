// From the scene's tree model to what bake voxelizes: one BoughSpec per scenes::Bough.
#pragma once

#include "pine/bake/layer_field.h"

#include <vector>

namespace pine::scenes {
struct Tree;
}

namespace pine::bake {

/// The needle hue of the tracer (vdbtrace/src/traced_scene.cpp, kNeedleHue): a species' grey
/// needle albedo a becomes a hue * a / hue.y, so bakes and renders colour needles alike.
inline constexpr double kNeedleHue[3] = {0.45, 1.0, 0.35};

/// The boughs of a grown tree (scenes::growTree, with its species set): branch from the
/// segment's base to its tip, needle parameters at mid-bough (they vary slowly along a branch,
/// section 3.1), albedo the species' needle albedo in the tracer's hue.
std::vector<BoughSpec> treeBoughs(const scenes::Tree& tree);

}  // namespace pine::bake
