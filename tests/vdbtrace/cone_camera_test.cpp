// The camera's matrices, as an EXR header records them, against the cones it traces: a point
// on the ray through image position (px, py) projects back to (px / width, py / height).
#include "pine/vdbtrace/cone_camera.h"

#include <glm/geometric.hpp>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
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

TEST(ConeCamera, APixelsSquareConeHoldsEverySubpixelCone)
{
    // The multiscale split asks what the pixel's square holds before choosing k: every cone
    // of a k x k split must lie within squareCone's disc, its angle from the pixel's axis plus
    // its own half-angle no more than the square's. Frames from narrow to 150 degrees, every
    // k the split uses; the pixels include the frame's corners, where the pixel's own cone
    // widened by sqrt(2) (its disc's rule until 2026-12-07) falls short.
    std::mt19937 random(11);
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    double worstMargin = 1.0, sqrt2Short = 0.0;
    for (int trial = 0; trial < 60; ++trial) {
        scenes::Camera c;
        c.position_cm = Vec3(0.0, -100.0, 50.0);
        c.lookAt_cm = Vec3(unit(random) * 20, 0.0, 40.0 + unit(random) * 20);
        c.up = Vec3(0, 0, 1);
        c.fovY_rad = 0.1 + 2.5 * trial / 59.0;  // up to 149 degrees
        c.width = 16 + 3 * trial;
        c.height = 12 + trial;
        const ConeCamera camera(c);
        for (int corner = 0; corner < 6; ++corner) {
            const int x = corner < 4 ? (corner % 2) * (c.width - 1) : int(unit(random) * c.width);
            const int y = corner < 4 ? (corner / 2) * (c.height - 1) : int(unit(random) * c.height);
            const ConeRay square = camera.squareCone(x, y);
            const ConeRay pixel = camera.cone(x, y);
            EXPECT_EQ(square.direction, pixel.direction);
            const double squareAngle = std::atan(0.5 * square.spread);
            const double sqrt2Angle = std::atan(0.5 * std::sqrt(2.0) * pixel.spread);
            for (int k = 2; k <= 4; ++k) {
                for (int s = 0; s < k * k; ++s) {
                    const ConeRay sub = camera.subpixelCone(x, y, s, k);
                    const double reach =
                        std::acos(std::min(1.0, glm::dot(sub.direction, square.direction))) +
                        std::atan(0.5 * sub.spread);
                    ASSERT_LE(reach, squareAngle * (1.0 + 1e-9))
                        << "fov " << c.fovY_rad << " pixel " << x << "," << y << " k " << k;
                    worstMargin = std::min(worstMargin, 1.0 - reach / squareAngle);
                    sqrt2Short = std::max(sqrt2Short, reach / sqrt2Angle - 1.0);
                }
            }
        }
    }
    std::printf(
        "the split's cones stay at least %.1f%% inside the square's disc; the pixel's "
        "cone widened by sqrt(2) falls %.1f%% short at worst\n",
        100.0 * worstMargin, 100.0 * sqrt2Short);
    EXPECT_GT(sqrt2Short, 0.05) << "the wide frames' corners should need more than sqrt(2)";
}

}  // namespace
}  // namespace pine::vdbtrace
