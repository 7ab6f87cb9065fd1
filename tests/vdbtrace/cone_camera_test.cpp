// The camera's matrices, as an EXR header records them, against the cones it traces: a point
// on the ray through image position (px, py) projects back to (px / width, py / height).
#include "pine/vdbtrace/cone_camera.h"

#include <glm/geometric.hpp>
#include <gtest/gtest.h>

#include <random>

namespace pine::vdbtrace {
namespace {

Vec3 transformed(const std::array<std::array<double, 4>, 4>& m, const Vec3& p, double* w = nullptr)
{
    Vec3 out;
    for (int i = 0; i < 3; ++i) out[i] = m[i][0] * p.x + m[i][1] * p.y + m[i][2] * p.z + m[i][3];
    const double h = m[3][0] * p.x + m[3][1] * p.y + m[3][2] * p.z + m[3][3];
    if (w) *w = h;
    return out;
}

TEST(ConeCamera, MatricesProjectEachConeBackToItsImagePosition)
{
    std::mt19937 random(5);
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    for (int trial = 0; trial < 200; ++trial) {
        scenes::Camera c;
        c.position_cm = Vec3(unit(random) * 400 - 200, unit(random) * 400 - 200, unit(random) * 300);
        c.lookAt_cm = Vec3(unit(random) * 50, unit(random) * 50, unit(random) * 100);
        c.up = trial % 3 ? Vec3(0, 0, 1) : glm::normalize(Vec3(0.2, 0.1, 1.0));
        c.fovY_rad = 0.2 + 1.5 * unit(random);
        c.width = 64 + trial;
        c.height = 48 + 2 * trial % 97;
        const ConeCamera camera(c);
        const auto toCamera = camera.worldToCamera();
        const auto toNdc = camera.worldToNdc();
        const double px = unit(random) * c.width, py = unit(random) * c.height;
        const ConeRay ray = camera.coneAt(px, py, 1.0);
        const double t = 1.0 + 1000.0 * unit(random);
        const Vec3 p = ray.origin + t * ray.direction;
        // Camera space: the eye at the origin, the view axis along z, distances kept.
        const Vec3 q = transformed(toCamera, p);
        EXPECT_NEAR(glm::length(q), t, 1e-9 * t);
        EXPECT_NEAR(q.z, t * glm::dot(ray.direction, camera.forward()), 1e-9 * t);
        EXPECT_NEAR(glm::length(transformed(toCamera, c.position_cm)), 0.0, 1e-9);
        // Right is +x and up is +y: a point right of the centre has x > 0.
        const ConeRay right = camera.coneAt(0.9 * c.width, 0.5 * c.height, 1.0);
        EXPECT_GT(transformed(toCamera, right.origin + right.direction).x, 0.0);
        const ConeRay top = camera.coneAt(0.5 * c.width, 0.1 * c.height, 1.0);
        EXPECT_GT(transformed(toCamera, top.origin + top.direction).y, 0.0);
        // NDC: the image position over the whole image, y down.
        double w = 0.0;
        const Vec3 n = transformed(toNdc, p, &w);
        ASSERT_GT(w, 0.0);
        EXPECT_NEAR(n.x / w, px / c.width, 1e-9);
        EXPECT_NEAR(n.y / w, py / c.height, 1e-9);
        EXPECT_NEAR(n.z / w, 1.0 / q.z, 1e-12);
    }
}

}  // namespace
}  // namespace pine::vdbtrace
