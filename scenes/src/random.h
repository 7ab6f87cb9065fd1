// Portable uniform numbers (private). std::uniform_real_distribution is not specified to give
// the same numbers on every standard library; std::mt19937 is, so we build on its raw output.
#pragma once

#include <random>

namespace pine::scenes::detail {

/// Uniform in [0, 1) with 53 random bits: two 32-bit draws, as in Matsumoto & Nishimura's
/// genrand_res53.
inline double uniform01(std::mt19937& rng)
{
    const double a = static_cast<double>(rng() >> 5);  // 27 bits
    const double b = static_cast<double>(rng() >> 6);  // 26 bits
    return (a * 67108864.0 + b) * (1.0 / 9007199254740992.0);
}

/// Uniform in [lo, hi).
inline double uniform(std::mt19937& rng, double lo, double hi)
{
    return lo + (hi - lo) * uniform01(rng);
}

}  // namespace pine::scenes::detail
