// Where a bough's needles are: cone j's apex on the branch, needle i's direction on the cone
// (paper section 3.1: N needles of length l and radius r at aperture phi, cones every dh).
// The multiscale tracer's level 1 and the explicit-needle ground truth enumerate the same
// needles from here, so that they can be compared needle for needle.
#pragma once

#include "pine/analytic/direction.h"
#include "pine/vdbtrace/cone_crossings.h"
#include "pine/vdbtrace/geometry.h"
#include "pine/vdbtrace/traced_scene.h"

#include <glm/geometric.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>

namespace pine::vdbtrace {

/// A deterministic angle in [0, 2 pi) for cone j of a bough: where its first needle points
/// (splitmix64 of the bough's seed and j, so that neighbouring cones do not line up).
inline double coneRoll(unsigned seed, long j)
{
    std::uint64_t z = (std::uint64_t(seed) << 32) ^ std::uint64_t(j) ^ 0x9e3779b97f4a7c15ull;
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    z ^= z >> 31;
    return 2.0 * analytic::kPi * double(z >> 11) * 0x1.0p-53;
}

/// The needles of one bough: cones j = 0 .. floor(length / dh), apex base + j dh axis; needle
/// i = 0 .. N-1 of cone j at azimuth roll_j + 2 pi i / N around the branch, direction
/// cos(phi) axis + sin(phi) (cos(a) e1 + sin(a) e2), e1 = anyPerpendicular(axis),
/// e2 = axis x e1. Needle parameters are the bough's mid-bough ones (TracedBough::geometry).
class NeedleLayout {
public:
    explicit NeedleLayout(const TracedBough& b)
        : mBase(b.base_cm),
          mAxis(b.axis),
          mE1(analytic::anyPerpendicular(b.axis)),
          mE2(glm::cross(b.axis, mE1)),
          mSpacing(b.geometry.coneSpacing_cm),
          mCos(apertureTrig(b.geometry.cone.aperture_rad).cosPhi),
          mSin(apertureTrig(b.geometry.cone.aperture_rad).sinPhi),
          mLength(b.geometry.cone.needleLength_cm),
          mRadius(b.geometry.cone.needleRadius_cm),
          mLastCone(long(std::floor(b.length_cm / b.geometry.coneSpacing_cm))),
          mNeedles(int(scenes::wholeNeedles(b.geometry.cone.needlesPerCone))),
          mSeed(b.seed)
    {
    }

    long lastCone() const { return mLastCone; }    ///< j runs 0 .. lastCone()
    int needlesPerCone() const { return mNeedles; }  ///< N, at least 1
    double length() const { return mLength; }      ///< l, cm
    double radius() const { return mRadius; }      ///< r, cm
    const Vec3& e1() const { return mE1; }
    const Vec3& e2() const { return mE2; }

    double roll(long j) const { return coneRoll(mSeed, j); }
    /// Azimuth of needle i of cone j (any integer i: it wraps around the cone).
    double azimuth(long j, long i) const
    {
        return roll(j) + 2.0 * analytic::kPi * double(i) / mNeedles;
    }
    Vec3 apex(long j) const { return mBase + (double(j) * mSpacing) * mAxis; }
    /// Unit direction of the needle at azimuth a, from its apex towards its tip.
    Vec3 direction(double a) const
    {
        return mCos * mAxis + mSin * (std::cos(a) * mE1 + std::sin(a) * mE2);
    }

    /// Calls f(apex, direction) for every needle, cone by cone.
    template <typename F>
    void forEach(F&& f) const
    {
        for (long j = 0; j <= mLastCone; ++j) {
            const Vec3 a = apex(j);
            for (int i = 0; i < mNeedles; ++i) f(a, direction(azimuth(j, i)));
        }
    }

private:
    Vec3 mBase, mAxis, mE1, mE2;
    double mSpacing, mCos, mSin, mLength, mRadius;
    long mLastCone;
    int mNeedles;
    unsigned mSeed;
};

}  // namespace pine::vdbtrace
