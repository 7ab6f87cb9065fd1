// What the studies' command lines share (self_shadowing_study, bough_shadow_study): the
// direction towards their one directional light.
#pragma once

#include "pine/support/input_error.h"
#include "pine/vdbtrace/geometry.h"

#include <CLI/CLI.hpp>
#include <glm/geometric.hpp>

#include <cmath>
#include <vector>

namespace pine::study {

/// Adds --light X Y Z to `app`, its default what `xyz` holds.
inline void addLightOption(CLI::App& app, std::vector<double>& xyz)
{
    app.add_option("--light", xyz, "Towards the directional light, X Y Z (camera along +y)")
        ->expected(3)
        ->capture_default_str();
}

/// The unit direction `xyz` names; throws InputError unless it is finite and not zero.
inline vdbtrace::Vec3 lightDirection(const std::vector<double>& xyz)
{
    const vdbtrace::Vec3 v(xyz.at(0), xyz.at(1), xyz.at(2));
    const double length = glm::length(v);
    if (!(length > 0.0) || !std::isfinite(length)) {
        throw InputError("--light: the direction must be finite and not zero");
    }
    return v / length;
}

}  // namespace pine::study
