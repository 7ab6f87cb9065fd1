// The registry of layer models: to add one, write its type in a file of its own (as
// fibre_layer_model.cpp), declare its factory here and add it to the table.
#include "pine/vdbtrace/layer_model.h"

#include "pine/support/registry.h"

namespace pine::vdbtrace {

std::unique_ptr<LayerModel> makeFibreLayerModel();
std::unique_ptr<LayerModel> makePaperLayerModel();

namespace {

const Registry<LayerModel>& registry()
{
    static const Registry<LayerModel> models = [] {
        Registry<LayerModel> r("layer model");
        r.add("fibre", makeFibreLayerModel());  // the needles' own statistics (faithful)
        r.add("paper", makePaperLayerModel());  // constant A whatever the crossing (sec. 3.3)
        return r;
    }();
    return models;
}

}  // namespace

const LayerModel& layerModel(const std::string& name) { return registry().get(name); }

std::vector<std::string> layerModelNames() { return registry().names(); }

}  // namespace pine::vdbtrace
