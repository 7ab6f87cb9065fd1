// How much one layer of needles stops a line that crosses it (docs/errata.md E13): the choice
// every level that sees a bough's cones as layers makes (level 2, the self-shadowing of levels
// 1-2, and level 3's exact law). A model is a type registered by name in src/layer_models.cpp
// and chosen once per render (the scene's render.layer_model).
#pragma once

#include "pine/vdbtrace/traced_scene.h"

#include <functional>
#include <string>
#include <vector>

namespace pine::vdbtrace {

/// One layer of a bough met by a line: cone `cone`'s needles, where the line meets them.
struct LayerHit {
    long cone = 0;
    double t = 0.0;        ///< along the line: where its needles are met
    double opacity = 0.0;  ///< the probability that the line hits one of them, in [0, 1]
    /// Where a model knows the needle azimuths that stop the line there (the "arcs" model,
    /// cone_arcs.h): their arc about the axis, radians in NeedleLayout's frame; width 0 where
    /// it does not. The arc is the passage's own, before the line's other passages of the
    /// cone: `opacity` is what it adds to them.
    double arcFrom = 0.0, arcWidth = 0.0;
};

class LayerModel {
public:
    virtual ~LayerModel() = default;
    /// Calls visit for every layer of b that the line o + t d (d unit) meets for t in
    /// [tIn, tOut], in order along it (transmittancesAlong reads the layers before a needle
    /// as those the view's line met), until it returns false (a line gone opaque needs no
    /// more); each layer's needles are independent of every other layer's (each cone has its
    /// own roll, needle_layout.h).
    virtual void layers(const TracedBough& b, const Vec3& o, const Vec3& d, double tIn,
                        double tOut, const std::function<bool(const LayerHit&)>& visit) const = 0;
    /// The light that reaches x on a needle of cone `ownCone` from unit direction
    /// `towardsLight` through b's other layers (section 6's self-shadowing, counted), for a
    /// needle seen from unit direction `towardsViewer` through b's layers in front of it (a
    /// model whose layers' needles lie where the view's line passed may condition on it: the
    /// layer correlation; a zero vector: not seen, or not known).
    virtual double transmittance(const TracedBough& b, const Vec3& x, const Vec3& towardsLight,
                                 long ownCone, const Vec3& towardsViewer) const = 0;
    /// transmittance() for every needle a viewing line meets: `hits` are the layers of b that
    /// the line o + t d (d unit, from the viewer) met, front to back, as layers() gave them;
    /// out[k] is the light from unit `towardsLight` that reaches hits[k]'s needles at
    /// o + hits[k].t d, seen through hits[0, k) (towardsViewer -d). This base calls
    /// transmittance() for each; a model that conditions on the view's line reads that line's
    /// layers from `hits` in place of walking it again from every needle. They are the same
    /// bands, each integrated from the edge the line enters it by rather than the other, so
    /// the two agree to the bands' quadrature (cone_crossings.h), which the conditioning
    /// magnifies near the hot spot (a light within a degree of the view: a needle's light up
    /// to 2e-2 lower, the line's mean 1e-5); and where the line starts inside b (a viewer
    /// among the needles) only the layers in front of the viewer count, where a walk back
    /// from the needle went on behind the viewer (docs/architecture.md).
    virtual void transmittancesAlong(const TracedBough& b, const Vec3& o, const Vec3& d,
                                     const std::vector<LayerHit>& hits, const Vec3& towardsLight,
                                     std::vector<double>& out) const;
    /// A needle on a viewing line: where along it, its cone, and the point of its axis nearest
    /// the line (all of the needle's axis lies at its azimuth, which fixes its cone's roll).
    struct NeedleOnLine {
        double t;
        long cone;
        Vec3 onAxis;
    };
    /// transmittancesAlong() for needles anywhere on the line o + t d, t in [tIn, tOut] (level
    /// 1's, each found near its cone's sheet), `hits` the line's layers over that span:
    /// out[k] for needles[k]. This base calls transmittance() for each; a model that
    /// conditions on the view's line reads the layers before a needle's band from `hits`
    /// where a walk back from the needle would leave that band out as its own (the needle
    /// inside the span, in a band of its own cone not hidden in the bark between it and the
    /// band's start), and walks back from the others.
    virtual void transmittancesAt(const TracedBough& b, const Vec3& o, const Vec3& d, double tIn,
                                  double tOut, const std::vector<LayerHit>& hits,
                                  const std::vector<NeedleOnLine>& needles,
                                  const Vec3& towardsLight, std::vector<double>& out) const;
};

/// The model registered as `name`, its crossings of one cone `correlated` or not (see
/// layerCorrelated; a model without needle azimuths, as "paper", is independent either way);
/// throws InputError naming the registered ones.
const LayerModel& layerModel(const std::string& name, bool correlated);
/// The registered names, in registration order.
std::vector<std::string> layerModelNames();
/// Whether the render.layer_correlation `name` correlates a cone's crossings: "needles" (the
/// lines of the view and of the light through one cone meet its same evenly spaced needles)
/// does, "independent" (every crossing on its own, section 6) does not; throws InputError
/// naming the known ones.
bool layerCorrelated(const std::string& name);
/// The values of render.layer_correlation, the faithful one first.
std::vector<std::string> layerCorrelationNames();

}  // namespace pine::vdbtrace
