#include "pine/vdbtrace/exr_output.h"

#include <glm/geometric.hpp>

#include <cmath>
#include <limits>

namespace pine::vdbtrace {
namespace {

Matrix44 forRowVectors(const std::array<std::array<double, 4>, 4>& m)
{
    Matrix44 out;
    for (int i = 0; i < 4; ++i) {
        for (int j = 0; j < 4; ++j) out.m[i][j] = float(m[j][i]);
    }
    return out;
}

}  // namespace

Image exrImage(const Image& rendered, const ConeCamera& camera, const RenderMethod& method,
               const EffectsPlan& plan)
{
    Image exr(rendered.width, rendered.height);
    exr.originX = rendered.originX;
    exr.originY = rendered.originY;
    exr.frameWidth = rendered.frameWidth;
    exr.frameHeight = rendered.frameHeight;
    exr.rgba = rendered.rgba;
    for (const auto& [name, values] : rendered.aovs) {
        if (!computesAov(method, name, plan)) continue;
        if (name != "depth") {
            exr.aovs[name] = values;
            continue;
        }
        std::vector<float>& z = exr.aov("Z");
        for (int y = 0; y < rendered.height; ++y) {
            for (int x = 0; x < rendered.width; ++x) {
                const std::size_t i =
                    std::size_t(y) * std::size_t(rendered.width) + std::size_t(x);
                const ConeRay ray = camera.cone(x + rendered.originX, y + rendered.originY);
                const double along = glm::dot(ray.direction, camera.forward());
                z[i] = std::isfinite(values[i]) ? float(double(values[i]) * along)
                                                : std::numeric_limits<float>::infinity();
            }
        }
    }
    return exr;
}

Metadata cameraMetadata(const ConeCamera& camera)
{
    return {{"worldToCamera", forRowVectors(camera.worldToCamera())},
            {"worldToNDC", forRowVectors(camera.worldToNdc())}};
}

}  // namespace pine::vdbtrace
