// What an EXR holds of a render: Z along the view axis (also in a crop), the AOVs a method
// computes and no others, the camera's matrices for row vectors.
#include "pine/vdbtrace/exr_output.h"

#include <glm/geometric.hpp>
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

namespace pine::vdbtrace {
namespace {

scenes::Camera wideCamera()
{
    scenes::Camera c;
    c.position_cm = Vec3(10.0, -300.0, 80.0);
    c.lookAt_cm = Vec3(-20.0, 0.0, 40.0);
    c.fovY_rad = 1.2;  // wide: the view axis and a corner ray differ by 40 degrees
    c.width = 40;
    c.height = 30;
    return c;
}

Image rendered(int width, int height)
{
    Image image(width, height);
    for (const char* name : {"level", "depth", "diffuse", "specular", "foliage", "tree"}) {
        std::vector<float>& v = image.aov(name);
        for (std::size_t i = 0; i < v.size(); ++i) v[i] = float(100.0 + double(i));
    }
    image.aov("depth")[3] = std::numeric_limits<float>::infinity();
    return image;
}

TEST(ExrOutput, ZIsTheDistanceAlongTheViewAxisAndInfiniteWhereNothingIsHit)
{
    const ConeCamera camera(wideCamera());
    for (const bool crop : {false, true}) {
        Image image = rendered(crop ? 10 : 40, crop ? 8 : 30);
        if (crop) {
            image.originX = 25;
            image.originY = 17;
            image.frameWidth = 40;
            image.frameHeight = 30;
        }
        const Image exr = exrImage(image, camera, renderMethod("multiscale"), EffectsPlan{});
        ASSERT_TRUE(exr.aovs.count("Z"));
        EXPECT_FALSE(exr.aovs.count("depth"));
        EXPECT_EQ(exr.originX, image.originX);
        EXPECT_EQ(exr.frameWidth, image.frameWidth);
        const std::vector<float>& z = exr.aovs.at("Z");
        for (int y = 0; y < image.height; ++y) {
            for (int x = 0; x < image.width; ++x) {
                const std::size_t i = std::size_t(y * image.width + x);
                const float t = image.aovs.at("depth")[i];
                if (!std::isfinite(t)) {
                    EXPECT_EQ(z[i], std::numeric_limits<float>::infinity());
                    continue;
                }
                // The hit point, then its camera-space z through worldToCamera.
                const ConeRay ray = camera.cone(x + image.originX, y + image.originY);
                const Vec3 p = ray.origin + double(t) * ray.direction;
                const auto m = camera.worldToCamera();
                const double zc = m[2][0] * p.x + m[2][1] * p.y + m[2][2] * p.z + m[2][3];
                EXPECT_NEAR(z[i], zc, 1e-4 * zc) << x << ", " << y;
            }
        }
        // Off axis, Z is shorter than the distance along the ray.
        EXPECT_LT(z.back(), image.aovs.at("depth").back() * 0.99f);
    }
}

TEST(ExrOutput, OnlyTheAovsTheMethodComputes)
{
    const ConeCamera camera(wideCamera());
    EffectsPlan plan;
    plan.diffuse = true;
    plan.specular = false;
    const auto names = [&](const char* method) {
        std::string out;
        for (const auto& [name, values] : exrImage(rendered(4, 3), camera, renderMethod(method),
                                                   plan).aovs) {
            out += name + " ";
        }
        return out;
    };
    EXPECT_EQ(names("multiscale"), "Z diffuse foliage level tree ");
    EXPECT_EQ(names("geometry"), "Z diffuse foliage tree ");
    EXPECT_EQ(names("reference"), "Z diffuse foliage tree ");
}

TEST(ExrOutput, CameraMatricesAreForRowVectors)
{
    const ConeCamera camera(wideCamera());
    const Metadata m = cameraMetadata(camera);
    ASSERT_EQ(m.size(), 2u);
    const Matrix44& toCamera = std::get<Matrix44>(m[0].second);
    EXPECT_EQ(m[0].first, "worldToCamera");
    // p M with p the eye (a row vector) is the origin; the translation is in the last row.
    const Vec3 eye = wideCamera().position_cm;
    for (int j = 0; j < 3; ++j) {
        const double v = eye.x * toCamera.m[0][j] + eye.y * toCamera.m[1][j] +
                         eye.z * toCamera.m[2][j] + toCamera.m[3][j];
        EXPECT_NEAR(v, 0.0, 1e-3);
        EXPECT_EQ(toCamera.m[j][3], 0.0f);
    }
    EXPECT_EQ(m[1].first, "worldToNDC");
}

}  // namespace
}  // namespace pine::vdbtrace
