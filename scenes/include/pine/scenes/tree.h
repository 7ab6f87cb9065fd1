// A grown tree: trunk and branches as cylinders, each needle-bearing branch with its bough.
#pragma once

#include "pine/scenes/scene.h"

#include <cstddef>
#include <vector>

namespace pine::scenes {

/// A straight piece of trunk or branch, a cylinder (tapering ignored), in world cm.
struct Segment {
    Vec3 base_cm, tip_cm;
    double radius_cm = 0.1;
    int order = 0;  ///< 0 trunk, 1 branch of the trunk, 2 ...
};

/// The needle cylinder around one needle-bearing segment (paper section 3.1): its axis runs
/// from the segment's base to its tip, needles pointing towards the tip.
/// Needle parameters vary along a whole branch (all its segments drawn at one bracket depth,
/// base to tip), not per segment: atBase and atTip are that branch-wide interpolation sampled at
/// this segment's ends.
struct Bough {
    std::size_t segment = 0;   ///< index into Tree::segments
    NeedleParameters atBase;   ///< at the segment's base
    NeedleParameters atTip;    ///< at its tip
    /// Outer radius: the largest R = l sin(phi) along the bough.
    double radius_cm() const;
    /// Cones on the bough: its length over the mean cone spacing. The mean is the logarithmic
    /// one, which makes the count exact when dh varies linearly along the bough.
    double coneCount(double length_cm) const;
    /// Needles on the bough: its cones times its middle's N in whole needles (wholeNeedles),
    /// as every method draws them (added).
    double needleCount(double length_cm) const;
};

struct TreeCounts {
    std::size_t branches = 0;  ///< segments of order >= 1
    std::size_t boughs = 0;
    double cones = 0.0;
    double needles = 0.0;
};

struct Tree {
    std::vector<Segment> segments;
    std::vector<Bough> boughs;
    Vec3 boundsMin_cm{0.0}, boundsMax_cm{0.0};  ///< of segments and boughs
    const Species* species = nullptr;
    TreeCounts counts() const;
};

/// Grows a tree from its species' L-system and the placement's seed: the same inputs give the
/// same tree on every machine.
/// @note The placement's height scales the branch skeleton (positions and radii) so that the
/// highest segment end sits height_cm above the base; needles keep the species' sizes, so cone
/// and needle counts scale with the height. Throws std::invalid_argument when a height is asked
/// of a tree that grows no height (a horizontal bough) or the brackets do not balance, and
/// std::length_error when the L-system grows past kMaxLSystemLength symbols (lsystem.h).
/// loadScene rejects the last two, and a height for a species that grows none.
Tree growTree(const Species& species, const TreePlacement& placement);

/// A copy of `tree` moved by `offset_cm` (a scatter's variant placed at another base).
Tree movedBy(const Tree& tree, const Vec3& offset_cm);

/// Height of the unscaled tree (highest segment end above its base), in cm. (added)
double naturalHeight(const Species& species, unsigned seed);

}  // namespace pine::scenes
