// A bounding volume hierarchy over boxes (median split), queried by cone rays: each box is
// grown by the footprint's half-width at its far side, so no primitive the cone touches is
// missed.
#pragma once

#include "pine/vdbtrace/geometry.h"

#include <glm/geometric.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <type_traits>
#include <vector>

namespace pine::vdbtrace {

class Bvh {
public:
    Bvh() = default;
    explicit Bvh(const std::vector<Aabb>& boxes);

    /// Calls visit(index) for every primitive whose box the cone may touch before tMax, in a
    /// fixed order. A visit that returns bool ends the query by returning false.
    template <class Visit>
    void query(const ConeRay& ray, double tMax, Visit&& visit) const
    {
        if (mNodes.empty()) return;
        const Slabs slabs(ray);
        std::uint32_t stack[64];
        int top = 0;
        stack[top++] = 0;
        while (top > 0) {
            const Node& node = mNodes[stack[--top]];
            if (!slabs.meets(ray, node, tMax)) continue;
            if (node.count > 0) {
                for (std::uint32_t i = 0; i < node.count; ++i) {
                    if constexpr (std::is_same_v<std::invoke_result_t<Visit, std::uint32_t>,
                                                 bool>) {
                        if (!visit(mIndices[node.first + i])) return;
                    } else {
                        visit(mIndices[node.first + i]);
                    }
                }
            } else if (top + 2 <= 64) {
                stack[top++] = node.first;
                stack[top++] = node.first + 1;
            }
        }
    }

    const Aabb& bounds() const { return mNodes.front().box; }
    bool empty() const { return mNodes.empty(); }

private:
    struct Node {
        Aabb box;
        Vec3 centre{0.0};           ///< of the box
        double halfDiagonal = 0.0;  ///< of the box
        std::uint32_t first = 0;    ///< leaf: first index; inner: first child
        std::uint32_t count = 0;    ///< leaf: number of primitives; inner: 0
    };
    /// A ray's slab test, its reciprocal direction computed once per query: the node's box
    /// grown by half the footprint's width at its far side (conservatively), entered before
    /// tMax.
    struct Slabs {
        Vec3 inverse{0.0};
        bool parallel[3] = {false, false, false};
        explicit Slabs(const ConeRay& ray)
        {
            for (int i = 0; i < 3; ++i) {
                parallel[i] = std::abs(ray.direction[i]) < 1e-300;
                inverse[i] = parallel[i] ? 0.0 : 1.0 / ray.direction[i];
            }
        }
        bool meets(const ConeRay& ray, const Node& node, double tMax) const
        {
            const double margin =
                0.5 * ray.width(glm::length(node.centre - ray.origin) + node.halfDiagonal);
            double t0 = 0.0, t1 = tMax;
            for (int i = 0; i < 3; ++i) {
                const double lo = node.box.lo[i] - margin, hi = node.box.hi[i] + margin;
                const double o = ray.origin[i];
                if (parallel[i]) {
                    if (o < lo || o > hi) return false;
                    continue;
                }
                double a = (lo - o) * inverse[i], b = (hi - o) * inverse[i];
                if (a > b) std::swap(a, b);
                t0 = std::max(t0, a);
                t1 = std::min(t1, b);
                if (t0 > t1) return false;
            }
            return true;
        }
    };
    void build(const std::vector<Aabb>& boxes, std::uint32_t node, std::uint32_t first,
               std::uint32_t count);

    std::vector<Node> mNodes;
    std::vector<std::uint32_t> mIndices;
};

}  // namespace pine::vdbtrace
