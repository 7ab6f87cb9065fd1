// A tree as a proxy for other tools: its branch mesh (a closed, outward-facing solid of the
// cylinders the tracers draw, in the file's frame and unit), the instance list that places it
// back, and the digest a render checks grids against.
#include "pine/bake/tree_boughs.h"
#include "pine/bake/tree_proxy.h"
#include "pine/scenes/tree.h"

#include "test_support.h"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <map>
#include <sstream>
#include <utility>

namespace pine::bake {
namespace {

scenes::Tree twoSegments()
{
    scenes::Tree tree;
    tree.segments.push_back({Vec3(110.0, -40.0, 5.0), Vec3(110.0, -40.0, 305.0), 6.0, 0});
    tree.segments.push_back({Vec3(110.0, -40.0, 100.0), Vec3(160.0, -10.0, 120.0), 1.5, 1});
    return tree;
}

struct Mesh {
    std::vector<Vec3> vertices;
    std::vector<std::vector<std::size_t>> faces;  // 0-based vertex indices
};

/// A small OBJ reader of what branchMeshObj writes ("v", "f a//n ..."), independent of it.
Mesh parseObj(const std::string& text)
{
    Mesh mesh;
    std::istringstream in(text);
    std::string line;
    while (std::getline(in, line)) {
        std::istringstream l(line);
        std::string tag;
        l >> tag;
        if (tag == "v") {
            Vec3 v;
            l >> v.x >> v.y >> v.z;
            mesh.vertices.push_back(v);
        } else if (tag == "f") {
            std::vector<std::size_t> face;
            std::string corner;
            while (l >> corner) face.push_back(std::stoul(corner.substr(0, corner.find('/'))) - 1);
            mesh.faces.push_back(face);
        }
    }
    return mesh;
}

TEST(TreeProxy, TheBranchMeshIsAClosedOutwardSolidOfTheCylinders)
{
    const scenes::Tree tree = twoSegments();
    const int sides = 12;
    for (const FileLayout& layout :
         {FileLayout{LengthUnit::Centimetre, std::nullopt},
          FileLayout{LengthUnit::Metre, TreeFrame{Vec3(110.0, -40.0, 5.0), 0.9}}}) {
        const Mesh mesh = parseObj(branchMeshObj(tree, layout, sides));
        ASSERT_EQ(mesh.vertices.size(), 2u * 2u * sides);
        ASSERT_EQ(mesh.faces.size(), 2u * (sides + 2u));
        const double u = centimetresPer(layout.unit);
        // Closed: every directed edge appears once and its reverse once (consistent winding).
        std::map<std::pair<std::size_t, std::size_t>, int> edges;
        for (const auto& f : mesh.faces) {
            for (std::size_t i = 0; i < f.size(); ++i) edges[{f[i], f[(i + 1) % f.size()]}] += 1;
        }
        for (const auto& [edge, count] : edges) {
            EXPECT_EQ(count, 1);
            EXPECT_EQ(edges.count({edge.second, edge.first}), 1u);
        }
        // Volume by the divergence theorem: positive (outward) and that of two regular prisms.
        double volume = 0.0;
        for (const auto& f : mesh.faces) {
            for (std::size_t i = 1; i + 1 < f.size(); ++i) {
                volume += glm::dot(mesh.vertices[f[0]], glm::cross(mesh.vertices[f[i]],
                                                                    mesh.vertices[f[i + 1]])) /
                          6.0;
            }
        }
        double expected = 0.0;
        for (const scenes::Segment& s : tree.segments) {
            const double r = s.radius_cm / u, length = glm::length(s.tip_cm - s.base_cm) / u;
            expected += 0.5 * sides * std::sin(2.0 * 3.141592653589793 / sides) * r * r * length;
        }
        EXPECT_NEAR(volume, expected, 1e-6 * expected);
        // Each vertex lies on its segment's cylinder, mapped into the file's frame.
        for (std::size_t k = 0; k < mesh.vertices.size(); ++k) {
            const scenes::Segment& s = tree.segments[k / (2 * sides)];
            const Vec3 a = toFile(s.base_cm, layout), b = toFile(s.tip_cm, layout);
            const Vec3 axis = glm::normalize(b - a), d = mesh.vertices[k] - a;
            const double along = glm::dot(d, axis);
            EXPECT_NEAR(glm::length(d - along * axis), s.radius_cm / u, 1e-6 * s.radius_cm / u);
            EXPECT_TRUE(std::abs(along) < 1e-6 || std::abs(along - glm::length(b - a)) < 1e-6);
        }
        if (layout.treeFrame) {  // the trunk's base at the origin
            EXPECT_NEAR(glm::length(toFile(tree.segments[0].base_cm, layout)), 0.0, 1e-12);
        }
    }
}

TEST(TreeProxy, AFileFrameIsTheTreesBaseAndTurnInTheUnit)
{
    // toFile, written out apart: R(-turn) (p - base) / unit.
    const Vec3 base(110.0, -40.0, 5.0);
    for (const double turn : {0.0, 0.9, -2.4}) {
        const FileLayout layout{LengthUnit::Metre, TreeFrame{base, turn}};
        for (const Vec3 p : {Vec3(110.0, -40.0, 5.0), Vec3(160.0, -10.0, 120.0), Vec3(-3, 7, 1)}) {
            const Vec3 q = p - base;
            const Vec3 expected = Vec3(std::cos(turn) * q.x + std::sin(turn) * q.y,
                                       -std::sin(turn) * q.x + std::cos(turn) * q.y, q.z) /
                                  100.0;
            const Vec3 got = toFile(p, layout);
            for (int i = 0; i < 3; ++i) EXPECT_NEAR(got[i], expected[i], 1e-12);
        }
    }
    EXPECT_EQ(toFile(Vec3(1.0, 2.0, 3.0), FileLayout{LengthUnit::Centimetre, std::nullopt}),
              Vec3(1.0, 2.0, 3.0));
}

TEST(TreeProxy, TheInstanceListPutsEachTreeBackWhereTheSceneHasIt)
{
    const TreeFrame frame{Vec3(110.0, -40.0, 5.0), 2.2};
    const FileLayout layout{LengthUnit::Metre, frame};
    const nlohmann::json list = instanceList(
        "s.json", LengthUnit::Metre,
        {ProxyInstance{4, "tree_004.vdb", "tree_004.obj", "fir", 9, frame},
         ProxyInstance{5, "tree_005.vdb", "tree_005.obj", "fir", 9, std::nullopt}});
    EXPECT_EQ(list.at("units"), "m");
    ASSERT_EQ(list.at("instances").size(), 2u);
    const auto& placed = list.at("instances")[0];
    EXPECT_EQ(placed.at("grids"), "tree_004.vdb");
    EXPECT_NEAR(placed.at("rotate_z_deg").get<double>(), 2.2 * 180.0 / 3.141592653589793, 1e-12);
    for (const Vec3 world : {Vec3(0.0), Vec3(160.0, -10.0, 120.0), Vec3(-3.0, 7.0, 1.0)}) {
        const Vec3 p = toFile(world, layout);
        const auto& m = placed.at("tree_to_world");
        for (int i = 0; i < 3; ++i) {
            const double back = m[i][0].get<double>() * p.x + m[i][1].get<double>() * p.y +
                                m[i][2].get<double>() * p.z + m[i][3].get<double>();
            EXPECT_NEAR(back, world[i] / 100.0, 1e-12);
        }
    }
    const auto& unplaced = list.at("instances")[1].at("tree_to_world");
    for (int i = 0; i < 4; ++i) {
        for (int j = 0; j < 4; ++j) EXPECT_EQ(unplaced[i][j].get<double>(), i == j ? 1.0 : 0.0);
    }
}

TEST(TreeProxy, TheTreeDigestChangesWithAnyBough)
{
    const std::vector<BoughSpec> boughs = {
        test::paperBough(Vec3(0.0), Vec3(1, 0, 0), 10.0),
        test::paperBough(Vec3(0.0, 1.0, 0.0), Vec3(0, 1, 0), 12.0)};
    const std::string digest = treeDigest(boughs);
    EXPECT_EQ(digest.size(), 16u);
    EXPECT_EQ(treeDigest(boughs), digest);
    for (int change = 0; change < 4; ++change) {
        std::vector<BoughSpec> other = boughs;
        if (change == 0) other[1].tip_cm.z += 1e-9;
        if (change == 1) other[0].needles.cone.needlesPerCone = 13;
        if (change == 2) other[1].needleAlbedo.y = 0.31;
        if (change == 3) other.pop_back();
        EXPECT_NE(treeDigest(other), digest) << change;
    }
}

}  // namespace
}  // namespace pine::bake
