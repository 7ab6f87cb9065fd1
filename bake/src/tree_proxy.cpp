#include "pine/bake/tree_proxy.h"

#include "pine/scenes/tree.h"

#include <glm/geometric.hpp>

#include <cmath>
#include <sstream>

namespace pine::bake {

TreeFrame treeFrame(const scenes::TreePlacement& placement)
{
    return {placement.base_cm, placement.rotation_rad};
}

Vec3 toFile(const Vec3& world_cm, const FileLayout& layout)
{
    const openvdb::Vec3d p =
        worldToFile(layout).transform(openvdb::Vec3d(world_cm.x, world_cm.y, world_cm.z));
    return Vec3(p.x(), p.y(), p.z());
}

namespace {

/// Two unit vectors across the axis a, completing it to a right-handed frame.
void across(const Vec3& a, Vec3& u, Vec3& v)
{
    const Vec3 helper = std::abs(a.z) < 0.9 ? Vec3(0, 0, 1) : Vec3(1, 0, 0);
    u = glm::normalize(glm::cross(helper, a));
    v = glm::cross(a, u);
}

}  // namespace

std::string branchMeshObj(const scenes::Tree& tree, const FileLayout& layout, int sides)
{
    if (sides < 3) throw BakeError("branch mesh: at least 3 sides, got " + std::to_string(sides));
    std::ostringstream obj;
    obj.precision(9);
    obj << "# trunk and branches of a tree, " << unitName(layout.unit) << ", "
        << (layout.treeFrame ? "tree" : "world") << " frame (written by bake)\n";
    obj << "o tree\n";
    const double kTwoPi = 6.283185307179586;
    const double unit = centimetresPer(layout.unit);
    std::size_t vertices = 0, normals = 0;
    int order = -1;
    for (const scenes::Segment& s : tree.segments) {
        const Vec3 p0 = toFile(s.base_cm, layout), p1 = toFile(s.tip_cm, layout);
        const double length = glm::length(p1 - p0);
        const double r = s.radius_cm / unit;
        if (!(length > 0.0) || !(r > 0.0)) continue;
        if (s.order != order) {
            order = s.order;
            obj << "g order_" << order << "\n";
        }
        const Vec3 a = (p1 - p0) / length;
        Vec3 u, v;
        across(a, u, v);
        for (int end = 0; end < 2; ++end) {
            for (int k = 0; k < sides; ++k) {
                const double t = kTwoPi * k / sides;
                const Vec3 p = (end ? p1 : p0) + r * (std::cos(t) * u + std::sin(t) * v);
                obj << "v " << p.x << ' ' << p.y << ' ' << p.z << '\n';
            }
        }
        for (int k = 0; k < sides; ++k) {
            const double t = kTwoPi * k / sides;
            const Vec3 n = std::cos(t) * u + std::sin(t) * v;
            obj << "vn " << n.x << ' ' << n.y << ' ' << n.z << '\n';
        }
        obj << "vn " << -a.x << ' ' << -a.y << ' ' << -a.z << '\n';
        obj << "vn " << a.x << ' ' << a.y << ' ' << a.z << '\n';
        const auto vi = [&](int end, int k) { return vertices + 1 + end * sides + (k % sides); };
        const auto ni = [&](int k) { return normals + 1 + (k % sides); };
        for (int k = 0; k < sides; ++k) {  // sides: counter-clockwise seen from outside
            obj << "f " << vi(0, k) << "//" << ni(k) << ' ' << vi(0, k + 1) << "//" << ni(k + 1)
                << ' ' << vi(1, k + 1) << "//" << ni(k + 1) << ' ' << vi(1, k) << "//" << ni(k)
                << '\n';
        }
        const std::size_t base = normals + sides + 1, tip = normals + sides + 2;
        obj << 'f';  // the base cap faces -a: clockwise about a
        for (int k = sides - 1; k >= 0; --k) obj << ' ' << vi(0, k) << "//" << base;
        obj << "\nf";
        for (int k = 0; k < sides; ++k) obj << ' ' << vi(1, k) << "//" << tip;
        obj << '\n';
        vertices += 2 * std::size_t(sides);
        normals += std::size_t(sides) + 2;
    }
    return obj.str();
}

nlohmann::json instanceList(const std::string& scene, LengthUnit unit,
                            const std::vector<ProxyInstance>& instances)
{
    const double u = centimetresPer(unit);
    nlohmann::json list = nlohmann::json::array();
    for (const ProxyInstance& in : instances) {
        const TreeFrame f = in.frame.value_or(TreeFrame{});
        const double c = std::cos(f.rotation_rad), s = std::sin(f.rotation_rad);
        const Vec3 t = f.base_cm / u;
        nlohmann::json entry = {
            {"tree", in.tree},
            {"grids", in.grids},
            {"mesh", in.mesh},
            {"species", in.species},
            {"seed", in.seed},
            {"translate", {t.x, t.y, t.z}},
            {"rotate_z_deg", f.rotation_rad * 180.0 / 3.141592653589793},
            {"tree_to_world",
             {{c, -s, 0.0, t.x}, {s, c, 0.0, t.y}, {0.0, 0.0, 1.0, t.z}, {0.0, 0.0, 0.0, 1.0}}}};
        list.push_back(entry);
    }
    return {{"format", "pine-instances"},
            {"version", 1},
            {"scene", scene},
            {"units", unitName(unit)},
            {"instances", list}};
}

}  // namespace pine::bake
