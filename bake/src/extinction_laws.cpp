// The registry of extinction laws: to add one, write its type in a file of its own (as
// layer_extinction_law.cpp), declare its factory here and add it to the table.
#include "pine/bake/extinction_law.h"

#include "pine/support/registry.h"

namespace pine::bake {

std::unique_ptr<ExtinctionLaw> makeFibreExtinctionLaw();
std::unique_ptr<ExtinctionLaw> makeLayerExtinctionLaw();
std::unique_ptr<ExtinctionLaw> makePoissonExtinctionLaw();

namespace {

const Registry<ExtinctionLaw>& registry()
{
    static const Registry<ExtinctionLaw> laws = [] {
        Registry<ExtinctionLaw> r("extinction law");
        r.add("fibre", makeFibreExtinctionLaw());      // evenly spaced thin fibres (faithful)
        r.add("layer", makeLayerExtinctionLaw());      // section 6's layers (the paper's)
        r.add("poisson", makePoissonExtinctionLaw());  // fibres placed independently
        return r;
    }();
    return laws;
}

}  // namespace

const ExtinctionLaw& extinctionLaw(const std::string& name) { return registry().get(name); }

std::vector<std::string> extinctionLawNames() { return registry().names(); }

}  // namespace pine::bake
