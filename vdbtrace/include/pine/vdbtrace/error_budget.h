// The error budget (issue 10): what each approximation costs in accuracy and saves in time.
// Every alternative of every model choice (scenes::ModelChoices: the paper's and any other
// registered one) switched alone from the scene's choice, and every choice the paper's at
// once; `vdbtrace compare` renders each and sets it against the scene's own render.
#pragma once

#include "pine/scenes/scene.h"

#include <string>
#include <vector>

namespace pine::vdbtrace {

struct BudgetSwitch {
    std::string label;   ///< what is switched, as the scene's render keys: "bough_law=linear"
    std::string method;  ///< the method the choice changes: "multiscale" or "reference"
    bool paper = false;  ///< the paper's choice (else another alternative, or all of them)
    scenes::ModelChoices model;  ///< the scene's choices with this one switched
};

/// Each alternative of each choice that differs from `scene`'s, one at a time, in the order
/// of ModelChoices' members; then "preset=paper" (every multiscale choice the paper's) unless
/// `scene` is already the paper's.
std::vector<BudgetSwitch> errorBudgetSwitches(const scenes::ModelChoices& scene);

}  // namespace pine::vdbtrace
