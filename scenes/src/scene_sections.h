// The readers of a scene file's sections, shared between the files that implement them
// (private to pine_scenes). Each reads one JSON value, checks it, and throws SceneError.
#pragma once

#include "json_reader.h"

#include "pine/scenes/scene.h"

#include <vector>

namespace pine::scenes::detail {

/// One entry of "species" (species_parser.cpp).
Species readSpecies(const Json& value, const Where& where);

/// The "trees" array, scatters expanded, bases set on the ground (placement_parser.cpp).
/// Reads the scene's species and ground, which must be read already.
std::vector<TreePlacement> readTrees(const Json& value, const Where& where, const Scene& scene);

}  // namespace pine::scenes::detail
