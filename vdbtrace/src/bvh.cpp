#include "pine/vdbtrace/bvh.h"

#include <glm/geometric.hpp>

#include <algorithm>
#include <numeric>
#include <stdexcept>

namespace pine::vdbtrace {

namespace {

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
{
    if (boxes.size() != balls.size()) {
        throw std::invalid_argument("Bvh: one ball per box is needed");
    }
    if (boxes.empty()) return;
    mIndices.resize(boxes.size());
    std::iota(mIndices.begin(), mIndices.end(), 0u);
    // A node of more than 4 splits into halves of at least 2, so there are at most N / 2
    // leaves and N - 1 nodes: reserving 2 N kept half the nodes' memory idle (a landscape's
    // 3.5 million primitives, about 300 MB).
    mNodes.reserve(boxes.size());
    mNodes.emplace_back();
    build(boxes, balls, 0, 0, std::uint32_t(boxes.size()));
}

// Fills node `node` (already allocated) for mIndices[first, first + count); an inner node's
// two children are allocated next to each other.
void Bvh::build(const std::vector<Aabb>& boxes, const std::vector<Sphere>& balls,
                std::uint32_t node, std::uint32_t first, std::uint32_t count)
{
    Aabb box, centres;
    for (std::uint32_t i = first; i < first + count; ++i) {
        box.grow(boxes[mIndices[i]]);
        centres.grow(boxes[mIndices[i]].centre());
    }
    mNodes[node].box = box;
    mNodes[node].centre = box.centre();
    mNodes[node].halfDiagonal = 0.5 * glm::length(box.hi - box.lo);
    double reach = mNodes[node].halfDiagonal;
    for (std::uint32_t i = first; i < first + count; ++i) {
        const Sphere& ball = balls[mIndices[i]];
        reach = std::max(reach, glm::length(ball.centre - box.centre()) + ball.radius);
    }
    // Grown a little past rounding, so that the node's nearest-first bound never exceeds a
    // primitive's computed in floating point (a few ulps of scene-sized numbers).
    mNodes[node].ballRadius = reach * (1.0 + 1e-9) + 1e-9;
    if (count <= 4) {
        mNodes[node].first = first;
        mNodes[node].count = count;
        return;
    }
    const Vec3 extent = centres.hi - centres.lo;
    const int axis = extent.x > extent.y ? (extent.x > extent.z ? 0 : 2)
                                         : (extent.y > extent.z ? 1 : 2);
    const std::uint32_t mid = first + count / 2;
    std::nth_element(mIndices.begin() + first, mIndices.begin() + mid,
                     mIndices.begin() + first + count, [&](std::uint32_t a, std::uint32_t b) {
                         return boxes[a].centre()[axis] < boxes[b].centre()[axis];
                     });
    const std::uint32_t left = std::uint32_t(mNodes.size());
    mNodes.emplace_back();
    mNodes.emplace_back();
    mNodes[node].first = left;
    mNodes[node].count = 0;
    build(boxes, balls, left, first, mid - first);
    build(boxes, balls, left + 1, mid, first + count - mid);
}

}  // namespace pine::vdbtrace
