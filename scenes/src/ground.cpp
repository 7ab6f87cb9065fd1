#include "pine/scenes/scene.h"

#include <cmath>

namespace pine::scenes {

double Ground::heightAt(double x_cm, double y_cm) const
{
    if (kind != Kind::Hill) return height_cm;  // a plane; with no ground, trees still stand here
    // The Gaussian hill of Figure 10's scene: z = height + peak exp(-d^2 / (2 radius^2)).
    const double dx = x_cm - hillCentre_cm.x, dy = y_cm - hillCentre_cm.y;
    const double d2 = dx * dx + dy * dy;
    return height_cm + hillPeak_cm * std::exp(-d2 / (2.0 * hillRadius_cm * hillRadius_cm));
}

}  // namespace pine::scenes
