// The registry of extinction laws: to add one, write its type in a file of its own (as
// layer_extinction_law.cpp), declare its factory here and add a row to the table.
#include "pine/bake/extinction_law.h"
#include "pine/bake/tree_grids.h"

#include <memory>

namespace pine::bake {

std::unique_ptr<ExtinctionLaw> makeLayerExtinctionLaw();

namespace {

struct Registered {
    std::string name;
    std::unique_ptr<ExtinctionLaw> law;
};

const std::vector<Registered>& registry()
{
    static const std::vector<Registered> laws = [] {
        std::vector<Registered> r;
        r.push_back({"layer", makeLayerExtinctionLaw()});  // section 6's layers (the default)
        return r;
    }();
    return laws;
}

}  // namespace

const ExtinctionLaw& extinctionLaw(const std::string& name)
{
    std::string known;
    for (const Registered& r : registry()) {
        if (r.name == name) return *r.law;
        known += (known.empty() ? "" : ", ") + r.name;
    }
    throw BakeError("unknown extinction law '" + name + "' (known: " + known + ")");
}

std::vector<std::string> extinctionLawNames()
{
    std::vector<std::string> names;
    for (const Registered& r : registry()) names.push_back(r.name);
    return names;
}

}  // namespace pine::bake
