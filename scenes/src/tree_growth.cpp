// The turtle that draws a species' L-system string into segments and boughs (section 3.1: "a
// tree is a set of branches and needles that we describe using an L-system").
#include "pine/scenes/lsystem.h"
#include "pine/scenes/tree.h"

#include "random.h"

#include <glm/geometric.hpp>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <stdexcept>
#include <vector>

namespace pine::scenes {
namespace {

// Rodrigues' rotation of v about the unit axis a by angle (right-handed).
Vec3 rotate(const Vec3& v, const Vec3& a, double angle_rad)
{
    const double c = std::cos(angle_rad), s = std::sin(angle_rad);
    return v * c + glm::cross(a, v) * s + a * (glm::dot(a, v) * (1.0 - c));
}

// The turtle's frame (ABOP's H, L, U with H x L = U), kept orthonormal: a thousand rotations
// in a row must not let it drift.
struct Frame {
    Vec3 heading{0.0, 0.0, 1.0};  // H: the trunk grows along +z
    Vec3 left{0.0, 1.0, 0.0};     // L
    Vec3 up{-1.0, 0.0, 0.0};      // U = H x L

    void orthonormalize()
    {
        heading = glm::normalize(heading);
        up = glm::normalize(glm::cross(heading, left));
        left = glm::cross(up, heading);
    }
    void yaw(double a)  // about U: '+' '-'
    {
        heading = rotate(heading, up, a);
        left = rotate(left, up, a);
        orthonormalize();
    }
    void pitch(double a)  // about L: '&' (a > 0 turns H away from U, "down") '^'
    {
        heading = rotate(heading, left, a);
        up = rotate(up, left, a);
        orthonormalize();
    }
    void roll(double a)  // about H: '/' '\'
    {
        left = rotate(left, heading, a);
        up = rotate(up, heading, a);
        orthonormalize();
    }
};

struct TurtleState {
    Vec3 position{0.0};
    Frame frame;
    double lengthScale = 1.0;
    double radius_cm = 0.0;
};

// The segments drawn at one bracket depth since its '[': one branch, whose needle parameters
// run from needlesAtBase at its first segment's base to needlesAtTip at its last one's tip.
struct OpenBranch {
    int order = 0;
    std::vector<std::size_t> segments;
};

class Turtle {
public:
    Turtle(const Species& species, unsigned seed) : mSpecies(species), mRng(seed)
    {
        mState.radius_cm = species.trunkRadius_cm;
        mBranches.push_back(OpenBranch{0, {}});
    }

    void draw(const std::string& program)
    {
        for (char c : program) step(c);
        if (!mStack.empty()) throw std::invalid_argument("L-system: unbalanced '['");
        closeBranch();
    }

    Tree finish()
    {
        std::sort(mTree.boughs.begin(), mTree.boughs.end(),
                  [](const Bough& a, const Bough& b) { return a.segment < b.segment; });
        return std::move(mTree);
    }

private:
    // A turn of `nominal` radians, perturbed uniformly within +-jitter from the tree's seed:
    // one draw per turn symbol, so the sequence of draws, and the tree, depend only on the seed.
    double turn(double nominal)
    {
        return nominal + mSpecies.jitter_rad * (2.0 * detail::uniform01(mRng) - 1.0);
    }

    void step(char c)
    {
        switch (c) {
        case 'F': {
            const double length = mSpecies.segment_cm * mState.lengthScale;
            const Vec3 tip = mState.position + mState.frame.heading * length;
            const int order = mBranches.back().order;
            mTree.segments.push_back(Segment{mState.position, tip, mState.radius_cm, order});
            mBranches.back().segments.push_back(mTree.segments.size() - 1);
            mState.position = tip;
            break;
        }
        case '[':
            mStack.push_back(mState);
            mState.radius_cm *= mSpecies.branchRadiusRatio;
            mBranches.push_back(OpenBranch{static_cast<int>(mStack.size()), {}});
            break;
        case ']':
            if (mStack.empty()) throw std::invalid_argument("L-system: unbalanced ']'");
            closeBranch();
            mState = mStack.back();
            mStack.pop_back();
            break;
        case '+': mState.frame.yaw(turn(mSpecies.branchAngle_rad)); break;
        case '-': mState.frame.yaw(turn(-mSpecies.branchAngle_rad)); break;
        case '&': mState.frame.pitch(turn(mSpecies.branchAngle_rad)); break;
        case '^': mState.frame.pitch(turn(-mSpecies.branchAngle_rad)); break;
        case '/': mState.frame.roll(turn(mSpecies.divergence_rad)); break;
        case '\\': mState.frame.roll(turn(-mSpecies.divergence_rad)); break;
        case '!':
            mState.lengthScale *= mSpecies.lengthDecay;
            mState.radius_cm *= mSpecies.radiusDecay;
            break;
        default: break;  // a non-terminal
        }
    }

    // Boughs for the branch just ended (order >= 1; the trunk carries none), each segment's
    // needle parameters interpolated by arc length along the whole branch.
    void closeBranch()
    {
        const OpenBranch branch = std::move(mBranches.back());
        mBranches.pop_back();
        if (branch.order < 1 || branch.segments.empty()) return;
        double total = 0.0;
        for (std::size_t i : branch.segments) total += segmentLength(i);
        double along = 0.0;
        for (std::size_t i : branch.segments) {
            const double length = segmentLength(i);
            const double t0 = total > 0.0 ? along / total : 0.0;
            along += length;
            const double t1 = total > 0.0 ? std::min(along / total, 1.0) : 1.0;
            const NeedleParameters& base = mSpecies.needlesAtBase;
            const NeedleParameters& tip = mSpecies.needlesAtTip;
            mTree.boughs.push_back(Bough{i, lerp(base, tip, t0), lerp(base, tip, t1)});
        }
    }

    double segmentLength(std::size_t i) const
    {
        const Segment& s = mTree.segments[i];
        return glm::length(s.tip_cm - s.base_cm);
    }

    const Species& mSpecies;
    std::mt19937 mRng;
    TurtleState mState;
    std::vector<TurtleState> mStack;
    std::vector<OpenBranch> mBranches;
    Tree mTree;
};

// The tree in its own frame: base at the origin, unscaled, unrotated.
Tree growLocal(const Species& species, unsigned seed)
{
    const std::string program =
        expandLSystem(species.axiom, species.rules, species.iterations, kMaxLSystemLength);
    Turtle turtle(species, seed);
    turtle.draw(program);
    return turtle.finish();
}

double topOf(const Tree& tree)
{
    double top = 0.0;
    for (const Segment& s : tree.segments) top = std::max({top, s.base_cm.z, s.tip_cm.z});
    return top;
}

// Box of the segments (cylinders) and boughs: every needle point lies within the needle length
// of its bough's axis, since needles start on the axis (section 3.1).
void computeBounds(Tree& tree, const Vec3& base)
{
    if (tree.segments.empty()) {
        tree.boundsMin_cm = tree.boundsMax_cm = base;
        return;
    }
    Vec3 lo(std::numeric_limits<double>::infinity()), hi(-lo);
    const auto add = [&](const Segment& s, double margin) {
        lo = glm::min(lo, glm::min(s.base_cm, s.tip_cm) - margin);
        hi = glm::max(hi, glm::max(s.base_cm, s.tip_cm) + margin);
    };
    for (const Segment& s : tree.segments) add(s, s.radius_cm);
    for (const Bough& b : tree.boughs) {
        add(tree.segments[b.segment], std::max(b.atBase.length_cm, b.atTip.length_cm));
    }
    tree.boundsMin_cm = lo;
    tree.boundsMax_cm = hi;
}

}  // namespace

double naturalHeight(const Species& species, unsigned seed)
{
    return topOf(growLocal(species, seed));
}

Tree growTree(const Species& species, const TreePlacement& placement)
{
    Tree tree = growLocal(species, placement.seed);
    double scale = 1.0;
    if (placement.height_cm > 0.0) {
        const double top = topOf(tree);
        // A height of 1e-9 cm is no height: scaling it up would blow rounding up with it.
        if (!(top > 1e-9)) {
            throw std::invalid_argument("growTree: species '" + placement.species +
                                        "' grows no height to scale to height_cm");
        }
        scale = placement.height_cm / top;
    }
    const double c = std::cos(placement.rotation_rad), s = std::sin(placement.rotation_rad);
    const auto toWorld = [&](const Vec3& p) {
        const Vec3 q = p * scale;
        return placement.base_cm + Vec3(c * q.x - s * q.y, s * q.x + c * q.y, q.z);
    };
    for (Segment& segment : tree.segments) {
        segment.base_cm = toWorld(segment.base_cm);
        segment.tip_cm = toWorld(segment.tip_cm);
        segment.radius_cm *= scale;
    }
    computeBounds(tree, placement.base_cm);
    tree.species = &species;
    // A forest's grown trees are all held while its boughs are made: no spare capacity (the
    // paper's fir's vectors had grown to 512 slots for 348 segments and 330 boughs).
    tree.segments.shrink_to_fit();
    tree.boughs.shrink_to_fit();
    return tree;
}

Tree movedBy(const Tree& tree, const Vec3& offset_cm)
{
    Tree moved = tree;
    for (Segment& segment : moved.segments) {
        segment.base_cm += offset_cm;
        segment.tip_cm += offset_cm;
    }
    moved.boundsMin_cm += offset_cm;
    moved.boundsMax_cm += offset_cm;
    return moved;
}

}  // namespace pine::scenes
