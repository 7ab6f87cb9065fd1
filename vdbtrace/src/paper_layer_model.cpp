// The paper's layer model (sections 3.3 and 6): each cone is a semi-opaque surface of opacity
// A = 2 N r / (pi R), whatever the angle a line crosses it at and wherever (errata E13). The
// layers are the true cones (E12), as levels 1-2 have always crossed them.
#include "pine/vdbtrace/cone_crossings.h"
#include "pine/vdbtrace/layer_model.h"

#include <algorithm>
#include <cmath>
#include <memory>

namespace pine::vdbtrace {
namespace {

class PaperLayerModel final : public LayerModel {
public:
    void layers(const TracedBough& b, const Vec3& o, const Vec3& d, double tIn, double tOut,
                const std::function<bool(const LayerHit&)>& visit) const override
    {
        forEachConeCrossing(b, o, d, tIn, tOut, [&](long j, double t) {
            return visit(LayerHit{j, t, b.layerOpacity});
        });
    }

    double transmittance(const TracedBough& b, const Vec3& x, const Vec3& towardsLight, long,
                         const Vec3&) const override
    {
        double tIn, tOut;
        if (!layeredInterval(b, x, towardsLight, tIn, tOut)) return 1.0;
        int count = 0;
        forEachConeCrossing(b, x, towardsLight, std::max(tIn, 1e-6), tOut,
                            [&count](long, double) { ++count; });
        return std::pow(1.0 - b.layerOpacity, count);
    }
};

}  // namespace

std::unique_ptr<LayerModel> makePaperLayerModel() { return std::make_unique<PaperLayerModel>(); }

}  // namespace pine::vdbtrace
