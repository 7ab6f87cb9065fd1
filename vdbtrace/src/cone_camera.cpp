#include "pine/vdbtrace/cone_camera.h"

#include <glm/geometric.hpp>

#include <algorithm>
#include <cmath>
#include <utility>

namespace pine::vdbtrace {

ConeCamera::ConeCamera(const scenes::Camera& c)
    : mEye(c.position_cm), mWidth(c.width), mHeight(c.height)
{
    mForward = glm::normalize(c.lookAt_cm - c.position_cm);
    mRight = glm::normalize(glm::cross(mForward, c.up));
    mUp = glm::cross(mRight, mForward);
    mTanHalf = std::tan(0.5 * c.fovY_rad);
    mAspect = double(c.width) / c.height;
}

ConeRay ConeCamera::coneAt(double px, double py, double pixels) const
{
    const double sx = (2.0 * px / mWidth - 1.0) * mTanHalf * mAspect;
    const double sy = (1.0 - 2.0 * py / mHeight) * mTanHalf;
    const Vec3 d = mForward + sx * mRight + sy * mUp;
    const double len = glm::length(d);
    ConeRay ray;
    ray.origin = mEye;
    ray.direction = d / len;
    // A pixel spans p = 2 tan(fov/2) / height on the image plane at distance 1 along the view
    // axis. Off axis, at distance len, it subtends p / len across the radial direction and
    // p / len^2 along it (seen obliquely): their geometric mean is the footprint's growth.
    ray.spread = pixels * 2.0 * mTanHalf / mHeight / std::pow(len, 1.5);
    return ray;
}

ConeRay ConeCamera::squareCone(int x, int y) const
{
    ConeRay ray = cone(x, y);
    double tanMax = 0.0;  // of the widest angle from the ray to a corner's
    for (const auto& [cx, cy] : {std::pair{x, y}, {x + 1, y}, {x, y + 1}, {x + 1, y + 1}}) {
        const Vec3 corner = coneAt(cx, cy, 1.0).direction;
        const double c = glm::dot(corner, ray.direction);
        tanMax = std::max(tanMax, std::sqrt(std::max(0.0, 1.0 - c * c)) / c);
    }
    ray.spread = 2.0 * tanMax;
    return ray;
}

std::array<std::array<double, 4>, 4> ConeCamera::worldToCamera() const
{
    std::array<std::array<double, 4>, 4> m{};
    const Vec3* rows[3] = {&mRight, &mUp, &mForward};
    for (int i = 0; i < 3; ++i) {
        const Vec3& r = *rows[i];
        m[i] = {r.x, r.y, r.z, -glm::dot(r, mEye)};
    }
    m[3] = {0.0, 0.0, 0.0, 1.0};
    return m;
}

std::array<std::array<double, 4>, 4> ConeCamera::worldToNdc() const
{
    // coneAt's image position: px / width = 1/2 + x / (2 z tan(fov/2) aspect), py / height =
    // 1/2 - y / (2 z tan(fov/2)), with (x, y, z) in camera space.
    const double sx = 0.5 / (mTanHalf * mAspect), sy = 0.5 / mTanHalf;
    const double ndcFromCamera[4][4] = {
        {sx, 0.0, 0.5, 0.0}, {0.0, -sy, 0.5, 0.0}, {0.0, 0.0, 0.0, 1.0}, {0.0, 0.0, 1.0, 0.0}};
    const auto camera = worldToCamera();
    std::array<std::array<double, 4>, 4> m{};
    for (int i = 0; i < 4; ++i) {
        for (int j = 0; j < 4; ++j) {
            for (int k = 0; k < 4; ++k) m[i][j] += ndcFromCamera[i][k] * camera[k][j];
        }
    }
    return m;
}

}  // namespace pine::vdbtrace
