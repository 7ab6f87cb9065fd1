#include "pine/vdbtrace/error_budget.h"

#include "pine/bake/extinction_law.h"
#include "pine/vdbtrace/bough_law.h"
#include "pine/vdbtrace/layer_model.h"
#include "pine/vdbtrace/traced_scene.h"

#include <functional>
#include <sstream>

namespace pine::vdbtrace {
namespace {

using scenes::ModelChoices;

// A choice among registered names: its render key, the method that reads it, the names and
// the member.
struct NamedChoice {
    const char* key;
    const char* method;
    std::vector<std::string> (*names)();
    std::string ModelChoices::*member;
};

// A number: only the paper's value is an alternative.
struct NumberChoice {
    const char* key;
    double ModelChoices::*member;
};

std::string number(double v)
{
    std::ostringstream s;
    s << v;
    return s.str();
}

}  // namespace

std::vector<BudgetSwitch> errorBudgetSwitches(const ModelChoices& scene)
{
    const ModelChoices paper = ModelChoices::paper();
    const NamedChoice named[] = {
        {"bough_law", "multiscale", boughLawNames, &ModelChoices::boughLaw},
        {"layer_model", "multiscale", layerModelNames, &ModelChoices::layerModel},
        {"extinction_law", "reference", bake::extinctionLawNames, &ModelChoices::extinctionLaw},
        {"shadow_origin", "multiscale", shadowOriginNames, &ModelChoices::shadowOrigin},
        {"bark", "multiscale", barkNames, &ModelChoices::bark},
        {"layer_correlation", "multiscale", layerCorrelationNames, &ModelChoices::layerCorrelation},
        {"occluder_profile", "multiscale", occluderProfileNames, &ModelChoices::occluderProfile},
    };
    const NumberChoice numbers[] = {{"level_blend", &ModelChoices::levelBlend},
                                    {"cone_level_max", &ModelChoices::coneLevelMax},
                                    {"pixel_split_q", &ModelChoices::pixelSplitQ}};
    std::vector<BudgetSwitch> out;
    for (const NamedChoice& c : named) {
        for (const std::string& name : c.names()) {
            if (name == scene.*c.member) continue;
            BudgetSwitch s{std::string(c.key) + "=" + name, c.method, name == paper.*c.member,
                           scene};
            s.model.*c.member = name;
            out.push_back(s);
        }
    }
    for (const NumberChoice& c : numbers) {
        if (scene.*c.member == paper.*c.member) continue;
        BudgetSwitch s{std::string(c.key) + "=" + number(paper.*c.member), "multiscale", true,
                       scene};
        s.model.*c.member = paper.*c.member;
        out.push_back(s);
    }
    ModelChoices all = paper;
    all.extinctionLaw = scene.extinctionLaw;  // the reference's, not multiscale's
    bool differs = false;
    for (const NamedChoice& c : named) {
        differs |= std::string(c.method) == "multiscale" && all.*c.member != scene.*c.member;
    }
    for (const NumberChoice& c : numbers) differs |= all.*c.member != scene.*c.member;
    if (differs) out.push_back({"preset=paper", "multiscale", true, all});
    return out;
}

}  // namespace pine::vdbtrace
