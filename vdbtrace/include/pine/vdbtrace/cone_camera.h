// The pinhole camera of a scene, one cone per pixel: the pixel's footprint grows with
// distance by the pixel's angular size (section 3.2: "the conic ray is used to estimate the
// apparent size of primitives").
#pragma once

#include "pine/scenes/scene.h"
#include "pine/vdbtrace/geometry.h"

#include <array>

namespace pine::vdbtrace {

class ConeCamera {
public:
    explicit ConeCamera(const scenes::Camera& camera);
    /// The cone through the centre of pixel (x, y), row 0 at the top.
    ConeRay cone(int x, int y) const { return coneAt(x + 0.5, y + 0.5, 1.0); }
    /// The cone through image point (px, py) in pixel units (0..width, 0..height), as wide as
    /// `pixels` pixels: a sub-pixel ray is a narrower cone.
    ConeRay coneAt(double px, double py, double pixels) const;
    /// Cone s (row-major) of pixel (x, y) split into n x n equal squares, each a cone 1/n as
    /// wide through its square's centre.
    ConeRay subpixelCone(int x, int y, int s, int n) const
    {
        return coneAt(x + (s % n + 0.5) / n, y + (s / n + 0.5) / n, 1.0 / n);
    }
    /// The cone through the centre of pixel (x, y) as wide as the disc through its square's
    /// corners: every subpixelCone of the pixel lies within it, off the view axis too (a
    /// cone's spread is the geometric mean of the pixel's radial and tangential sizes, so the
    /// pixel's own cone widened by sqrt(2) falls short of its corners by sqrt(len), len the
    /// distance to the image plane along its ray: 1.17 at a 4:3 40-degree frame's corner).
    ConeRay squareCone(int x, int y) const;
    int width() const { return mWidth; }
    int height() const { return mHeight; }
    /// The unit view axis.
    const Vec3& forward() const { return mForward; }

    /// The camera's matrices, m[row][column] for column vectors (world in cm); an EXR header
    /// holds them transposed (OpenEXR's worldToCamera and worldToNDC). Camera space: x right,
    /// y up, z along the view axis (left-handed, as RenderMan's and pbrt's). NDC (RenderMan's):
    /// after dividing by w, x and y are the image position in [0, 1] over the whole frame, x
    /// to the right and y down from the top-left corner (as pixel rows run); z is
    /// 1 / (camera-space z).
    std::array<std::array<double, 4>, 4> worldToCamera() const;
    std::array<std::array<double, 4>, 4> worldToNdc() const;

private:
    Vec3 mEye, mForward, mRight, mUp;
    double mTanHalf = 0.0, mAspect = 1.0;
    int mWidth = 1, mHeight = 1;
};

}  // namespace pine::vdbtrace
