// A directional light's shadow cones are parallel tubes. Walking the BVH from the far light down
// to the shaded point, each visited 94 nodes and 42 primitives on the paper forest, of which 2
// or 3 shade it. Here the primitives are binned once per frame by where their cylinders project
// on the plane across the light, each cell's nearest the light first: a cone reads the few
// cells its tube crosses, down to the point's depth, and keeps the primitives whose projected
// axis comes within reach of its own.
//
// Exact: a query yields every primitive the BVH query would yield that can shade the cone (a
// superset of those whose strip a shadow line meets over its footprint), in the order the BVH
// query yields them, so that each transmittance is the same product of the same factors.
#pragma once

#include "pine/vdbtrace/geometry.h"

#include <glm/geometric.hpp>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <vector>

namespace pine::vdbtrace {

class LightColumns {
public:
    /// A primitive as seen from the light: its axis from `base` to `end`, within `radius_cm` of
    /// which lies all it can shade with.
    struct Primitive {
        Vec3 base{0.0}, end{0.0};
        double radius_cm = 0.0;
    };
    /// Over `count` primitives, primitive(i) giving each (asked once), in `order`: rank i of
    /// Bvh::queryOrder, for light direction `towardsLight` (unit). Returns nothing if the
    /// columns would take more than `maxBytes`.
    static std::unique_ptr<LightColumns> build(std::size_t count,
                                               const std::function<Primitive(std::size_t)>& at,
                                               const std::vector<std::uint32_t>& order,
                                               const Vec3& towardsLight, std::size_t maxBytes);

    /// Calls visit(index) -> bool (false stops) for every primitive whose cylinder comes within
    /// `radius_cm` of the line through x along the light and reaches no farther from the light
    /// than `beyond_cm` past x, in the order Bvh::query visits them; and perhaps some others.
    template <class Visit>
    void query(const Vec3& x, double radius_cm, double beyond_cm, Visit&& visit) const;

    std::size_t bytes() const;

private:
    LightColumns() = default;
    // Where a primitive's axis projects across the light, and how far it reaches (rounded up).
    struct Shadow {
        float a[2], b[2];
        float radius;           ///< its radius, and the rounding of a and b to floats
        std::int32_t first[2];  ///< the first cell along each of the across directions
    };
    struct Entry {
        float depth;  ///< the nearest to the light any of it lies (rounded down)
        std::uint32_t rank;
    };
    double across(const Vec3& p, int k) const { return glm::dot(p, mAcross[k]); }
    double depth(const Vec3& p) const { return -glm::dot(p, mTowardsLight); }

    Vec3 mTowardsLight{0.0}, mAcross[2] = {Vec3(0.0), Vec3(0.0)};
    double mCell_cm = 1.0, mOrigin[2] = {0.0, 0.0};
    int mCells[2] = {0, 0};
    std::vector<std::uint32_t> mFirst;  ///< per cell, its entries' start; one more at the end
    std::vector<Entry> mEntries;
    std::vector<Shadow> mShadows;         ///< per rank
    std::vector<std::uint32_t> mIndexOf;  ///< per rank, the primitive
};

template <class Visit>
void LightColumns::query(const Vec3& x, double radius_cm, double beyond_cm, Visit&& visit) const
{
    const double p[2] = {across(x, 0), across(x, 1)};
    // The floats' rounding of where each primitive projects, and then some.
    const double slack = 1e-6 * (std::abs(p[0]) + std::abs(p[1]) + 1.0);
    int from[2], to[2];
    for (int k = 0; k < 2; ++k) {
        const double lo = (p[k] - radius_cm - slack - mOrigin[k]) / mCell_cm;
        const double hi = (p[k] + radius_cm + slack - mOrigin[k]) / mCell_cm;
        if (!(hi >= 0.0) || !(lo < double(mCells[k]))) return;
        from[k] = std::max(0, int(std::floor(lo)));
        to[k] = std::min(mCells[k] - 1, int(std::floor(hi)));
    }
    const double deepest = depth(x) + beyond_cm;
    thread_local std::vector<std::uint32_t> ranks;
    ranks.clear();
    for (int j = from[1]; j <= to[1]; ++j) {
        for (int i = from[0]; i <= to[0]; ++i) {
            const std::size_t cell = std::size_t(j) * std::size_t(mCells[0]) + std::size_t(i);
            for (std::uint32_t e = mFirst[cell]; e < mFirst[cell + 1]; ++e) {
                const Entry& entry = mEntries[e];
                if (double(entry.depth) > deepest) break;
                // The distance from x's line to the primitive's projected axis, squared.
                const Shadow& s = mShadows[entry.rank];
                const double ax = s.a[0], ay = s.a[1];
                const double dx = double(s.b[0]) - ax, dy = double(s.b[1]) - ay;
                const double length2 = dx * dx + dy * dy;
                double f = length2 > 0.0 ? ((p[0] - ax) * dx + (p[1] - ay) * dy) / length2 : 0.0;
                f = std::clamp(f, 0.0, 1.0);
                const double ex = ax + f * dx - p[0], ey = ay + f * dy - p[1];
                const double reach = double(s.radius) + radius_cm + slack;
                if (!(ex * ex + ey * ey <= reach * reach)) continue;
                // Once: from the first of the query's cells that the primitive is binned in.
                if (std::max(int(s.first[0]), from[0]) == i &&
                    std::max(int(s.first[1]), from[1]) == j) {
                    ranks.push_back(entry.rank);
                }
            }
        }
    }
    std::sort(ranks.begin(), ranks.end());
    for (const std::uint32_t rank : ranks) {
        if (!visit(mIndexOf[rank])) return;
    }
}

}  // namespace pine::vdbtrace
