// A species: the L-system that grows its branches and the needle parameters of its boughs.
#pragma once

#include <algorithm>
#include <cmath>
#include <map>
#include <string>

namespace pine::scenes {

/// Needle parameters of a bough (paper section 3.1), linearly interpolated from the branch's
/// base (t = 0) to its tip (t = 1): "they change slowly along a branch".
struct NeedleParameters {
    double aperture_rad = 0.3927;  ///< phi
    double length_cm = 4.25;       ///< l
    double radius_cm = 0.05;       ///< r
    double perCone = 12;           ///< N
    double coneSpacing_cm = 0.9;   ///< dh
};

/// Parameters at fraction t in [0, 1] from a to b, each linearly.
NeedleParameters lerp(const NeedleParameters& a, const NeedleParameters& b, double t);

/// N as needles are drawn: whole needles a cone, at least one. Every method draws a bough with
/// its middle's N so (bake::boughGeometry), the explicit needles as the closed forms.
inline double wholeNeedles(double perCone)
{
    return std::max(1.0, std::round(perCone));
}

struct Species {
    // L-system (Prusinkiewicz & Lindenmayer) with a 3D turtle:
    //   F  segment of length `segment_cm`      [ ]  push / pop the turtle
    //   +  -  turn (yaw) by +-branchAngle       &  ^  pitch down / up by branchAngle
    //   /  \  roll by +-divergence             !    scale radius and length by the decays
    // Letters other than F are non-terminals the turtle ignores. A segment's order is the
    // bracket depth at which it is drawn (0 the trunk); '[' also scales the radius by
    // branchRadiusRatio, since a branch is thinner than the axis it grows from.
    // Deterministic: a stochastic choice (rules with alternatives) draws from the tree's seed.
    std::string axiom = "A";
    std::map<char, std::string> rules;
    int iterations = 5;
    double branchAngle_rad = 1.2;
    double divergence_rad = 2.4;   ///< roll between successive branches (phyllotaxis)
    double segment_cm = 10.0;
    double trunkRadius_cm = 3.0;
    double lengthDecay = 0.8;      ///< factor applied by '!'
    double radiusDecay = 0.7;
    double branchRadiusRatio = 1.0;  ///< factor applied to the radius by '[' (added)
    double jitter_rad = 0.1;       ///< random perturbation of each turn, from the seed

    NeedleParameters needlesAtBase, needlesAtTip;
    double barkAlbedo = 0.25;
    double needleAlbedo = 0.35;     ///< diffuse
    double needleSpecular = 0.1;    ///< weight of the specular term
    double specularExponent = 100;  ///< n
};

}  // namespace pine::scenes
