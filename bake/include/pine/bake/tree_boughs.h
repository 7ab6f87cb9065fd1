// From the scene's tree model to what bake voxelizes: one BoughSpec per scenes::Bough.
#pragma once

#include "pine/bake/layer_field.h"
#include "pine/bake/tree_grids.h"

#include <string>
#include <vector>

namespace pine::scenes {
struct NeedleParameters;
struct Tree;
}

namespace pine::bake {

/// A scene's needle parameters (scenes::NeedleParameters) as the shaders' type: the one place
/// where one becomes the other. N is rounded to whole needles, as the explicit needles draw it.
analytic::BoughGeometry boughGeometry(const scenes::NeedleParameters& p);

/// The boughs of a grown tree (scenes::growTree, with its species set), one per tree.boughs in
/// order: branch from the segment's base to its tip, needle parameters at mid-bough (they vary
/// slowly along a branch, section 3.1), albedo scenes::needleColour. The tracer prepares its
/// boughs from the same list.
std::vector<BoughSpec> treeBoughs(const scenes::Tree& tree);

/// A digest of the boughs (their ends, needle parameters and albedo, FNV-1a 64 in 16 hex
/// digits): bake records it in each file, and a render refuses grids of another tree.
std::string treeDigest(const std::vector<BoughSpec>& boughs);

/// The boughs of all `trees` in one set of grids, the trees' boughs in order: what the
/// reference method renders a whole scene through (bake tree/scene write one file a tree).
/// Each bough's tree is its index in `trees` (TreeGrids::tree).
TreeGrids bakeScene(const std::vector<scenes::Tree>& trees, const BakeSettings& settings);

}  // namespace pine::bake
