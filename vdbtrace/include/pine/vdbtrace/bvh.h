// A bounding volume hierarchy over boxes (median split), queried by cone rays: each box is
// grown by the footprint's half-width at its far side, so no primitive the cone touches is
// missed. Each node also holds a ball about its box's centre holding its primitives' balls,
// so that a front-to-back query can visit them nearest first and stop where the pixel is
// opaque, never reaching what lies behind.
#pragma once

#include "pine/vdbtrace/geometry.h"

#include <glm/geometric.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <functional>
#include <limits>
#include <type_traits>
#include <vector>

namespace pine::vdbtrace {

/// What Bvh::nearestFirst has still to visit, kept by its caller so that no query allocates.
class NearestFirstQueue {
public:
    void clear() { mHeap.clear(); }
    /// A primitive of the caller's own (not in the BVH), visited in its turn.
    void add(double nearest, std::uint32_t index) { push({nearest, index, true}); }

private:
    friend class Bvh;
    struct Entry {
        double nearest;
        std::uint32_t index;  ///< a node or a primitive
        bool primitive;
    };
    // Visited later: farther, or as near and a primitive where the other is a node (whose
    // primitives may be as near), or of a larger index.
    static bool later(const Entry& a, const Entry& b)
    {
        if (a.nearest != b.nearest) return a.nearest > b.nearest;
        if (a.primitive != b.primitive) return a.primitive;
        return a.index > b.index;
    }
    void push(const Entry& e)
    {
        mHeap.push_back(e);
        std::push_heap(mHeap.begin(), mHeap.end(), later);
    }
    Entry pop()
    {
        std::pop_heap(mHeap.begin(), mHeap.end(), later);
        const Entry e = mHeap.back();
        mHeap.pop_back();
        return e;
    }
    std::vector<Entry> mHeap;
};

class Bvh {
public:
    Bvh() = default;
    /// Each primitive's ball is its box's circumscribed one.
    explicit Bvh(const std::vector<Aabb>& boxes);
    /// `balls[i]` holds what primitive i's nearest-first bound is taken over (nearestFirst).
    Bvh(const std::vector<Aabb>& boxes, const std::vector<Sphere>& balls);
    /// Over `count` primitives, bounds(i, box, ball) giving primitive i's box and ball as
    /// above, asked twice each: what the build keeps of each is its box's centre (24 bytes;
    /// a landscape's 6.6 million boxes and balls took 530 MB).
    using Bounds = std::function<void(std::size_t, Aabb&, Sphere&)>;
    Bvh(std::size_t count, const Bounds& bounds);

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

    /// Calls visit(index, nearest) for the primitives query(ray, tMax) would visit and those
    /// added to `queue` beforehand, in increasing order of nearest = nearestOf(index) (then of
    /// index), until visit returns false. nearestOf must bound no lower than
    /// nearestAlong(ray, ball) of the primitive's ball: then no primitive that comes later
    /// has a smaller bound, and the order is the one sorting them all would give. A primitive
    /// whose nearestOf is +infinity (the caller knows the ray misses it) is not visited.
    template <class NearestOf, class Visit>
    void nearestFirst(const ConeRay& ray, double tMax, NearestFirstQueue& queue,
                      NearestOf&& nearestOf, Visit&& visit) const
    {
        const Slabs slabs(ray);
        using Entry = NearestFirstQueue::Entry;
        const auto met = [&](std::uint32_t index, Entry& out) {
            const Node& node = mNodes[index];
            if (!slabs.meets(ray, node, tMax)) return false;
            out = {nearestAlong(ray, Sphere{node.centre(), node.ballRadius}), index, false};
            return true;
        };
        // The entry to visit next when it is known without the queue: the root first, then the
        // nearer child of the node just opened where nothing queued comes before it (the order
        // is strict: no two entries tie), saving its push and pop. Opening a node early only
        // queues its children sooner: the primitives are visited in the same order.
        Entry next{};
        bool held = !mNodes.empty() && met(0, next);
        while (held || !queue.mHeap.empty()) {
            const Entry e = held ? next : queue.pop();
            held = false;
            if (e.primitive) {
                if (!visit(e.index, e.nearest)) return;
                continue;
            }
            const Node& node = mNodes[e.index];
            if (node.count > 0) {
                for (std::uint32_t i = 0; i < node.count; ++i) {
                    const std::uint32_t index = mIndices[node.first + i];
                    const double nearest = nearestOf(index);
                    if (nearest != std::numeric_limits<double>::infinity()) {
                        queue.push({nearest, index, true});
                    }
                }
                continue;
            }
            Entry children[2];
            int n = 0;
            n += met(node.first, children[n]) ? 1 : 0;
            n += met(node.first + 1, children[n]) ? 1 : 0;
            if (n == 2) {
                if (NearestFirstQueue::later(children[0], children[1])) {
                    std::swap(children[0], children[1]);
                }
                queue.push(children[1]);
            }
            if (n > 0) {
                if (queue.mHeap.empty() ||
                    NearestFirstQueue::later(queue.mHeap.front(), children[0])) {
                    next = children[0];
                    held = true;
                } else {
                    queue.push(children[0]);
                }
            }
        }
    }

    /// The primitives in the order query() visits those it visits: ranks 0, 1, ... of a query
    /// that meets every node.
    std::vector<std::uint32_t> queryOrder() const;

    /// The root's box (rounded outwards to single precision).
    Aabb bounds() const;
    bool empty() const { return mNodes.empty(); }

private:
    /// 40 bytes, where double precision took 96 (a landscape indexes 6.6 million primitives):
    /// single precision rounded outwards, so that a node still holds what its primitives hold
    /// and bounds them no later than they bound themselves; both walks visit the same
    /// primitives in the same order.
    struct Node {
        float lo[3] = {0.0f, 0.0f, 0.0f}, hi[3] = {0.0f, 0.0f, 0.0f};  ///< the box
        float halfDiagonal = 0.0f;  ///< of the box, rounded up
        float ballRadius = 0.0f;    ///< about centre(), holding the primitives' balls
        std::uint32_t first = 0;    ///< leaf: first index; inner: first child
        std::uint32_t count = 0;    ///< leaf: number of primitives; inner: 0
        Vec3 centre() const
        {
            return 0.5 * (Vec3(lo[0], lo[1], lo[2]) + Vec3(hi[0], hi[1], hi[2]));
        }
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
                0.5 * ray.width(glm::length(node.centre() - ray.origin) + node.halfDiagonal);
            double t0 = 0.0, t1 = tMax;
            for (int i = 0; i < 3; ++i) {
                const double lo = node.lo[i] - margin, hi = node.hi[i] + margin;
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
    void build(const std::vector<Vec3>& centres, const Bounds& bounds, std::uint32_t node,
               std::uint32_t first, std::uint32_t count);
    /// Sets node `node`'s box (rounded outwards) and returns its centre.
    Vec3 setBox(std::uint32_t node, const Aabb& box);

    std::vector<Node> mNodes;
    std::vector<std::uint32_t> mIndices;
};

}  // namespace pine::vdbtrace
