// Camera paths: keys interpolated as docs/scene-format.md says, checked against independent
// formulas; every frame a path renders is a usable camera or the file is refused.
#include "test_support.h"

#include "pine/scenes/camera.h"
#include "pine/scenes/scene.h"

#include <gtest/gtest.h>
#include <glm/geometric.hpp>

#include <cmath>
#include <numbers>
#include <random>
#include <string>

namespace pine::scenes {
namespace {

using test::errorOf;
using test::json;

constexpr double kDeg = std::numbers::pi / 180.0;

json sceneWithPath(const json& path)
{
    json j = json::parse(R"({
      "camera": {"position": [0, -500, 100], "look_at": [0, 0, 100], "fov_deg": 40,
                 "resolution": [32, 24]},
      "lights": [{"type": "directional", "direction": [0, 0, 1]}],
      "trees": []
    })");
    j["camera_path"] = path;
    return j;
}

CameraPath randomPath(std::mt19937& rng, int keyCount, bool uniform)
{
    std::uniform_real_distribution<double> coord(-300.0, 300.0), gap(0.5, 7.0);
    CameraPath path;
    double frame = 3.0;
    for (int k = 0; k < keyCount; ++k) {
        CameraKey key;
        key.frame = frame;
        frame += uniform ? 4.0 : gap(rng);
        key.position_cm = {coord(rng), coord(rng), coord(rng)};
        key.lookAt_cm = {coord(rng), coord(rng), coord(rng)};
        key.up = glm::normalize(Vec3(coord(rng), coord(rng), 400.0));
        key.fovY_rad = (20.0 + 0.1 * (coord(rng) + 300.0)) * kDeg;
        path.keys.push_back(key);
    }
    return path;
}

TEST(CameraPath, PassesThroughEveryKeyAndHoldsBeyondTheEnds)
{
    std::mt19937 rng(7);
    const Camera still;
    for (const auto interpolation :
         {CameraPath::Interpolation::Smooth, CameraPath::Interpolation::Linear}) {
        CameraPath path = randomPath(rng, 5, false);
        path.interpolation = interpolation;
        for (const CameraKey& key : path.keys) {
            const Camera c = path.at(key.frame, still);
            EXPECT_LT(glm::length(c.position_cm - key.position_cm), 1e-9);
            EXPECT_LT(glm::length(c.lookAt_cm - key.lookAt_cm), 1e-9);
            EXPECT_NEAR(c.fovY_rad, key.fovY_rad, 1e-12);
        }
        for (const double f :
             {path.keys.front().frame - 3.0, 0.5 * (path.keys[1].frame + path.keys[2].frame),
              path.keys.back().frame + 3.0}) {
            EXPECT_NEAR(glm::length(path.at(f, still).up), 1.0, 1e-12) << "frame " << f;
        }
        EXPECT_LT(
            glm::length(path.at(path.keys.back().frame + 3.0, still).up - path.keys.back().up),
            1e-12);
        const Camera before = path.at(path.keys.front().frame - 10.0, still);
        const Camera after = path.at(path.keys.back().frame + 10.0, still);
        EXPECT_EQ(before.position_cm, path.keys.front().position_cm);
        EXPECT_EQ(after.lookAt_cm, path.keys.back().lookAt_cm);
        EXPECT_EQ(after.width, still.width);
    }
}

// On evenly spaced keys the curve is the textbook Catmull-Rom spline:
// p(s) = 0.5 [2 p1 + (-p0 + p2) s + (2 p0 - 5 p1 + 4 p2 - p3) s^2 + (-p0 + 3 p1 - 3 p2 + p3) s^3]
// between p1 and p2 (its basis matrix, written independently of the Hermite form).
TEST(CameraPath, EvenKeysGiveTheTextbookCatmullRomSpline)
{
    std::mt19937 rng(11);
    const CameraPath path = randomPath(rng, 6, true);
    for (std::size_t k = 1; k + 2 < path.keys.size(); ++k) {
        for (const double s : {0.1, 0.37, 0.5, 0.83}) {
            const Vec3 p0 = path.keys[k - 1].position_cm, p1 = path.keys[k].position_cm;
            const Vec3 p2 = path.keys[k + 1].position_cm, p3 = path.keys[k + 2].position_cm;
            const Vec3 expected =
                0.5 * (2.0 * p1 + (-p0 + p2) * s + (2.0 * p0 - 5.0 * p1 + 4.0 * p2 - p3) * s * s +
                       (-p0 + 3.0 * p1 - 3.0 * p2 + p3) * s * s * s);
            const double frame = path.keys[k].frame + s * 4.0;
            EXPECT_LT(glm::length(path.at(frame, Camera()).position_cm - expected), 1e-9)
                << "key " << k << ", s " << s;
        }
    }
}

// The camera's velocity is continuous through every key (uneven spacing included), and two
// keys move it at a constant speed: a dolly stays a dolly.
TEST(CameraPath, VelocityIsContinuousThroughKeysAndConstantBetweenTwo)
{
    std::mt19937 rng(5);
    const double h = 1e-4;
    for (int trial = 0; trial < 20; ++trial) {
        const CameraPath path = randomPath(rng, 5, false);
        for (std::size_t k = 1; k + 1 < path.keys.size(); ++k) {
            // One-sided slopes over h and h / 2, extrapolated (Richardson): the curvature's
            // O(h) term cancels, so a kink shows and the curve's bending does not.
            const double f = path.keys[k].frame;
            const auto slope = [&](double step) {
                const Vec3 d =
                    path.at(f + step, Camera()).position_cm - path.at(f, Camera()).position_cm;
                return d / step;
            };
            const Vec3 left = 2.0 * slope(-h / 2) - slope(-h);
            const Vec3 right = 2.0 * slope(h / 2) - slope(h);
            EXPECT_LT(glm::length(left - right), 1e-3 * (1.0 + glm::length(left)))
                << "trial " << trial << ", key " << k;
        }
        CameraPath two = path;
        two.keys.resize(2);
        const double f0 = two.keys[0].frame, f1 = two.keys[1].frame;
        for (const double s : {0.2, 0.5, 0.9}) {
            const Vec3 linear =
                two.keys[0].position_cm + s * (two.keys[1].position_cm - two.keys[0].position_cm);
            EXPECT_LT(glm::length(two.at(f0 + s * (f1 - f0), Camera()).position_cm - linear), 1e-9);
        }
    }
}

TEST(CameraPath, KeysInheritWhatTheyOmitAndFramesDefaultToTheKeys)
{
    const Scene s = parseScene(sceneWithPath(json::parse(R"({
        "keys": [{"frame": 1, "position": [0, -400, 100]},
                 {"frame": 9, "position": [0, -800, 100], "fov_deg": 30},
                 {"frame": 12.5, "look_at": [10, 0, 100]}],
        "fps": 30, "interpolation": "linear"})"))
                                   .dump(),
                               "p.json");
    const CameraPath& p = s.cameraPath;
    ASSERT_EQ(p.keys.size(), 3u);
    EXPECT_EQ(p.keys[0].lookAt_cm, Vec3(0, 0, 100));  // the still camera's
    EXPECT_NEAR(p.keys[0].fovY_rad, 40 * kDeg, 1e-12);
    EXPECT_EQ(p.keys[2].position_cm, Vec3(0, -800, 100));  // the key before it
    EXPECT_NEAR(p.keys[2].fovY_rad, 30 * kDeg, 1e-12);
    EXPECT_EQ(p.firstFrame, 1);
    EXPECT_EQ(p.lastFrame, 12);
    EXPECT_EQ(p.framesPerSecond, 30.0);
    EXPECT_EQ(p.interpolation, CameraPath::Interpolation::Linear);
    EXPECT_NEAR(p.at(5.0, s.camera).position_cm.y, -600.0, 1e-9);
    EXPECT_EQ(p.at(5.0, s.camera).width, 32);
}

TEST(CameraPath, BadPathsAreRefusedNamingTheKeyOrTheFrame)
{
    const auto refused = [](const std::string& path, const std::string& where,
                            const std::string& problem) {
        const std::string message = errorOf(sceneWithPath(json::parse(path)));
        EXPECT_NE(message.find(where), std::string::npos) << message;
        EXPECT_NE(message.find(problem), std::string::npos) << message;
        EXPECT_EQ(message.find('\n'), std::string::npos) << message;
    };
    refused(R"({"keys": []})", "camera_path.keys", "at least one key");
    refused(R"({"keys": [{"frame": 4}, {"frame": 4}]})", "camera_path.keys[1].frame",
            "must exceed the previous key's (4)");
    refused(R"({"keys": [{"frame": 1, "positon": [0, 0, 0]}]})", "camera_path.keys[0].positon",
            "unknown key");
    refused(R"({"keys": [{"frame": 1}], "frames": [5, 2]})", "camera_path.frames[1]", "5");
    refused(R"({"keys": [{"frame": 1}], "frames": [0, 200000]})", "camera_path.frames",
            "more than 100000");
    refused(R"({"keys": [{"frame": 1}], "interpolation": "cubic"})", "camera_path.interpolation",
            "\"smooth\" or \"linear\"");
    refused(R"({"keys": [{"frame": 1, "fov_deg": 0}]})", "camera_path.keys[0].fov_deg",
            "must be in (0, 180)");
    refused(R"({"keys": [{"frame": 1, "up": [0, 0, 0]}]})", "camera_path.keys[0].up", "");
    // fps is a float in each frame's header: 1e-320 was written there as 0, 1e308 as inf.
    refused(R"({"keys": [{"frame": 1}], "fps": 1e-320})", "camera_path.fps",
            "must be in [0.001, 1000000]");
    refused(R"({"keys": [{"frame": 1}], "fps": 1e308})", "camera_path.fps", "must be in");
    // The look-at reaches the camera between keys.
    refused(R"({"keys": [{"frame": 0, "position": [0, -10, 100], "look_at": [0, 10, 100]},
                         {"frame": 10, "position": [0, 10, 100], "look_at": [0, -10, 100]}],
               "interpolation": "linear"})",
            "camera_path: at frame 5", "look_at equals position");
    // A key so far from its look-at that their distance overflows, each coordinate finite:
    // the first frame moving towards it already does.
    refused(R"({"keys": [{"frame": 0}, {"frame": 4, "position": [1e308, -1e308, 1e308]}],
               "interpolation": "linear"})",
            "camera_path: at frame 1", "too far from position");
    // A smooth curve overshoots its keys' field of view below 0.
    refused(R"({"keys": [{"frame": 0, "fov_deg": 170}, {"frame": 1, "fov_deg": 170},
                         {"frame": 2, "fov_deg": 1}, {"frame": 30, "fov_deg": 1}]})",
            "camera_path: at frame", "outside (0, 180)");
}

}  // namespace
}  // namespace pine::scenes
