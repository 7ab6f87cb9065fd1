// The registry of layer models: to add one, write its type in a file of its own (as
// fibre_layer_model.cpp), declare its factory here and add it to the tables, one per layer
// correlation (render.layer_correlation).
#include "pine/vdbtrace/layer_model.h"

#include "pine/support/registry.h"

namespace pine::vdbtrace {

std::unique_ptr<LayerModel> makeArcsLayerModel(bool correlated);
std::unique_ptr<LayerModel> makeFibreLayerModel(bool correlated);
std::unique_ptr<LayerModel> makePaperLayerModel();

namespace {

// The models whose crossings of one cone share its needles (render.layer_correlation
// "needles"), and those whose crossings are each independent ("independent").
const Registry<LayerModel>& registry(bool correlated)
{
    static const auto table = [](bool c) {
        Registry<LayerModel> r("layer model");
        r.add("fibre", makeFibreLayerModel(c));  // the needles' own statistics, over bands
        r.add("arcs", makeArcsLayerModel(c));    // ... over each crossing's exact arc
        r.add("paper", makePaperLayerModel());   // constant A whatever the crossing (sec. 3.3)
        return r;
    };
    static const Registry<LayerModel> correlatedModels = table(true), independent = table(false);
    return correlated ? correlatedModels : independent;
}

const Registry<const bool>& correlations()
{
    static const Registry<const bool> r =
        namedSwitch("layer correlation", "needles", "independent");
    return r;
}

}  // namespace

void LayerModel::transmittancesAlong(const TracedBough& b, const Vec3& o, const Vec3& d,
                                     const std::vector<LayerHit>& hits, const Vec3& towardsLight,
                                     std::vector<double>& out) const
{
    out.resize(hits.size());
    for (std::size_t k = 0; k < hits.size(); ++k) {
        out[k] = transmittance(b, o + hits[k].t * d, towardsLight, hits[k].cone, -d);
    }
}

void LayerModel::transmittancesAt(const TracedBough& b, const Vec3& o, const Vec3& d, double,
                                  double, const std::vector<LayerHit>&,
                                  const std::vector<NeedleOnLine>& needles,
                                  const Vec3& towardsLight, std::vector<double>& out) const
{
    out.resize(needles.size());
    for (std::size_t k = 0; k < needles.size(); ++k) {
        out[k] = transmittance(b, o + needles[k].t * d, towardsLight, needles[k].cone, -d);
    }
}

const LayerModel& layerModel(const std::string& name, bool correlated)
{
    return registry(correlated).get(name);
}

bool layerCorrelated(const std::string& name) { return correlations().get(name); }

std::vector<std::string> layerModelNames() { return registry(true).names(); }

std::vector<std::string> layerCorrelationNames() { return correlations().names(); }

}  // namespace pine::vdbtrace
