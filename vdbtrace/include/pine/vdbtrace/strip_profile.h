// A quantity across a bough's strip, the band of width 2R a bough covers on the screen: a
// bough law's opacity or transfer as a function of the chord's signed offset xi from the axis
// (a chord through the axis crosses far more layers than one near the edge), read as its mean
// over a pixel's footprint, which is how the pixel sees it.
#pragma once

#include "pine/vdbtrace/geometry.h"

#include <cstddef>
#include <span>
#include <vector>

namespace pine::vdbtrace {

class StripProfile {
public:
    /// 0 everywhere.
    StripProfile() = default;
    /// `value` across the whole strip (the paper's laws: one value for the strip).
    static StripProfile constant(double value);
    /// cells[k] at the centre of cell k of equal cells over xi in [-R, R], in order of xi;
    /// read as piecewise constant. Throws std::invalid_argument for no cells.
    static StripProfile sampled(std::span<const double> cells);

    bool isConstant() const { return mPrefix.empty(); }
    /// A sampled profile's cells, as given to sampled(); none for a constant.
    std::vector<double> cellValues() const;
    /// What it holds beyond itself, in bytes.
    std::size_t heapBytes() const { return mPrefix.capacity() * sizeof(double); }
    /// The mean over the strip.
    double mean() const;
    /// (1 / w) times the integral of the value over the footprint [gap - w/2, gap + w/2]
    /// intersected with the strip [-R, R], R = halfWidth: the footprint's coverage times the
    /// mean value over what it covers. For a constant: stripCoverage(gap, R, w) * value. A
    /// footprint of no width reads the value at gap.
    double overFootprint(double gap, double halfWidth, double w) const;

private:
    double integralTo(double u) const;  ///< int_-1^u of the value, u = xi / R in [-1, 1]

    double mConstant = 0.0;
    std::vector<double> mPrefix;  ///< int_-1^u at the cell edges u_k = -1 + 2 k / K
};

/// A bough's two halves across its strip.
struct FrontRearProfile {
    StripProfile front, rear;
};

}  // namespace pine::vdbtrace
