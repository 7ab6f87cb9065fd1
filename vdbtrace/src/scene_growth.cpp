#include "pine/vdbtrace/scene_growth.h"

#include "pine/scenes/species.h"
#include "pine/support/input_error.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace pine::vdbtrace {

namespace {

using Json = nlohmann::json;

const char* const kAxisNames[] = {"trees-region", "trees-density", "resolution", "needles"};

// Calls f on every scatter of the document's trees; throws if there is none.
template <typename F>
void forEachScatter(Json& scene, const std::string& axis, F&& f)
{
    int found = 0;
    if (scene.contains("trees") && scene["trees"].is_array()) {
        for (Json& entry : scene["trees"]) {
            if (entry.is_object() && entry.contains("scatter") && entry["scatter"].is_object()) {
                f(entry["scatter"]);
                ++found;
            }
        }
    }
    if (!found) {
        throw InputError("--grow " + axis +
                         ": the scene has no \"scatter\" in \"trees\" to grow (explicit "
                         "placements are kept as they are)");
    }
}

long long grownCount(const Json& scatter, double factor)
{
    const double count = scatter.contains("count") ? scatter["count"].get<double>() : 0.0;
    return std::max(1LL, std::llround(count * factor));
}

// The scatter's region scaled by s about its point nearest the camera's ground position.
void scaleRegion(Json& scatter, const Json& scene, double s)
{
    if (!scatter.contains("region")) return;  // the parser names the missing key
    Json& region = scatter["region"];
    const double x0 = region[0][0].get<double>(), y0 = region[0][1].get<double>();
    const double x1 = region[1][0].get<double>(), y1 = region[1][1].get<double>();
    double cx = 0.5 * (x0 + x1), cy = 0.5 * (y0 + y1);
    if (scene.contains("camera") && scene["camera"].contains("position")) {
        const Json& p = scene["camera"]["position"];
        cx = std::clamp(p[0].get<double>(), std::min(x0, x1), std::max(x0, x1));
        cy = std::clamp(p[1].get<double>(), std::min(y0, y1), std::max(y0, y1));
    }
    region = Json::array({Json::array({cx + s * (x0 - cx), cy + s * (y0 - cy)}),
                          Json::array({cx + s * (x1 - cx), cy + s * (y1 - cy)})});
}

}  // namespace

std::vector<std::string> growthAxisNames() { return {std::begin(kAxisNames), std::end(kAxisNames)}; }

GrowthAxis growthAxis(const std::string& name)
{
    for (int k = 0; k < 4; ++k) {
        if (name == kAxisNames[k]) return GrowthAxis(k);
    }
    throw InputError("--grow: unknown axis \"" + name +
                     "\" (known: trees-region, trees-density, resolution, needles)");
}

nlohmann::json growScene(const nlohmann::json& scene, GrowthAxis axis, double factor)
{
    if (!(factor > 0.0) || !std::isfinite(factor)) {
        throw InputError("--grow: the factor must be a positive number");
    }
    Json out = scene;
    const std::string name = kAxisNames[int(axis)];
    switch (axis) {
    case GrowthAxis::TreesInRegion:
        forEachScatter(out, name, [&](Json& scatter) {
            scatter["count"] = grownCount(scatter, factor);
            if (scatter.contains("min_spacing")) {
                scatter["min_spacing"] = scatter["min_spacing"].get<double>() / std::sqrt(factor);
            }
        });
        break;
    case GrowthAxis::TreesAtDensity:
        forEachScatter(out, name, [&](Json& scatter) {
            scatter["count"] = grownCount(scatter, factor);
            scaleRegion(scatter, scene, std::sqrt(factor));
        });
        break;
    case GrowthAxis::Resolution: {
        if (!out.contains("camera") || !out["camera"].contains("resolution")) {
            throw InputError("--grow resolution: the scene's camera has no \"resolution\"");
        }
        Json& r = out["camera"]["resolution"];
        for (int k = 0; k < 2; ++k) {
            r[k] = std::max(1LL, std::llround(r[k].get<double>() * std::sqrt(factor)));
        }
        break;
    }
    case GrowthAxis::NeedleDensity: {
        if (!out.contains("species")) break;  // no trees: nothing to grow
        const double fallback = scenes::Species{}.needlesAtBase.coneSpacing_cm;
        for (auto& [speciesName, species] : out["species"].items()) {
            if (!species.is_object()) continue;  // "comment"
            Json& needles = species["needles"];
            Json& base = needles["base"];
            base["cone_spacing"] =
                (base.contains("cone_spacing") ? base["cone_spacing"].get<double>() : fallback) /
                factor;
            // A tip without its own spacing takes the base's, already grown.
            if (needles.contains("tip") && needles["tip"].contains("cone_spacing")) {
                needles["tip"]["cone_spacing"] =
                    needles["tip"]["cone_spacing"].get<double>() / factor;
            }
        }
        break;
    }
    }
    return out;
}

double growthExponent(const std::vector<double>& x, const std::vector<double>& y)
{
    const std::size_t n = std::min(x.size(), y.size());
    if (n < 2) return std::numeric_limits<double>::quiet_NaN();
    double sx = 0.0, sy = 0.0, sxx = 0.0, sxy = 0.0;
    for (std::size_t k = 0; k < n; ++k) {
        if (!(x[k] > 0.0) || !(y[k] > 0.0)) return std::numeric_limits<double>::quiet_NaN();
        const double lx = std::log(x[k]), ly = std::log(y[k]);
        sx += lx;
        sy += ly;
        sxx += lx * lx;
        sxy += lx * ly;
    }
    const double denominator = double(n) * sxx - sx * sx;
    if (!(std::abs(denominator) > 0.0)) return std::numeric_limits<double>::quiet_NaN();
    return (double(n) * sxy - sx * sy) / denominator;
}

}  // namespace pine::vdbtrace
