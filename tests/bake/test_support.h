// Shared by the bake tests: fresh temporary folders and boughs of the paper's parameters.
#pragma once

#include "pine/bake/layer_field.h"

#include <glm/geometric.hpp>

#include <stdlib.h>

#include <filesystem>
#include <stdexcept>
#include <string>

namespace pine::bake::test {

/// A fresh folder under the system's temporary directory, removed with its contents.
class TempDir {
public:
    TempDir()
    {
        std::string pattern =
            (std::filesystem::temp_directory_path() / "pine-bake-test-XXXXXX").string();
        if (!mkdtemp(pattern.data())) throw std::runtime_error("mkdtemp failed");
        mPath = pattern;
    }
    ~TempDir()
    {
        std::error_code ec;
        std::filesystem::remove_all(mPath, ec);
    }
    TempDir(const TempDir&) = delete;
    TempDir& operator=(const TempDir&) = delete;

    const std::filesystem::path& path() const { return mPath; }

private:
    std::filesystem::path mPath;
};

/// The paper's benchmark bough (section 7: N = 12, r = 0.05, l = 4.25, phi = pi/8, dh = 0.9;
/// R = 1.63 cm, A = 0.235) along `axis` from `base`, `length_cm` long.
inline BoughSpec paperBough(const Vec3& base, const Vec3& axis, double length_cm)
{
    BoughSpec b;
    b.base_cm = base;
    b.tip_cm = base + glm::normalize(axis) * length_cm;
    b.aperture_rad = 3.14159265358979323846 / 8;
    b.needleLength_cm = 4.25;
    b.needleRadius_cm = 0.05;
    b.needlesPerCone = 12;
    b.coneSpacing_cm = 0.9;
    b.needleAlbedo = Vec3(0.135, 0.3, 0.105);
    return b;
}

}  // namespace pine::bake::test
