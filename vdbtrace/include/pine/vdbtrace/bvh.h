// A bounding volume hierarchy over boxes (median split), queried by cone rays: each box is
// grown by the footprint's half-width at its far side, so no primitive the cone touches is
// missed. Primary cones walk it nearest first (queryNearestFirst), so that what lies behind
// an opaque composite is never reached.
#pragma once

#include "pine/vdbtrace/geometry.h"

#include <glm/geometric.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <stdexcept>
#include <type_traits>
#include <vector>

namespace pine::vdbtrace {

/// A ball holding a primitive (or a node's primitives).
struct Sphere {
    Vec3 centre{0.0};
    double radius = 0.0;
};

/// The least depth along the ray at which the cone can touch anything inside `s`: the
/// centre's depth less the radius, less the footprint's width at the ball's far side (wider
/// than the half-width the cone's edge needs).
inline double nearestDepth(const ConeRay& ray, const Sphere& s)
{
    const double centre = glm::dot(s.centre - ray.origin, ray.direction);
    return centre - s.radius - ray.width(std::max(0.0, centre + s.radius));
}

class Bvh {
public:
    Bvh() = default;
    /// `spheres` (one per box, or none): what queryNearestFirst orders the primitives by.
    explicit Bvh(const std::vector<Aabb>& boxes, std::vector<Sphere> spheres = {});

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

    /// A node or primitive waiting in queryNearestFirst's queue.
    struct Pending {
        double nearest;      ///< nearestDepth of its ball
        std::uint32_t index;  ///< node or primitive
        bool primitive;
    };

    /// Calls visit(nearest, index) for the primitives query() would visit, in increasing
    /// (nearest, index), nearest = nearestDepth(ray, its sphere), until visit returns false.
    /// Nodes wait in the same queue under their ball's nearest depth, which no primitive below
    /// them is nearer than, so a primitive is visited only once none nearer can remain: a
    /// front-to-back composite that turns opaque stops the walk where it is. `queue`: the
    /// caller's scratch (one per thread). Needs the spheres.
    template <class Visit>
    void queryNearestFirst(const ConeRay& ray, double tMax, std::vector<Pending>& queue,
                           Visit&& visit) const
    {
        queue.clear();
        if (mNodes.empty()) return;
        if (mSpheres.empty()) throw std::logic_error("Bvh: walked nearest first without spheres");
        const Slabs slabs(ray);
        // A min-queue: the nearest first; at equal depth a node before a primitive (it may
        // hold one of equal depth and lower index), primitives by index.
        const auto later = [](const Pending& a, const Pending& b) {
            if (a.nearest != b.nearest) return a.nearest > b.nearest;
            if (a.primitive != b.primitive) return a.primitive;
            return a.index > b.index;
        };
        const auto push = [&](const Pending& p) {
            queue.push_back(p);
            std::push_heap(queue.begin(), queue.end(), later);
        };
        const auto pushNode = [&](std::uint32_t n) {
            const Node& node = mNodes[n];
            if (slabs.meets(ray, node, tMax)) {
                push({nearestDepth(ray, {node.centre, node.reach}), n, false});
            }
        };
        pushNode(0);
        while (!queue.empty()) {
            std::pop_heap(queue.begin(), queue.end(), later);
            const Pending p = queue.back();
            queue.pop_back();
            if (p.primitive) {
                if (!visit(p.nearest, p.index)) return;
                continue;
            }
            const Node& node = mNodes[p.index];
            if (node.count > 0) {
                for (std::uint32_t i = 0; i < node.count; ++i) {
                    const std::uint32_t k = mIndices[node.first + i];
                    push({nearestDepth(ray, mSpheres[k]), k, true});
                }
            } else {
                pushNode(node.first);
                pushNode(node.first + 1);
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
        double reach = 0.0;  ///< radius of a ball about `centre` holding its primitives' balls
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
    double reachOf(const Vec3& centre, std::uint32_t first, std::uint32_t count) const;

    std::vector<Node> mNodes;
    std::vector<std::uint32_t> mIndices;
    std::vector<Sphere> mSpheres;  ///< per primitive; empty without queryNearestFirst
};

}  // namespace pine::vdbtrace
