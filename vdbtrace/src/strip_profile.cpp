#include "pine/vdbtrace/strip_profile.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace pine::vdbtrace {

StripProfile StripProfile::constant(double value)
{
    StripProfile p;
    p.mConstant = value;
    return p;
}

StripProfile StripProfile::sampled(std::span<const double> cells)
{
    if (cells.empty()) throw std::invalid_argument("a strip profile needs at least one cell");
    StripProfile p;
    const double width = 2.0 / double(cells.size());
    p.mPrefix.reserve(cells.size() + 1);
    p.mPrefix.push_back(0.0);
    for (double v : cells) p.mPrefix.push_back(p.mPrefix.back() + v * width);
    return p;
}

std::vector<double> StripProfile::cellValues() const
{
    std::vector<double> cells;
    const double width = mPrefix.empty() ? 0.0 : 2.0 / double(mPrefix.size() - 1);
    for (std::size_t k = 1; k < mPrefix.size(); ++k) {
        cells.push_back((mPrefix[k] - mPrefix[k - 1]) / width);
    }
    return cells;
}

double StripProfile::mean() const { return isConstant() ? mConstant : 0.5 * mPrefix.back(); }

double StripProfile::integralTo(double u) const
{
    const double cells = double(mPrefix.size() - 1);
    const double x = std::clamp(0.5 * (u + 1.0) * cells, 0.0, cells);
    const std::size_t k = std::min(std::size_t(x), mPrefix.size() - 2);
    return mPrefix[k] + (x - double(k)) * (mPrefix[k + 1] - mPrefix[k]);
}

double StripProfile::overFootprint(double gap, double halfWidth, double w) const
{
    if (isConstant()) return stripCoverage(gap, halfWidth, w) * mConstant;
    if (!(halfWidth > 0.0)) return 0.0;
    if (!(w > 0.0)) {
        if (!(std::abs(gap) < halfWidth)) return 0.0;
        const double cells = double(mPrefix.size() - 1);
        const std::size_t k =
            std::min(std::size_t(0.5 * (gap / halfWidth + 1.0) * cells), mPrefix.size() - 2);
        return (mPrefix[k + 1] - mPrefix[k]) * 0.5 * cells;
    }
    const double a = std::max(gap - 0.5 * w, -halfWidth), b = std::min(gap + 0.5 * w, halfWidth);
    if (!(b > a)) return 0.0;
    return (integralTo(b / halfWidth) - integralTo(a / halfWidth)) * halfWidth / w;
}

}  // namespace pine::vdbtrace
