// Deterministic random inputs for property tests: a fixed seed, so a failure reproduces.
#pragma once

#include "pine/analytic/bough_shader.h"
#include "pine/analytic/direction.h"

#include <glm/geometric.hpp>

#include <random>

namespace pine::analytic::test {

class RandomDirections {
public:
    explicit RandomDirections(unsigned seed) : mRng(seed) {}

    /// Uniform on the sphere.
    Vec3 direction()
    {
        for (;;) {
            const Vec3 v(mNormal(mRng), mNormal(mRng), mNormal(mRng));
            if (auto u = safeNormalize(v)) return *u;
        }
    }
    double uniform(double lo, double hi) { return lo + (hi - lo) * mUniform(mRng); }
    /// Log-uniform in [lo, hi].
    double logUniform(double lo, double hi)
    {
        return std::exp(uniform(std::log(lo), std::log(hi)));
    }

private:
    std::mt19937 mRng;
    std::normal_distribution<double> mNormal;
    std::uniform_real_distribution<double> mUniform{0.0, 1.0};
};

/// A rotation of `v` about unit `axis` by `angle`.
inline Vec3 rotate(const Vec3& v, const Vec3& axis, double angle)
{
    return v * std::cos(angle) + glm::cross(axis, v) * std::sin(angle) +
           axis * glm::dot(axis, v) * (1.0 - std::cos(angle));
}

}  // namespace pine::analytic::test
