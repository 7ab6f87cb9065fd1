// A scene: camera, lights, ground, trees and what to compute (docs/scene-format.md).
// World space is right-handed, z up; lengths in cm (the paper's unit), angles in degrees in the
// file and radians in memory.
#pragma once

#include "pine/support/input_error.h"

#include "pine/scenes/camera.h"
#include "pine/scenes/species.h"

#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

#include <cmath>
#include <filesystem>
#include <map>
#include <stdexcept>
#include <string>
#include <vector>

namespace pine::scenes {

using Vec2 = glm::dvec2;

/// A scene file that cannot be used: the message is one line naming file, key and, where the
/// parser gives it, line:column ("scenes/x.json:12:7: camera.fov_deg: must be in (0, 180)").
/// Its bytes that are not text (a key's newline, a string's NUL) are shown as \\xNN
/// (pine::printable): a NUL passed through what() would end the message there.
class SceneError : public InputError {
public:
    explicit SceneError(const std::string& message) : InputError(printable(message)) {}
};

/// The most a light's colour times its irradiance (or intensity) may be, and the background's
/// colour: radiance is written as float (at most 3.4e38), and a pixel sums several lights'
/// reflections; a brighter light would overflow only after the render.
inline constexpr double kMaxLightValue = 1e30;

struct PointLight {
    Vec3 position_cm{0.0};
    Vec3 colour{1.0};
    double intensity = 1.0;  ///< radiant intensity: irradiance at distance d is intensity / d^2
};

struct DirectionalLight {
    Vec3 towardsLight{0.0, 0.0, 1.0};  ///< unit
    Vec3 colour{1.0};
    double irradiance = 1.0;  ///< on a surface facing the light
};

struct Ground {
    enum class Kind { None, Plane, Hill };
    Kind kind = Kind::Plane;
    double height_cm = 0.0;  ///< plane height; the hill's base height
    // Hill: z = height + peak * exp(-|xy - centre|^2 / (2 radius^2)).
    double hillPeak_cm = 0.0;
    double hillRadius_cm = 1.0;
    Vec2 hillCentre_cm{0.0};
    Vec3 albedo{0.3, 0.25, 0.2};
    /// Height of the ground under (x, y).
    double heightAt(double x_cm, double y_cm) const;
};

/// What the scene asks the tracer to compute; nothing else is computed (DESIGN.md).
struct Effects {
    bool diffuse = true;
    bool specular = false;
    bool shadows = false;        ///< shadows cast by trees on each other and on the ground
    bool selfShadowing = false;  ///< shadowing inside a bough (the paper's section 6 terms)
};

/// A tree: species, placement and the seed of its L-system.
struct TreePlacement {
    std::string species;
    Vec3 base_cm{0.0};     ///< where the trunk meets the ground (z set on the ground if absent)
    double height_cm = 0;  ///< scale the grown tree to this height; 0 keeps the species' own
    double rotation_rad = 0;  ///< about z
    unsigned seed = 1;
    /// Index (in Scene::trees) of an earlier placement this tree is a copy of, moved to its own
    /// base: a scatter's "variants" (same species, seed, height and rotation). -1: its own tree.
    long long variantOf = -1;
};

/// The model of each approximation the paper makes (docs/models.md), by name: vdbtrace and
/// bake look each up in their registries, which refuse an unknown one.
struct ModelChoices {
    std::string boughLaw = "exact";       ///< level 3's law: "exact" or "linear" (sec. 6.6)
    std::string layerModel = "fibre";     ///< a layer's opacity: "fibre" or "paper" (const. A)
    std::string extinctionLaw = "fibre";  ///< the reference's field: "fibre" or "layer"
    /// Where a bough hit's shadow cone stands for: "needles" (where the needles it shows lie)
    /// or "axis" (one line from the chord's middle, section 7's shadow ray per bough).
    std::string shadowOrigin = "needles";
    /// Within q in [t / levelBlend, t levelBlend] about each level threshold t a bough is
    /// shaded at both levels and the two mixed (smoothstep in log q); 1: the paper's switch.
    double levelBlend = 1.5;
    /// The branch a bough's needles grow from: "solid" (a cylinder of the segment's radius,
    /// inside which the needles' roots are hidden) or "line" (the bough's axis, section 3.1).
    std::string bark = "solid";
    /// Level 3 (the bough a volume) from q = footprint / dh at least this; level 2 below it
    /// (down to RenderSettings::needleLevelMax). The paper's 1 for both presets: in a forest
    /// level 2 agrees with the needles where level 3 does not, but beyond q ~ 1.4 one line a
    /// pixel through the layers aliases (docs/models.md "Level threshold").
    double coneLevelMax = 1.0;
    /// Self-shadowing through the fibre layers: "needles" (the lines of the view and of the
    /// light through one cone meet its same evenly spaced needles: the hot spot) or
    /// "independent" (every crossing on its own, section 6).
    std::string layerCorrelation = "needles";
    /// The explicit needles' ends (the geometry method's ground truth): "open" (a needle is
    /// its side, as section 4 shades it and every level models it) or "flat" (a solid
    /// cylinder whose end discs reflect and stop light: the ground truth until 2026-12-07,
    /// kept by the paper preset so that its published images stay reproducible).
    std::string needleEnds = "open";
    /// The multiscale method's cones per pixel: a pixel whose cone shows a bough at q =
    /// footprint / dh above this (where it shows none, whose corners do) is traced again as
    /// k x k cones, each 1/k as wide, k = ceil(q / pixelSplitQ) up to
    /// kMaxPixelSplit, so that the boughs are shaded and composited at footprints of about
    /// this many cone spacings, up to kMaxPixelSplit times finer than the pixel's. 0: one cone
    /// a pixel, the paper's (section 3.2).
    double pixelSplitQ = 0.5;
    static constexpr int kMaxPixelSplit = 4;
    /// A bough's opacity seen from a light along its axis, where its law's strip runs to the
    /// cones' end (exact, corrected): "cones" (where its cones' needles reach: a chain's
    /// neighbours overlap as one long bough) or "even" (the strip's mean all along, section
    /// 7's one shadow ray through the bough's volume).
    std::string occluderProfile = "cones";
    /// Every choice as the paper prints it (preset "paper"): today's published behaviour.
    static ModelChoices paper()
    {
        return {"linear", "paper",       "layer", "axis", 1.0,   "line",
                1.0,      "independent", "flat",  0.0,    "even"};
    }
    /// The choices that agree with the explicit needles (preset "faithful", the default).
    static ModelChoices faithful() { return {}; }
};

struct RenderSettings {
    Vec3 background{0.55, 0.7, 0.9};
    /// preset, then bough_law, layer_model, extinction_law, shadow_origin, level_blend, bark,
    /// cone_level_max, layer_correlation, needle_ends, pixel_split_q, occluder_profile
    ModelChoices model;
    /// Level thresholds on q = footprint width / cone spacing dh at the hit (the paper chooses
    /// dh = 2 pi R / N, the gap between needle tips, so dh is also the needles' spacing):
    /// q < needleLevelMax: level 1, needles resolved; q < model.coneLevelMax: level 2, each
    /// cone a semi-opaque surface; otherwise level 3, the bough a volume.
    double needleLevelMax = 0.25;

    /// The widest model.levelBlend that keeps the bands about the two thresholds apart, so
    /// that a bough is mixed from two levels at most: sqrt(coneLevelMax / needleLevelMax).
    double widestLevelBlend() const { return std::sqrt(model.coneLevelMax / needleLevelMax); }
};

struct Scene {
    std::filesystem::path source;  ///< the file it came from (for messages and metadata)
    std::string name;
    Camera camera;
    CameraPath cameraPath;  ///< empty: the camera stands still
    std::vector<PointLight> pointLights;
    std::vector<DirectionalLight> directionalLights;
    Ground ground;
    std::map<std::string, Species> species;
    std::vector<TreePlacement> trees;  ///< explicit placements and scattered ones, expanded
    Effects effects;
    RenderSettings render;
};

/// Reads and validates a scene file. Throws SceneError (one line, see above) on malformed JSON,
/// a key nobody reads, a missing or non-finite value, a negative size, an unknown species.
Scene loadScene(const std::filesystem::path& file);

/// The same from text (for tests); `name` stands for the file in messages.
Scene parseScene(const std::string& json, const std::filesystem::path& name);

}  // namespace pine::scenes
