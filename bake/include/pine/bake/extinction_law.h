// How the baked layer field stops light: the extinction sigma(d) of a voxel for a ray along
// unit d, and its mean over directions (what `density` holds). A law is a type registered by
// name in src/extinction_laws.cpp; bake writes its name into every file (pine:extinction_law)
// and the reference method integrates the grids with the law they were baked with.
#pragma once

#include "pine/bake/layer_field.h"

#include <string>
#include <vector>

namespace pine::bake {

class ExtinctionLaw {
public:
    virtual ~ExtinctionLaw() = default;
    /// The law as a formula of the grids, for a person reading the file (pine:extinction).
    virtual std::string formula() const = 0;
    /// sigma(d), per cm, at a point of the field for a unit direction d.
    virtual double extinction(const LayerSample& field, const Vec3& d) const = 0;
    /// The mean of sigma over all directions, per cm: the isotropic density.
    virtual double meanExtinction(const LayerSample& field) const = 0;
};

/// The law registered as `name`; throws InputError naming the registered ones.
const ExtinctionLaw& extinctionLaw(const std::string& name);
/// The registered names, in registration order (the first is the default).
std::vector<std::string> extinctionLawNames();

}  // namespace pine::bake
