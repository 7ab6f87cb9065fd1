// The small fir the tracer tests render: close enough (75 cm) that its footprint spans all
// three levels with the thresholds below, lit by a directional and a point light.
#pragma once

#include <nlohmann/json.hpp>

#include <string>

namespace pine::vdbtrace::test {

/// `effects`: the JSON list's contents, e.g. R"("diffuse", "shadows")".
inline std::string firScene(const std::string& effects, int width = 96, int height = 72)
{
    return R"({
  "name": "test fir",
  "camera": {"position": [0, -75, 50], "look_at": [0, 0, 40], "up": [0, 0, 1], "fov_deg": 45,
             "resolution": [)" + std::to_string(width) + ", " + std::to_string(height) + R"(]},
  "lights": [{"type": "directional", "direction": [0.5, -0.6, 0.8], "colour": [1, 1, 1], "irradiance": 3},
             {"type": "point", "position": [-80, -120, 150], "colour": [1, 0.9, 0.8], "intensity": 40000}],
  "ground": {"type": "plane", "height": 0, "albedo": [0.3, 0.25, 0.2]},
  "species": {"fir": {
     "lsystem": {"axiom": "A", "rules": {"A": "F[&B]/[&B]/[&B]/[&B]/[&B]!A", "B": "F[+C][-C]F[+C][-C]F", "C": "F"},
                 "iterations": 6, "branch_angle_deg": 60, "divergence_deg": 72, "segment": 8,
                 "trunk_radius": 2, "length_decay": 0.85, "radius_decay": 0.8, "jitter_deg": 5},
     "needles": {"base": {"aperture_deg": 22.5, "length": 4.25, "radius": 0.05, "per_cone": 12, "cone_spacing": 0.9},
                 "tip": {"aperture_deg": 30, "length": 3.5, "radius": 0.05, "per_cone": 12, "cone_spacing": 0.9}},
     "bark_albedo": 0.25, "needle_albedo": 0.3, "needle_specular": 0.2, "specular_exponent": 80}},
  "trees": [{"species": "fir", "position": [0, 0], "seed": 3}],
  "effects": [)" + effects + R"(],
  "render": {"needle_level_max": 0.8, "cone_level_max": 1.3}
})";
}

// Five firs drawn from two variants of a scatter: each variant grown once, its copies moved
// (the geometry method instances its needles at them; native curves only).
inline std::string variantForest()
{
    nlohmann::json j = nlohmann::json::parse(firScene(R"("diffuse", "shadows")", 96, 72));
    j["trees"] = nlohmann::json::array({{{"scatter",
                                          {{"species", "fir"},
                                           {"count", 5},
                                           {"region", {{-45, 0}, {45, 70}}},
                                           {"min_spacing", 25},
                                           {"variants", 2},
                                           {"seed", 4}}}}});
    return j.dump();
}

}  // namespace pine::vdbtrace::test
