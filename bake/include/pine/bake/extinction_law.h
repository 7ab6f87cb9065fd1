// How the baked layer field stops light: the extinction sigma(d) of a voxel for a ray along
// unit d (or, for a banded law, the rate of needles met), and its mean over directions (what
// `density` holds). A law is a type registered by
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
    /// True when sigma is a rate of needles met, evenly spaced within each layer: a line is
    /// then stopped by each band of one layer with probability min(1, needles met there)
    /// rather than exp(-integral of sigma) (vdbtrace's layer_bands.h); false for an
    /// extinction.
    virtual bool banded() const { return false; }
};

/// The law registered as `name`; throws InputError naming the registered ones.
const ExtinctionLaw& extinctionLaw(const std::string& name);
/// The registered names, in registration order (the first is the default).
std::vector<std::string> extinctionLawNames();

}  // namespace pine::bake
