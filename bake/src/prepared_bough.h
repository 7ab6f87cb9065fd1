// A bough's layer field with everything that does not depend on the point computed once: what
// sampleBough evaluates per call and the voxelizer per voxel. Private to bake/.
#pragma once

#include "pine/bake/layer_field.h"

#include <optional>

namespace pine::bake::detail {

class PreparedBough {
public:
    explicit PreparedBough(const BoughSpec& spec);

    /// True when the bough fills no volume or stops no light (zero length, zero radius, A = 0)
    /// or its parameters are outside their domain (see invalidReason).
    bool empty() const { return mEmpty; }
    /// Why the spec is outside its domain (non-finite, phi outside (0, pi/2], a negative size,
    /// dh <= 0), or nullptr. Zero sizes are in the domain: they give an empty bough.
    const char* invalidReason() const { return mInvalid; }

    /// The field at x, or nothing outside the region (layer_field.h).
    std::optional<LayerSample> sample(const Vec3& x_cm) const;
    /// The field at x's distance from the axis, at most R, in x's direction across it: what
    /// the region holds beside x, wherever x lies along the axis (the field depends on the
    /// distance and direction alone), or nothing for an empty bough.
    std::optional<LayerSample> sampleAcross(const Vec3& x_cm) const;

    /// The cylinder that holds the region: from base along the axis for extent_cm() =
    /// length + R cot(phi) (the last cone's rim), radius R.
    const Vec3& base() const { return mBase; }
    const Vec3& axis() const { return mAxis; }
    double extent_cm() const { return mLength + mRadius * mCotPhi; }
    double radius_cm() const { return mRadius; }

private:
    LayerSample fieldAcross(const Vec3& across, double rho) const;

    Vec3 mBase{0.0}, mAxis{0.0, 0.0, 1.0};
    Vec3 mAnyRadial{1.0, 0.0, 0.0};  ///< a unit vector across the axis, for points on it
    double mLength = 0.0, mRadius = 0.0, mCotPhi = 0.0, mCosPhi = 1.0, mSinPhi = 0.0;
    double mInvSpacing = 0.0, mOpacity = 0.0;
    double mCoverageTimesRho = 0.0;  ///< N r / pi
    bool mEmpty = true;
    const char* mInvalid = nullptr;
};

}  // namespace pine::bake::detail
