#include "pine/vdbtrace/bvh.h"

#include <glm/geometric.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <stdexcept>

namespace pine::vdbtrace {

namespace {

std::size_t oneBallPerBox(const std::vector<Aabb>& boxes, const std::vector<Sphere>& balls)
{
    if (boxes.size() != balls.size()) {
        throw std::invalid_argument("Bvh: one ball per box is needed");
    }
    return boxes.size();
}

std::vector<Sphere> circumscribed(const std::vector<Aabb>& boxes)
{
    std::vector<Sphere> balls;
    balls.reserve(boxes.size());
    for (const Aabb& b : boxes) balls.push_back({b.centre(), 0.5 * glm::length(b.hi - b.lo)});
    return balls;
}

}  // namespace

Bvh::Bvh(const std::vector<Aabb>& boxes) : Bvh(boxes, circumscribed(boxes)) {}

Bvh::Bvh(const std::vector<Aabb>& boxes, const std::vector<Sphere>& balls)
    : Bvh(oneBallPerBox(boxes, balls), [&](std::size_t i, Aabb& box, Sphere& ball) {
          box = boxes[i];
          ball = balls[i];
      })
{
}

Bvh::Bvh(std::size_t count, const Bounds& bounds)
{
    if (count == 0) return;
    std::vector<Vec3> centres(count);
    for (std::size_t i = 0; i < count; ++i) {
        Aabb box;
        Sphere ball;
        bounds(i, box, ball);
        centres[i] = box.centre();
    }
    mIndices.resize(count);
    std::iota(mIndices.begin(), mIndices.end(), 0u);
    // A node of more than 4 splits into halves of at least 2, so there are at most N / 2
    // leaves and N - 1 nodes: reserving 2 N kept half the nodes' memory idle (a landscape's
    // 3.5 million primitives, about 300 MB).
    mNodes.reserve(count);
    mNodes.emplace_back();
    build(centres, bounds, 0, 0, std::uint32_t(count));
}

Vec3 Bvh::setBox(std::uint32_t node, const Aabb& box)
{
    Node& n = mNodes[node];
    for (int k = 0; k < 3; ++k) {
        n.lo[k] = roundedDown(box.lo[k]);
        n.hi[k] = roundedUp(box.hi[k]);
    }
    n.halfDiagonal = roundedUp(0.5 * glm::length(Vec3(n.hi[0], n.hi[1], n.hi[2]) -
                                                 Vec3(n.lo[0], n.lo[1], n.lo[2])) *
                               (1.0 + 1e-9));
    return n.centre();
}

// Fills node `node` (already allocated) for mIndices[first, first + count); an inner node's
// two children are allocated next to each other. The split is on the primitives' box
// centres; a node's box is its primitives' (its children's union), its ball holds its
// primitives' balls at a leaf and its children's balls above.
void Bvh::build(const std::vector<Vec3>& centres, const Bounds& bounds, std::uint32_t node,
                std::uint32_t first, std::uint32_t count)
{
    // Grown a little past rounding, so that the node's nearest-first bound never exceeds a
    // primitive's computed in floating point (a few ulps of scene-sized numbers).
    const auto setReach = [&](double reach) {
        mNodes[node].ballRadius = roundedUp(reach * (1.0 + 1e-9) + 1e-9);
    };
    if (count <= 4) {
        Aabb box;
        Sphere balls[4];
        for (std::uint32_t i = 0; i < count; ++i) {
            Aabb primitive;
            bounds(mIndices[first + i], primitive, balls[i]);
            box.grow(primitive);
        }
        const Vec3 centre = setBox(node, box);
        double reach = mNodes[node].halfDiagonal;
        for (std::uint32_t i = 0; i < count; ++i) {
            reach = std::max(reach, glm::length(balls[i].centre - centre) + balls[i].radius);
        }
        setReach(reach);
        mNodes[node].first = first;
        mNodes[node].count = count;
        return;
    }
    Aabb spread;  // of the centres
    for (std::uint32_t i = first; i < first + count; ++i) spread.grow(centres[mIndices[i]]);
    const Vec3 extent = spread.hi - spread.lo;
    const int axis = extent.x > extent.y ? (extent.x > extent.z ? 0 : 2)
                                         : (extent.y > extent.z ? 1 : 2);
    const std::uint32_t mid = first + count / 2;
    std::nth_element(mIndices.begin() + first, mIndices.begin() + mid,
                     mIndices.begin() + first + count, [&](std::uint32_t a, std::uint32_t b) {
                         return centres[a][axis] < centres[b][axis];
                     });
    const std::uint32_t left = std::uint32_t(mNodes.size());
    mNodes.emplace_back();
    mNodes.emplace_back();
    mNodes[node].first = left;
    mNodes[node].count = 0;
    build(centres, bounds, left, first, mid - first);
    build(centres, bounds, left + 1, mid, first + count - mid);
    Aabb box;
    for (const std::uint32_t child : {left, left + 1}) {
        const Node& c = mNodes[child];
        box.grow(Aabb{Vec3(c.lo[0], c.lo[1], c.lo[2]), Vec3(c.hi[0], c.hi[1], c.hi[2])});
    }
    const Vec3 centre = setBox(node, box);
    double reach = mNodes[node].halfDiagonal;
    for (const std::uint32_t child : {left, left + 1}) {
        const Node& c = mNodes[child];
        reach = std::max(reach, glm::length(c.centre() - centre) + double(c.ballRadius));
    }
    setReach(reach);
}

std::vector<std::uint32_t> Bvh::queryOrder() const
{
    std::vector<std::uint32_t> order;
    order.reserve(mIndices.size());
    if (mNodes.empty()) return order;
    std::vector<std::uint32_t> stack{0};
    while (!stack.empty()) {  // as query() walks, children pushed first then second
        const Node& node = mNodes[stack.back()];
        stack.pop_back();
        if (node.count > 0) {
            for (std::uint32_t i = 0; i < node.count; ++i) {
                order.push_back(mIndices[node.first + i]);
            }
        } else {
            stack.push_back(node.first);
            stack.push_back(node.first + 1);
        }
    }
    return order;
}

Aabb Bvh::bounds() const
{
    Aabb box;
    if (mNodes.empty()) return box;
    const Node& root = mNodes.front();
    box.lo = Vec3(root.lo[0], root.lo[1], root.lo[2]);
    box.hi = Vec3(root.hi[0], root.hi[1], root.hi[2]);
    return box;
}

}  // namespace pine::vdbtrace
