// A bounding volume hierarchy over boxes (median split), queried by cone rays: each box is
// grown by the footprint's half-width at its far side, so no primitive the cone touches is
// missed.
#pragma once

#include "pine/vdbtrace/geometry.h"

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
        std::uint32_t stack[64];
        int top = 0;
        stack[top++] = 0;
        while (top > 0) {
            const Node& node = mNodes[stack[--top]];
            double tIn, tOut;
            if (!intersectBox(ray, node.box, margin(ray, node.box), tMax, tIn, tOut)) continue;
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
        std::uint32_t first = 0;  ///< leaf: first index; inner: first child
        std::uint32_t count = 0;  ///< leaf: number of primitives; inner: 0
    };
    /// Half the footprint's width at the box's far side (conservatively).
    static double margin(const ConeRay& ray, const Aabb& box);
    void build(const std::vector<Aabb>& boxes, std::uint32_t node, std::uint32_t first,
               std::uint32_t count);

    std::vector<Node> mNodes;
    std::vector<std::uint32_t> mIndices;
};

}  // namespace pine::vdbtrace
