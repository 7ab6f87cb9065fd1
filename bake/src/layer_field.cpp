// The bough's layer field (paper section 6) on the true cones (docs/errata.md, E12).
#include "pine/bake/layer_field.h"

#include "prepared_bough.h"

#include "pine/analytic/cone_shader.h"

#include <glm/geometric.hpp>

#include <algorithm>
#include <cmath>

namespace pine::bake {

double LayerSample::layerExtinction() const
{
    // log1p keeps the digits of a thin layer (A << 1), where -ln(1 - A) ~ A.
    return std::min(-std::log1p(-std::clamp(layerOpacity, 0.0, 1.0)), kMaxLayerExtinction);
}

std::optional<LayerSample> sampleBough(const BoughSpec& bough, const Vec3& x_cm)
{
    return detail::PreparedBough(bough).sample(x_cm);
}

namespace detail {

namespace {

bool finite(const Vec3& v)
{
    return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}

}  // namespace

PreparedBough::PreparedBough(const BoughSpec& spec)
{
    const analytic::ConeGeometry& cone = spec.needles.cone;
    const double phi = cone.aperture_rad;
    if (!finite(spec.base_cm) || !finite(spec.tip_cm) || !finite(spec.needleAlbedo) ||
        !std::isfinite(phi) || !std::isfinite(cone.needleLength_cm) ||
        !std::isfinite(cone.needleRadius_cm) || !std::isfinite(cone.needlesPerCone) ||
        !std::isfinite(spec.needles.coneSpacing_cm)) {
        mInvalid = "a parameter is not finite";
    } else if (!(phi > 0.0 && phi <= analytic::kPi / 2)) {
        mInvalid = "aperture_rad must be in (0, pi/2]";
    } else if (cone.needleLength_cm < 0.0 || cone.needleRadius_cm < 0.0 ||
               cone.needlesPerCone < 0.0) {
        mInvalid = "needle length, radius and count must be >= 0";
    } else if (!(spec.needles.coneSpacing_cm > 0.0)) {
        mInvalid = "coneSpacing_cm must be > 0";
    }
    if (mInvalid) return;

    mBase = spec.base_cm;
    mLength = glm::length(spec.tip_cm - spec.base_cm);
    mRadius = analytic::boughRadius(cone);    // R = l sin(phi)
    mOpacity = analytic::layerOpacity(cone);  // A = 2 N r / (pi R), in [0, 1]
    mCoverageTimesRho = cone.needlesPerCone * cone.needleRadius_cm / analytic::kPi;
    mCosPhi = std::cos(phi);
    mSinPhi = std::sin(phi);
    mCotPhi = mCosPhi / mSinPhi;
    mInvSpacing = 1.0 / spec.needles.coneSpacing_cm;
    if (mLength > 0.0) mAxis = (spec.tip_cm - spec.base_cm) / mLength;
    // The world axis least along the branch, made orthogonal to it.
    Vec3 least(0.0);
    least[std::abs(mAxis.x) <= std::abs(mAxis.y)
              ? (std::abs(mAxis.x) <= std::abs(mAxis.z) ? 0 : 2)
              : (std::abs(mAxis.y) <= std::abs(mAxis.z) ? 1 : 2)] = 1.0;
    mAnyRadial = glm::normalize(least - glm::dot(least, mAxis) * mAxis);
    mEmpty = !(mLength > 0.0 && mRadius > 0.0 && mOpacity > 0.0 && std::isfinite(mAxis.x));
}

std::optional<LayerSample> PreparedBough::sample(const Vec3& x_cm) const
{
    if (mEmpty) return std::nullopt;
    const Vec3 v = x_cm - mBase;
    const double h = glm::dot(v, mAxis);
    const Vec3 across = v - h * mAxis;
    const double rho = glm::length(across);
    if (!(rho <= mRadius)) return std::nullopt;
    // g = h - rho cot(phi) is the height of the apex of the cone through x: the cones' apexes
    // lie on the branch, between its base and its tip.
    const double g = h - rho * mCotPhi;
    if (g < 0.0 || g > mLength) return std::nullopt;
    return fieldAcross(across, rho);
}

std::optional<LayerSample> PreparedBough::sampleAcross(const Vec3& x_cm) const
{
    if (mEmpty) return std::nullopt;
    const Vec3 v = x_cm - mBase;
    const Vec3 across = v - glm::dot(v, mAxis) * mAxis;
    const double rho = glm::length(across);
    if (!std::isfinite(rho)) return std::nullopt;
    return fieldAcross(rho <= mRadius ? across : across * (mRadius / rho), std::min(rho, mRadius));
}

LayerSample PreparedBough::fieldAcross(const Vec3& across, double rho) const
{
    // On the axis every cone has its apex and the radial direction is undefined; any will do,
    // since the needles' density there (|G| = 1 / (dh sin(phi)), coverage 1) is not. Dropping
    // the axis lost a whole row of voxels where it runs through their centres.
    const Vec3 radial = rho >= 1e-9 ? across / rho : mAnyRadial;
    LayerSample s;
    s.gradient = (mAxis - mCotPhi * radial) * mInvSpacing;  // grad g / dh
    s.needle = mCosPhi * mAxis + mSinPhi * radial;
    s.layerOpacity = mOpacity;
    s.needleCoverage = std::min(1.0, mCoverageTimesRho / rho);
    return s;
}

}  // namespace detail

}  // namespace pine::bake
