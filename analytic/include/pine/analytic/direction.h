// Directions relative to an axis: the projections of section 4 (Figure 3).
#pragma once

#include <glm/vec3.hpp>

#include <optional>

namespace pine::analytic {

using Vec3 = glm::dvec3;

inline constexpr double kPi = 3.14159265358979323846;

/// A unit direction X seen from a unit axis d: c = d.X, s = |X_p|, X_p = X - c d (section 4).
struct AxisProjection {
    double c = 0.0;  ///< cosine with the axis (c_v, c_l, c_h)
    double s = 0.0;  ///< norm of the part orthogonal to the axis (s_v, s_l, s_h), in [0, 1]
    Vec3 perp{0.0};  ///< X_p, the orthogonal part, of length s
};

/// Projects a unit direction on a unit axis. `s` comes from |d x X|, accurate near the axis
/// where sqrt(1 - c^2) would lose every digit.
AxisProjection projectOnAxis(const Vec3& axis, const Vec3& dir);

/// The unit vector along v, or nothing when v has no usable length (zero, denormal, NaN, inf).
std::optional<Vec3> safeNormalize(const Vec3& v);

/// The unit vector along a direction a user gave, whatever its finite magnitude: scaled by its
/// largest component first, so that neither 1e-200 nor 1e200 under- or overflows its length.
/// Nothing for the zero vector or a non-finite component. (safeNormalize, for vectors computed
/// from others, keeps refusing what is near zero: there it means parallel.)
std::optional<Vec3> normalizeGiven(const Vec3& v);

/// Angle in [0, pi] between two vectors, by atan2: exact near 0 and pi where acos is not,
/// and 0 (not NaN) when either vector is zero.
double angleBetween(const Vec3& a, const Vec3& b);

/// A unit vector orthogonal to the unit vector `axis`, chosen deterministically.
Vec3 anyPerpendicular(const Vec3& axis);

}  // namespace pine::analytic
