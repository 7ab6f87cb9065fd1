// One voxel standing for many values of extinction: the points of a voxel wider than R / 4
// (bake_boughs.cpp) or the children of a density level's voxel (density_pyramid.cpp). It holds
// the extinction whose opacity over its mean chord is their mean opacity, so that it lets
// through as much light as they do on average, where their mean would cover more (1 - exp(-x)
// is concave). Private to bake/.
#pragma once

#include <algorithm>
#include <cmath>

namespace pine::bake::detail {

/// The mean chord of a cube under isotropic lines, 4 V / S = 2/3 of its size (Cauchy).
constexpr double kMeanChordOverSize = 2.0 / 3.0;

/// 1 - exp(-sigma l): what an extinction stops over the chord l.
inline double opacityOver(double extinction, double chord)
{
    return -std::expm1(-extinction * chord);
}

/// The extinction that stops `opacity` over the chord l; an opacity that rounds to 1 stays
/// finite (27.6 / l).
inline double extinctionStopping(double opacity, double chord)
{
    return -std::log1p(-std::min(opacity, 1.0 - 1e-12)) / chord;
}

}  // namespace pine::bake::detail
