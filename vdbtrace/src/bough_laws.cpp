// The registry of bough laws: to add one, write its type in a file of its own (as
// linear_bough_law.cpp), declare its factory here and add a row to the table.
#include "pine/vdbtrace/bough_law.h"

#include <stdexcept>
#include <utility>

namespace pine::vdbtrace {

std::unique_ptr<BoughLaw> makeLinearBoughLaw();

namespace {

struct Registered {
    std::string name;
    std::unique_ptr<BoughLaw> law;
};

const std::vector<Registered>& registry()
{
    static const std::vector<Registered> laws = [] {
        std::vector<Registered> r;
        r.push_back({"linear", makeLinearBoughLaw()});  // section 6.6, clamped (the default)
        return r;
    }();
    return laws;
}

}  // namespace

const BoughLaw& boughLaw(const std::string& name)
{
    std::string known;
    for (const Registered& r : registry()) {
        if (r.name == name) return *r.law;
        known += (known.empty() ? "" : ", ") + r.name;
    }
    throw std::invalid_argument("unknown bough law '" + name + "' (known: " + known + ")");
}

std::vector<std::string> boughLawNames()
{
    std::vector<std::string> names;
    for (const Registered& r : registry()) names.push_back(r.name);
    return names;
}

}  // namespace pine::vdbtrace
