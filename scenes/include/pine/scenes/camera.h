// The camera, still or moving along a path of keyframes (docs/scene-format.md, "camera" and
// "camera_path"). Lengths in cm, angles in radians.
#pragma once

#include <glm/vec3.hpp>

#include <string>
#include <vector>

namespace pine::scenes {

using Vec3 = glm::dvec3;

struct Camera {
    Vec3 position_cm{0.0, -500.0, 100.0};
    Vec3 lookAt_cm{0.0, 0.0, 100.0};
    Vec3 up{0.0, 0.0, 1.0};
    double fovY_rad = 0.7;  ///< vertical field of view
    int width = 640, height = 480;
};

/// The camera as it stands at one frame of a path.
struct CameraKey {
    double frame = 0.0;
    Vec3 position_cm{0.0}, lookAt_cm{0.0}, up{0.0, 0.0, 1.0};
    double fovY_rad = 0.7;
};

/// A camera moving through keyframes, each of position, look-at, up and field of view
/// interpolated as a function of the frame number. "smooth": a cubic Hermite curve per
/// component whose tangent at a key is the slope between its neighbours (Catmull-Rom on the
/// keys' own frame spacing; at the first and last key the slope to their one neighbour), so
/// the camera's velocity is continuous through every key and two keys move it at a constant
/// speed; "linear": straight between keys. Before the first key and after the last the camera
/// holds still. The up vector is normalised after interpolation.
struct CameraPath {
    enum class Interpolation { Smooth, Linear };
    /// The most frames one job renders (a path's, or --frames): checked before any work.
    static constexpr int kMaxFrames = 100000;

    std::vector<CameraKey> keys;  ///< frames strictly increasing; empty: no path
    Interpolation interpolation = Interpolation::Smooth;
    int firstFrame = 0, lastFrame = 0;  ///< the frames rendered when none are named
    double framesPerSecond = 24.0;      ///< recorded with each frame, for players

    bool empty() const { return keys.empty(); }
    int frameCount() const { return empty() ? 0 : lastFrame - firstFrame + 1; }

    /// The camera at `frame`, its resolution `still`'s. Requires !empty().
    Camera at(double frame, const Camera& still) const;
};

/// What keeps a camera from rendering: the scene key at fault ("look_at", "up", "fov_deg")
/// and why, or an empty key if nothing does.
struct CameraFault {
    std::string key, why;
    explicit operator bool() const { return !key.empty(); }
};

/// What keeps `camera` from rendering: its look-at on its position or too far from it for the
/// distance to be a number, its up along the view or zero, its field of view outside (0, 180)
/// degrees. The scene reader names the key; camera paths and --frames word it whole.
CameraFault cameraFault(const Camera& camera);

/// cameraFault as one phrase ("look_at equals position (no view direction)"), or empty.
std::string cameraProblem(const Camera& camera);

/// The interpolation's names as a scene file writes them ("smooth", "linear").
const char* interpolationName(CameraPath::Interpolation interpolation);

}  // namespace pine::scenes
