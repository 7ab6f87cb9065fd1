#include "pine/bake/tree_boughs.h"

#include "pine/scenes/tree.h"

#include <stdexcept>

namespace pine::bake {

std::vector<BoughSpec> treeBoughs(const scenes::Tree& tree)
{
    if (!tree.species) throw std::invalid_argument("treeBoughs: the tree has no species");
    const double grey = tree.species->needleAlbedo;
    const Vec3 albedo = Vec3(kNeedleHue[0], kNeedleHue[1], kNeedleHue[2]) * (grey / kNeedleHue[1]);
    std::vector<BoughSpec> out;
    out.reserve(tree.boughs.size());
    for (const scenes::Bough& bough : tree.boughs) {
        const scenes::Segment& segment = tree.segments.at(bough.segment);
        const scenes::NeedleParameters p = scenes::lerp(bough.atBase, bough.atTip, 0.5);
        BoughSpec spec;
        spec.base_cm = segment.base_cm;
        spec.tip_cm = segment.tip_cm;
        spec.aperture_rad = p.aperture_rad;
        spec.needleLength_cm = p.length_cm;
        spec.needleRadius_cm = p.radius_cm;
        spec.needlesPerCone = p.perCone;
        spec.coneSpacing_cm = p.coneSpacing_cm;
        spec.needleAlbedo = albedo;
        out.push_back(spec);
    }
    return out;
}

}  // namespace pine::bake
