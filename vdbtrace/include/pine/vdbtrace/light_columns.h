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
#include <limits>
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
    /// columns would take more than `maxBytes`, or for 2^30 primitives or more.
    static std::unique_ptr<LightColumns> build(std::size_t count,
                                               const std::function<Primitive(std::size_t)>& at,
                                               const std::vector<std::uint32_t>& order,
                                               const Vec3& towardsLight, std::size_t maxBytes);

    /// Calls visit(index) -> bool (false stops) for every primitive whose cylinder comes within
    /// `radius_cm` (>= 0, else none) of the line through x along the light and reaches no
    /// farther from the light than `beyond_cm` past x, in the order Bvh::query visits them; and
    /// perhaps some others.
    /// A query that the last one this thread made of these columns holds (from the same point,
    /// no wider, a little deeper at most) reads the candidates that one gathered.
    template <class Visit>
    void query(const Vec3& x, double radius_cm, double beyond_cm, Visit&& visit) const;

    /// What a query yields, gathered afresh from the cells (the same primitives, the same
    /// order): for tests.
    template <class Visit>
    void queryCells(const Vec3& x, double radius_cm, double beyond_cm, Visit&& visit) const;

    std::size_t bytes() const;

private:
    LightColumns() = default;
    // Where a primitive's axis projects across the light, and how far it reaches (rounded up).
    struct Shadow {
        float a[2], b[2];
        float radius;  ///< its radius, and the rounding of a and b to floats
    };
    struct Entry {
        float depth;  ///< the nearest to the light any of it lies (rounded down)
        std::uint32_t rank : 30;
        /// Whether this cell is the primitive's first along each across direction: a query
        /// gathers a primitive from the first of its own cells that it reads, and this says
        /// which that is without reading the primitive's Shadow (most entries a query scans
        /// are primitives it meets again in another cell).
        std::uint32_t firstAlong0 : 1, firstAlong1 : 1;
    };
    // A primitive within reach of a neighbourhood: its Shadow's projection and its Entry's depth,
    // so that a query tests it as the cells would, without reading either again.
    struct Candidate {
        float a[2], b[2];
        float radius;
        float depth;
        std::uint32_t rank;
    };
    // The primitives within `reach_cm` (rounding of x included) of the line through `at` and no
    // deeper than `deepest`, by rank.
    struct Neighbourhood {
        std::uint64_t generation = 0;  ///< of the columns it was gathered from; 0: none
        double at[2] = {0.0, 0.0};
        double reach_cm = 0.0, deepest = 0.0;
        std::vector<Candidate> candidates;
    };
    // Candidates around p within `reach_cm` and no deeper than `deepest`, gathered into `out`.
    void gather(const double p[2], double reach_cm, double deepest, Neighbourhood& out) const;
    // This thread's neighbourhood holding p's query, gathered again if it does not.
    const Neighbourhood& around(const double p[2], double reach_cm, double deepest) const;
    // The floats' rounding of where each primitive projects, and then some, at p.
    static double slack(const double p[2])
    {
        return 1e-6 * (std::abs(p[0]) + std::abs(p[1]) + 1.0);
    }
    // Whether c's projected axis comes within reach_cm (c's radius added) of p.
    static bool within(const Candidate& c, const double p[2], double reach_cm)
    {
        const double ax = c.a[0], ay = c.a[1];
        const double dx = double(c.b[0]) - ax, dy = double(c.b[1]) - ay;
        const double length2 = dx * dx + dy * dy;
        // Where along the axis p comes nearest, clamped to its ends. Most candidates lie
        // beyond an end, where the quotient clamps to 0 or 1 anyway (division rounds
        // monotonically), so it is taken only between them; an infinite length (a float
        // overflowed) or a NaN divides, as it did.
        const double projected = (p[0] - ax) * dx + (p[1] - ay) * dy;
        double f = 0.0;
        if (length2 > 0.0) {
            const bool finite = length2 < std::numeric_limits<double>::infinity();
            if (finite && projected <= 0.0) {
                f = 0.0;
            } else if (finite && projected >= length2) {
                f = 1.0;
            } else {
                f = std::clamp(projected / length2, 0.0, 1.0);
            }
        }
        const double ex = ax + f * dx - p[0], ey = ay + f * dy - p[1];
        const double reach = double(c.radius) + reach_cm;
        return ex * ex + ey * ey <= reach * reach;
    }

    double across(const Vec3& p, int k) const { return glm::dot(p, mAcross[k]); }
    double depth(const Vec3& p) const { return -glm::dot(p, mTowardsLight); }

    Vec3 mTowardsLight{0.0}, mAcross[2] = {Vec3(0.0), Vec3(0.0)};
    double mCell_cm = 1.0, mOrigin[2] = {0.0, 0.0};
    int mCells[2] = {0, 0};
    std::vector<std::uint32_t> mFirst;  ///< per cell, its entries' start; one more at the end
    std::vector<Entry> mEntries;
    std::vector<Shadow> mShadows;         ///< per rank
    std::vector<std::uint32_t> mIndexOf;  ///< per rank, the primitive
    std::uint64_t mGeneration = 0;        ///< unique to these columns, never 0
};

template <class Visit>
void LightColumns::query(const Vec3& x, double radius_cm, double beyond_cm, Visit&& visit) const
{
    if (!(radius_cm >= 0.0)) return;
    const double p[2] = {across(x, 0), across(x, 1)};
    const double reach = radius_cm + slack(p), deepest = depth(x) + beyond_cm;
    // Each candidate tested as the cells' entries are: the same primitives, in rank order.
    for (const Candidate& c : around(p, reach, deepest).candidates) {
        if (double(c.depth) > deepest || !within(c, p, reach)) continue;
        if (!visit(mIndexOf[c.rank])) return;
    }
}

template <class Visit>
void LightColumns::queryCells(const Vec3& x, double radius_cm, double beyond_cm,
                              Visit&& visit) const
{
    if (!(radius_cm >= 0.0)) return;
    const double p[2] = {across(x, 0), across(x, 1)};
    Neighbourhood n;
    gather(p, radius_cm + slack(p), depth(x) + beyond_cm, n);
    for (const Candidate& c : n.candidates) {
        if (!visit(mIndexOf[c.rank])) return;
    }
}

}  // namespace pine::vdbtrace
