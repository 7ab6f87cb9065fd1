#include "pine/bake/tree_boughs.h"

#include "manifest.h"
#include "pine/scenes/colours.h"
#include "pine/scenes/tree.h"

#include <stdexcept>

namespace pine::bake {

analytic::BoughGeometry boughGeometry(const scenes::NeedleParameters& p)
{
    analytic::BoughGeometry g;
    g.cone.aperture_rad = p.aperture_rad;
    g.cone.needleLength_cm = p.length_cm;
    g.cone.needleRadius_cm = p.radius_cm;
    // Whole needles: the explicit needles (NeedleLayout) draw a whole number a cone, so every
    // method's N is that one, not the scene's mean over the bough (12 at the base and 9 at the
    // tip is 10.5 at the middle; the needles draw 11, and so do the closed forms and the bake).
    g.cone.needlesPerCone = scenes::wholeNeedles(p.perCone);
    g.coneSpacing_cm = p.coneSpacing_cm;
    return g;
}

std::vector<BoughSpec> treeBoughs(const scenes::Tree& tree)
{
    if (!tree.species) throw std::invalid_argument("treeBoughs: the tree has no species");
    const Vec3 albedo = scenes::needleColour(*tree.species);
    std::vector<BoughSpec> out;
    out.reserve(tree.boughs.size());
    for (const scenes::Bough& bough : tree.boughs) {
        const scenes::Segment& segment = tree.segments.at(bough.segment);
        BoughSpec spec;
        spec.base_cm = segment.base_cm;
        spec.tip_cm = segment.tip_cm;
        spec.needles = boughGeometry(scenes::lerp(bough.atBase, bough.atTip, 0.5));
        spec.needleAlbedo = albedo;
        out.push_back(spec);
    }
    return out;
}

std::string treeDigest(const std::vector<BoughSpec>& boughs)
{
    detail::Fnv1a64 hash;
    const auto add = [&](double v) {
        hash.update(std::string_view(reinterpret_cast<const char*>(&v), sizeof v));
    };
    for (const BoughSpec& b : boughs) {
        for (int i = 0; i < 3; ++i) {
            add(b.base_cm[i]);
            add(b.tip_cm[i]);
            add(b.needleAlbedo[i]);
        }
        const analytic::ConeGeometry& c = b.needles.cone;
        for (double v : {c.aperture_rad, c.needleLength_cm, c.needleRadius_cm,
                         double(c.needlesPerCone), b.needles.coneSpacing_cm}) {
            add(v);
        }
    }
    return detail::Fnv1a64::hex(hash.value());
}

TreeGrids bakeScene(const std::vector<scenes::Tree>& trees, const BakeSettings& settings)
{
    std::vector<BoughSpec> all;
    for (std::size_t i = 0; i < trees.size(); ++i) {
        for (BoughSpec& b : treeBoughs(trees[i])) {
            b.tree = int(i);
            all.push_back(b);
        }
    }
    return bakeBoughs(all, settings);
}

}  // namespace pine::bake
