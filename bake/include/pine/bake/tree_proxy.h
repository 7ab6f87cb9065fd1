// What other tools need beside a tree's grids to use it as a proxy: the tree's frame, its trunk
// and branches as a mesh, and the scene's instance list (bake/README.md).
#pragma once

#include "pine/bake/tree_grids.h"

#include <nlohmann/json.hpp>

#include <string>
#include <vector>

namespace pine::scenes {
struct Tree;
struct TreePlacement;
}

namespace pine::bake {

/// The frame a placement puts its tree in: origin at its base, turned about z.
TreeFrame treeFrame(const scenes::TreePlacement& placement);

/// A point of the scene (cm) in a file's world: the tree's frame if the layout has one, in its
/// unit.
Vec3 toFile(const Vec3& world_cm, const FileLayout& layout);

/// The trunk and branches (every segment, the cylinders the tracers draw) as a Wavefront OBJ
/// mesh in the layout's frame and unit: `sides`-gon prisms with caps, outward normals,
/// counter-clockwise faces. One object per tree, one group per branch order.
std::string branchMeshObj(const scenes::Tree& tree, const FileLayout& layout, int sides = 8);

/// One placement of a baked tree.
struct ProxyInstance {
    int tree = 0;                 ///< index among the scene's trees
    std::string grids, mesh;      ///< file names, relative to the instance list
    std::string species;
    unsigned seed = 0;
    std::optional<TreeFrame> frame;  ///< empty when baked in the world frame
};

/// The instance list (JSON) of a scene baked in `unit`: per placement, its files and the
/// transform from the files' frame to the scene's world, in that unit (a 4 x 4 matrix in rows,
/// for column vectors, with its translation and turn about z also apart).
nlohmann::json instanceList(const std::string& scene, LengthUnit unit,
                            const std::vector<ProxyInstance>& instances);

}  // namespace pine::bake
