#include "pine/scenes/camera.h"

#include <glm/geometric.hpp>

#include <algorithm>
#include <cassert>
#include <cmath>
#include <numbers>
#include <sstream>

namespace pine::scenes {
namespace {

// One component's value at `frame` between keys k and k + 1, `value(key)` reading it: the
// cubic Hermite curve with Catmull-Rom tangents on the keys' own spacing (non-uniform).
template <class T, class Value>
T hermite(const std::vector<CameraKey>& keys, std::size_t k, double frame, Value value)
{
    const double t0 = keys[k].frame, t1 = keys[k + 1].frame, dt = t1 - t0;
    const T p0 = value(keys[k]), p1 = value(keys[k + 1]);
    const auto slope = [&](std::size_t i) -> T {
        const std::size_t a = i == 0 ? 0 : i - 1, b = std::min(i + 1, keys.size() - 1);
        return (value(keys[b]) - value(keys[a])) / (keys[b].frame - keys[a].frame);
    };
    const double s = (frame - t0) / dt, s2 = s * s, s3 = s2 * s;
    return (2 * s3 - 3 * s2 + 1) * p0 + (s3 - 2 * s2 + s) * dt * slope(k) +
           (-2 * s3 + 3 * s2) * p1 + (s3 - s2) * dt * slope(k + 1);
}

template <class T, class Value>
T straight(const std::vector<CameraKey>& keys, std::size_t k, double frame, Value value)
{
    const double s = (frame - keys[k].frame) / (keys[k + 1].frame - keys[k].frame);
    return value(keys[k]) + s * (value(keys[k + 1]) - value(keys[k]));
}

}  // namespace

Camera CameraPath::at(double frame, const Camera& still) const
{
    assert(!keys.empty());
    Camera c = still;
    const auto set = [&c](const CameraKey& key) {
        c.position_cm = key.position_cm;
        c.lookAt_cm = key.lookAt_cm;
        c.up = glm::normalize(key.up);
        c.fovY_rad = key.fovY_rad;
    };
    if (frame <= keys.front().frame) {
        set(keys.front());
        return c;
    }
    if (frame >= keys.back().frame) {
        set(keys.back());
        return c;
    }
    // The segment [keys[k], keys[k + 1]) holding the frame.
    const auto after =
        std::upper_bound(keys.begin(), keys.end(), frame,
                         [](double f, const CameraKey& key) { return f < key.frame; });
    const std::size_t k = std::size_t(after - keys.begin()) - 1;
    const bool smooth = interpolation == Interpolation::Smooth;
    const auto vec = [&](auto value) {
        return smooth ? hermite<Vec3>(keys, k, frame, value)
                      : straight<Vec3>(keys, k, frame, value);
    };
    c.position_cm = vec([](const CameraKey& key) { return key.position_cm; });
    c.lookAt_cm = vec([](const CameraKey& key) { return key.lookAt_cm; });
    c.up = vec([](const CameraKey& key) { return key.up; });
    const auto fov = [](const CameraKey& key) { return key.fovY_rad; };
    c.fovY_rad =
        smooth ? hermite<double>(keys, k, frame, fov) : straight<double>(keys, k, frame, fov);
    // A zero up (keys' ups opposite) is left for the caller's check to name.
    const double upLength = glm::length(c.up);
    if (upLength > 0.0) c.up /= upLength;
    return c;
}

CameraFault cameraFault(const Camera& c)
{
    const Vec3 view = c.lookAt_cm - c.position_cm;
    if (!(glm::length(view) > 0.0)) return {"look_at", "equals position (no view direction)"};
    // Each coordinate finite, their distance not: the view direction would be zero.
    if (!std::isfinite(glm::length(view))) {
        return {"look_at", "lies too far from position for its distance to be a number"};
    }
    // An up vector along the view leaves the image's roll undefined.
    if (!(glm::length(glm::cross(glm::normalize(view), c.up)) >= 1e-6)) {
        return {"up", "is parallel to the view direction (or zero)"};
    }
    if (!(c.fovY_rad > 0.0 && c.fovY_rad < std::numbers::pi)) {
        std::ostringstream fov;
        fov << c.fovY_rad * 180.0 / std::numbers::pi << " is outside (0, 180)";
        return {"fov_deg", fov.str()};
    }
    return {};
}

std::string cameraProblem(const Camera& c)
{
    const CameraFault fault = cameraFault(c);
    return fault ? fault.key + " " + fault.why : std::string();
}

const char* interpolationName(CameraPath::Interpolation interpolation)
{
    return interpolation == CameraPath::Interpolation::Smooth ? "smooth" : "linear";
}

}  // namespace pine::scenes
