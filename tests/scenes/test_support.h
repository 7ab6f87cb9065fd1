// Shared by the scenes tests: a complete scene to mutate, error capture and temporary folders.
#pragma once

#include "../support/temp_dir.h"

#include "pine/scenes/scene.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

namespace pine::scenes::test {

using nlohmann::json;

/// The shipped scenes, read where they live.
inline std::filesystem::path scenesDir() { return PINE_SCENES_DIR; }

/// A scene using every section, each value different from its default, so that a test can see
/// each one arrive.
inline json fullScene()
{
    return json::parse(R"({
  "name": "full",
  "camera": {"position": [1, -400, 120], "look_at": [1, 0, 90], "up": [0, 0, 2],
             "fov_deg": 30, "resolution": [320, 240]},
  "lights": [
    {"type": "point", "position": [10, 20, 300], "colour": [1, 0.5, 0.25], "intensity": 900},
    {"type": "directional", "direction": [0, 0, 5], "colour": [0.5, 0.5, 1], "irradiance": 2}
  ],
  "ground": {"type": "hill", "height": -10, "peak": 200, "radius": 300, "centre": [50, -20],
             "albedo": [0.2, 0.3, 0.1]},
  "species": {
    "fir": {
      "lsystem": {"axiom": "A", "rules": {"A": "F [&B] / [&B] / [&B] ! A", "B": "F B"},
                  "iterations": 4, "branch_angle_deg": 70, "divergence_deg": 120,
                  "segment": 12, "trunk_radius": 2, "length_decay": 0.9,
                  "radius_decay": 0.8, "branch_radius_ratio": 0.25, "jitter_deg": 3},
      "needles": {
        "base": {"aperture_deg": 22.5, "length": 4.25, "radius": 0.05, "per_cone": 12,
                 "cone_spacing": 0.9},
        "tip": {"aperture_deg": 30, "length": 3}
      },
      "bark_albedo": 0.15, "needle_albedo": 0.4, "needle_specular": 0.2,
      "specular_exponent": 80
    }
  },
  "trees": [
    {"species": "fir", "position": [0, 0, 5], "height": 150, "rotation_deg": 90, "seed": 42},
    {"species": "fir", "position": [100, 50]},
    {"scatter": {"species": "fir", "count": 5, "region": [[-500, -500], [500, 500]],
                 "height": [80, 120], "min_spacing": 50, "seed": 9}}
  ],
  "effects": ["diffuse", "specular", "shadows", "self_shadowing"],
  "render": {"background": [0.1, 0.2, 0.3], "needle_level_max": 0.5, "cone_level_max": 2}
})");
}

/// The message parseScene throws for `text`, or "" when it throws nothing.
inline std::string errorOfText(const std::string& text,
                               const std::string& name = "test.json")
{
    try {
        parseScene(text, name);
    } catch (const SceneError& e) {
        return e.what();
    }
    return "";
}
inline std::string errorOf(const json& j) { return errorOfText(j.dump(2)); }

/// A fresh folder per test (tests/support/temp_dir.h), named for this suite.
class TempDir : public pine::test::TempDir {
public:
    TempDir() : pine::test::TempDir("pine-scenes-test") {}
};

}  // namespace pine::scenes::test
