// Scene files: loadScene / parseScene and the small sections (camera, lights, ground, effects,
// render). Keys, units, defaults and valid ranges: docs/scene-format.md.
#include "scene_sections.h"

#include "pine/support/atomic_file.h"

#include <glm/geometric.hpp>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <numbers>
#include <sstream>

namespace pine::scenes {
namespace {

using detail::Json;
using detail::ObjectReader;
using detail::Range;
using detail::Where;

constexpr double kRadPerDeg = std::numbers::pi / 180.0;
constexpr long long kMaxResolution = 16384;
const Vec3 kWhite{1.0};

Camera readCamera(const Json& value, const Where& where)
{
    ObjectReader r(value, where);
    Camera c;
    c.position_cm = r.vec3("position");
    c.lookAt_cm = r.vec3("look_at");
    if (const Json* up = r.optional("up")) c.up = detail::readDirection(*up, where.key("up"));
    c.fovY_rad = kRadPerDeg * r.number("fov_deg", Range::open(0, 180), c.fovY_rad / kRadPerDeg);
    if (const CameraFault fault = cameraFault(c)) where.key(fault.key).fail(fault.why);
    if (const Json* resolution = r.optional("resolution")) {
        const Where at = where.key("resolution");
        if (!resolution->is_array() || resolution->size() != 2) {
            at.fail("must be [width, height] in pixels");
        }
        c.width = static_cast<int>(detail::readInteger((*resolution)[0], at.index(0), 1,
                                                       kMaxResolution));
        c.height = static_cast<int>(detail::readInteger((*resolution)[1], at.index(1), 1,
                                                        kMaxResolution));
    }
    r.finish();
    return c;
}

constexpr long long kMaxFrame = 9999999;
constexpr long long kMaxFrames = CameraPath::kMaxFrames;

// "camera_path": keys that each change what they name of the camera before them (the first
// key, of the still camera), the frames to render and how to interpolate.
CameraPath readCameraPath(const Json& value, const Where& where, const Camera& still)
{
    ObjectReader r(value, where);
    CameraPath path;
    const Json& keys = r.required("keys");
    const Where keysAt = where.key("keys");
    if (!keys.is_array() || keys.empty()) keysAt.fail("must be an array of at least one key");
    CameraKey last{0.0, still.position_cm, still.lookAt_cm, still.up, still.fovY_rad};
    for (std::size_t i = 0; i < keys.size(); ++i) {
        ObjectReader k(keys[i], keysAt.index(i));
        CameraKey key = last;
        key.frame = k.number("frame", Range::closed(0.0, double(kMaxFrame)));
        if (i > 0 && !(key.frame > last.frame)) {
            k.where().key("frame").fail("must exceed the previous key's (" +
                                        detail::formatNumber(last.frame) + ")");
        }
        if (k.has("position")) key.position_cm = k.vec3("position");
        if (k.has("look_at")) key.lookAt_cm = k.vec3("look_at");
        if (const Json* up = k.optional("up")) {
            key.up = detail::readDirection(*up, k.where().key("up"));
        }
        key.fovY_rad =
            kRadPerDeg * k.number("fov_deg", Range::open(0, 180), key.fovY_rad / kRadPerDeg);
        k.finish();
        path.keys.push_back(key);
        last = key;
    }
    if (const Json* frames = r.optional("frames")) {
        const Where at = where.key("frames");
        if (!frames->is_array() || frames->size() != 2) {
            at.fail("must be [first, last], frame numbers");
        }
        path.firstFrame = int(detail::readInteger((*frames)[0], at.index(0), 0, kMaxFrame));
        path.lastFrame =
            int(detail::readInteger((*frames)[1], at.index(1), path.firstFrame, kMaxFrame));
    } else {
        path.firstFrame = int(std::ceil(path.keys.front().frame));
        path.lastFrame = std::max(path.firstFrame, int(std::floor(path.keys.back().frame)));
    }
    if (path.frameCount() > kMaxFrames) {
        where.key("frames").fail(std::to_string(path.frameCount()) + " frames, more than " +
                                 std::to_string(kMaxFrames));
    }
    // Written as a float in each frame's header: 1e-320 read as 0 there, 1e308 as inf.
    path.framesPerSecond = r.number("fps", Range::closed(1e-3, 1e6), path.framesPerSecond);
    const std::string interpolation = r.string("interpolation", "smooth");
    if (interpolation == "linear") {
        path.interpolation = CameraPath::Interpolation::Linear;
    } else if (interpolation != "smooth") {
        where.key("interpolation")
            .fail("must be \"smooth\" or \"linear\" (is \"" + interpolation + "\")");
    }
    r.finish();
    // Every frame it renders is a camera that can render: a smooth curve may overshoot its keys.
    for (int f = path.firstFrame; f <= path.lastFrame; ++f) {
        const std::string problem = cameraProblem(path.at(f, still));
        if (!problem.empty()) where.fail("at frame " + std::to_string(f) + ", " + problem);
    }
    return path;
}

// A light's colour times its strength, within kMaxLightValue.
void checkLightValue(const ObjectReader& r, const Vec3& colour, double strength,
                     const std::string& key)
{
    const double channel = std::max({colour.x, colour.y, colour.z});
    if (!(channel * strength <= kMaxLightValue)) {
        r.where().key(key).fail(detail::formatNumber(strength) + " times the colour (its largest " +
                                "channel " + detail::formatNumber(channel) +
                                ") is more than float radiance can hold (at most " +
                                detail::formatNumber(kMaxLightValue) + " in all)");
    }
}

void readLights(const Json& value, const Where& where, Scene& scene)
{
    if (!value.is_array() || value.empty()) where.fail("must be an array of at least one light");
    for (std::size_t i = 0; i < value.size(); ++i) {
        ObjectReader r(value[i], where.index(i));
        const std::string type = r.string("type");
        if (type == "point") {
            PointLight l;
            l.position_cm = r.vec3("position");
            l.colour = r.colour("colour", Range::atLeast(0), kWhite);
            l.intensity = r.number("intensity", Range::atLeast(0), l.intensity);
            checkLightValue(r, l.colour, l.intensity, "intensity");
            scene.pointLights.push_back(l);
        } else if (type == "directional") {
            DirectionalLight l;
            l.towardsLight = detail::readDirection(r.required("direction"),
                                                   r.where().key("direction"));
            l.colour = r.colour("colour", Range::atLeast(0), kWhite);
            l.irradiance = r.number("irradiance", Range::atLeast(0), l.irradiance);
            checkLightValue(r, l.colour, l.irradiance, "irradiance");
            scene.directionalLights.push_back(l);
        } else {
            r.where().key("type").fail("must be \"point\" or \"directional\" (is \"" + type +
                                       "\")");
        }
        r.finish();
    }
}

Ground readGround(const Json& value, const Where& where)
{
    ObjectReader r(value, where);
    Ground g;
    const std::string type = r.string("type");
    if (type == "none") {
        g.kind = Ground::Kind::None;
    } else if (type == "plane") {
        g.kind = Ground::Kind::Plane;
    } else if (type == "hill") {
        g.kind = Ground::Kind::Hill;
    } else {
        where.key("type").fail("must be \"plane\", \"hill\" or \"none\" (is \"" + type + "\")");
    }
    g.height_cm = r.number("height", Range::any(), g.height_cm);
    if (g.kind == Ground::Kind::Hill) {
        g.hillPeak_cm = r.number("peak", Range::any());
        g.hillRadius_cm = r.number("radius", Range::above(0));
        if (const Json* centre = r.optional("centre")) {
            g.hillCentre_cm = detail::readVec2(*centre, where.key("centre"));
        }
    }
    // No ground, no surface to colour: "albedo" is then a key nobody reads.
    if (g.kind != Ground::Kind::None) g.albedo = r.colour("albedo", Range::closed(0, 1), g.albedo);
    r.finish();
    return g;
}

Effects readEffects(const Json& value, const Where& where)
{
    if (!value.is_array()) where.fail("must be an array of effect names");
    Effects e;
    e.diffuse = false;  // a list names every effect wanted; nothing else is computed
    for (std::size_t i = 0; i < value.size(); ++i) {
        const std::string name = detail::readString(value[i], where.index(i));
        bool* flag = name == "diffuse"          ? &e.diffuse
                     : name == "specular"       ? &e.specular
                     : name == "shadows"        ? &e.shadows
                     : name == "self_shadowing" ? &e.selfShadowing
                                                : nullptr;
        if (!flag) {
            where.index(i).fail("unknown effect \"" + name +
                                "\" (known: diffuse, specular, shadows, self_shadowing)");
        }
        if (*flag) where.index(i).fail("effect \"" + name + "\" named twice");
        *flag = true;
    }
    return e;
}

RenderSettings readRender(const Json& value, const Where& where)
{
    ObjectReader r(value, where);
    RenderSettings s;
    s.background = r.colour("background", Range::closed(0, kMaxLightValue), s.background);
    const std::string preset = r.string("preset", "faithful");
    if (preset == "paper") {
        s.model = ModelChoices::paper();
    } else if (preset != "faithful") {
        where.key("preset").fail("must be \"faithful\" or \"paper\"");
    }
    s.model.boughLaw = r.string("bough_law", s.model.boughLaw);
    s.model.layerModel = r.string("layer_model", s.model.layerModel);
    s.model.extinctionLaw = r.string("extinction_law", s.model.extinctionLaw);
    s.model.shadowOrigin = r.string("shadow_origin", s.model.shadowOrigin);
    s.model.bark = r.string("bark", s.model.bark);
    s.model.layerCorrelation = r.string("layer_correlation", s.model.layerCorrelation);
    s.model.needleEnds = r.string("needle_ends", s.model.needleEnds);
    s.model.pixelSplitQ = r.number("pixel_split_q", Range::atLeast(0), s.model.pixelSplitQ);
    s.model.occluderProfile = r.string("occluder_profile", s.model.occluderProfile);
    s.needleLevelMax = r.number("needle_level_max", Range::above(0), s.needleLevelMax);
    s.model.coneLevelMax = r.number("cone_level_max", Range::above(0), s.model.coneLevelMax);
    if (!(s.model.coneLevelMax > s.needleLevelMax)) {
        where.key("cone_level_max").fail("must exceed needle_level_max (" +
                                         detail::formatNumber(s.needleLevelMax) + ")");
    }
    // The two bands must not overlap: a bough is mixed from two levels at most. Thresholds
    // closer than the default band allows narrow it.
    const double widest = s.widestLevelBlend();
    s.model.levelBlend = r.number("level_blend", Range::atLeast(1),
                                  std::min(s.model.levelBlend, widest));
    if (s.model.levelBlend > widest) {
        where.key("level_blend").fail("must be at most sqrt(cone_level_max / needle_level_max) (" +
                                      detail::formatNumber(widest) + ")");
    }
    r.finish();
    return s;
}

}  // namespace

Scene parseScene(const std::string& json, const std::filesystem::path& name)
{
    const std::string file = name.string();
    const Json document = detail::parseJsonDocument(json, file);
    const Where top{&file, ""};
    ObjectReader r(document, top);

    Scene scene;
    scene.source = name;
    scene.name = r.string("name", name.stem().string());
    scene.camera = readCamera(r.required("camera"), top.key("camera"));
    if (const Json* path = r.optional("camera_path")) {
        scene.cameraPath = readCameraPath(*path, top.key("camera_path"), scene.camera);
    }
    readLights(r.required("lights"), top.key("lights"), scene);
    if (const Json* ground = r.optional("ground")) {
        scene.ground = readGround(*ground, top.key("ground"));
    }
    if (const Json* species = r.optional("species")) {
        ObjectReader s(*species, top.key("species"));
        for (const auto& [speciesName, value] : species->items()) {
            if (speciesName == "comment") continue;
            if (speciesName.empty()) s.where().key(speciesName).fail("a species needs a name");
            scene.species.emplace(speciesName,
                                  detail::readSpecies(*s.optional(speciesName),
                                                      s.where().key(speciesName)));
        }
        s.finish();
    }
    // After species and ground: placements name the one and stand on the other.
    scene.trees = detail::readTrees(r.required("trees"), top.key("trees"), scene);
    if (const Json* effects = r.optional("effects")) {
        scene.effects = readEffects(*effects, top.key("effects"));
    }
    if (const Json* render = r.optional("render")) {
        scene.render = readRender(*render, top.key("render"));
    }
    r.finish();
    return scene;
}

Scene loadScene(const std::filesystem::path& file)
{
    if (const std::string why = io::whyUnreadable(file); !why.empty()) {
        throw SceneError(file.string() + ": cannot open: " + why);
    }
    std::ifstream in(file, std::ios::binary);
    if (!in) throw SceneError(file.string() + ": cannot open: permission denied or unreadable");
    std::ostringstream text;
    text << in.rdbuf();
    if (in.bad()) throw SceneError(file.string() + ": cannot read");
    return parseScene(text.str(), file);
}

}  // namespace pine::scenes
