// `vdbtrace bench --grow`: a scene grown along one axis, step by step, to measure how each
// method's time and memory grow with the forest (issue: "a scaling mode that grows the forest
// for both methods, with the growth exponents"). The scene is grown as its JSON document, so
// that each step is a scene file a user can render on its own.
#pragma once

#include <nlohmann/json.hpp>

#include <string>
#include <vector>

namespace pine::vdbtrace {

enum class GrowthAxis {
    TreesInRegion,   ///< "trees-region": each scatter's count x f in its own region
    TreesAtDensity,  ///< "trees-density": each scatter's count and region area x f
    Resolution,      ///< "resolution": the camera's pixels x f (each side x sqrt f)
    NeedleDensity,   ///< "needles": every species' cone spacing dh / f (needles per cm x f)
};

/// The axes' names, as `--grow` takes them, in the enum's order.
std::vector<std::string> growthAxisNames();

/// The axis named `name`. @throw InputError for an unknown name.
GrowthAxis growthAxis(const std::string& name);

/// `scene` (a scene file's document) grown by `factor` (> 0) along `axis`:
/// - trees-region: every scatter's count x factor (rounded, at least 1) and its min_spacing
///   / sqrt(factor), so that the denser forest still fits;
/// - trees-density: every scatter's count x factor and its region scaled by sqrt(factor) about
///   the region's point nearest the camera, so the forest grows away from the camera at the
///   same density;
/// - resolution: width and height x sqrt(factor), rounded;
/// - needles: every species' cone spacing (base, and tip where given) / factor.
/// Explicit tree placements are kept as they are. @throw InputError if a trees axis finds no
/// scatter, or the document lacks what the axis grows (a camera's resolution).
nlohmann::json growScene(const nlohmann::json& scene, GrowthAxis axis, double factor);

/// The exponent e of y ~ x^e: the least-squares slope of log y against log x. NaN with fewer
/// than two points or a non-positive value.
double growthExponent(const std::vector<double>& x, const std::vector<double>& y);

}  // namespace pine::vdbtrace
