// The registry of bough laws: to add one, write its type in a file of its own (as
// linear_bough_law.cpp), declare its factory here and add it to the table.
#include "pine/vdbtrace/bough_law.h"

#include "pine/support/registry.h"

namespace pine::vdbtrace {

std::unique_ptr<BoughLaw> makeCorrectedBoughLaw();
std::unique_ptr<BoughLaw> makeLinearBoughLaw();

namespace {

const Registry<BoughLaw>& registry()
{
    static const Registry<BoughLaw> laws = [] {
        Registry<BoughLaw> r("bough law");
        r.add("exact", makeExactBoughLaw());    // the layers crossed, chord by chord (faithful)
        r.add("linear", makeLinearBoughLaw());  // section 6.6, clamped (the paper's)
        r.add("corrected", makeCorrectedBoughLaw());  // the exact law, tabulated
        return r;
    }();
    return laws;
}

}  // namespace

const BoughLaw& boughLaw(const std::string& name) { return registry().get(name); }

std::vector<std::string> boughLawNames() { return registry().names(); }

}  // namespace pine::vdbtrace
