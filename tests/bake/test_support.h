// Shared by the bake tests: fresh temporary folders and boughs of the paper's parameters.
#pragma once

#include "../support/temp_dir.h"

#include "pine/analytic/bough_shader.h"
#include "pine/bake/layer_field.h"

#include <glm/geometric.hpp>

#include <stdlib.h>

#include <filesystem>
#include <stdexcept>
#include <string>

namespace pine::bake::test {

/// A fresh folder per test (tests/support/temp_dir.h), named for this suite.
class TempDir : public pine::test::TempDir {
public:
    TempDir() : pine::test::TempDir("pine-bake-test") {}
};

/// The paper's benchmark bough (section 7: N = 12, r = 0.05, l = 4.25, phi = pi/8, dh = 0.9;
/// R = 1.63 cm, A = 0.235) along `axis` from `base`, `length_cm` long.
inline BoughSpec paperBough(const Vec3& base, const Vec3& axis, double length_cm)
{
    BoughSpec b;
    b.base_cm = base;
    b.tip_cm = base + glm::normalize(axis) * length_cm;
    b.needles = analytic::paperBough();
    b.needleAlbedo = Vec3(0.135, 0.3, 0.105);
    return b;
}

}  // namespace pine::bake::test
