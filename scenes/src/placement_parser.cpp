// The "trees" section: explicit placements and seeded random scatters (the 80 firs of the
// paper's Figure 11 are a scatter). Keys, units, defaults and ranges: docs/scene-format.md.
#include "scene_sections.h"

#include "random.h"

#include "pine/scenes/tree.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <map>
#include <numbers>
#include <random>
#include <stdexcept>
#include <vector>

namespace pine::scenes::detail {
namespace {

constexpr double kRadPerDeg = std::numbers::pi / 180.0;
constexpr long long kMaxSeed = std::numeric_limits<std::uint32_t>::max();
constexpr long long kMaxScatterCount = 100'000;
constexpr int kScatterAttempts = 1000;  // per tree, before min_spacing is declared impossible

class PlacementReader {
public:
    explicit PlacementReader(const Scene& scene) : mScene(scene) {}

    std::string species(ObjectReader& r)
    {
        const std::string name = r.string("species");
        if (!mScene.species.count(name)) {
            std::string known;
            for (const auto& [n, s] : mScene.species) known += (known.empty() ? "" : ", ") + n;
            r.where().key("species").fail("unknown species \"" + name + "\" (defined: " +
                                          (known.empty() ? "none" : known) + ")");
        }
        return name;
    }

    /// A height to scale to needs a tree that grows upwards at all (a horizontal bough does
    /// not); checked once per species.
    void checkScalable(const std::string& name, const Where& where)
    {
        auto it = mHeights.find(name);
        if (it == mHeights.end()) {
            double h = 0.0;
            try {
                h = naturalHeight(mScene.species.at(name), 1);
            } catch (const std::exception& e) {
                where.fail(std::string("cannot grow species \"") + name + "\": " + e.what());
            }
            it = mHeights.emplace(name, h).first;
        }
        if (!(it->second > 1e-9)) {
            where.fail("species \"" + name +
                       "\" grows no height to scale (use 0 to keep its size)");
        }
    }

    TreePlacement placement(const Json& value, const Where& where)
    {
        ObjectReader r(value, where);
        TreePlacement p;
        p.species = species(r);
        const Json& position = r.required("position");
        const Where at = where.key("position");
        if (position.is_array() && position.size() == 2) {
            const Vec2 xy = readVec2(position, at);
            // No z: the trunk stands on the ground.
            p.base_cm = Vec3(xy, mScene.ground.heightAt(xy.x, xy.y));
        } else if (position.is_array() && position.size() == 3) {
            p.base_cm = readVec3(position, at);
        } else {
            at.fail("must be an array of 2 numbers (on the ground) or 3");
        }
        p.height_cm = r.number("height", Range::atLeast(0), 0.0);
        if (p.height_cm > 0.0) checkScalable(p.species, where.key("height"));
        p.rotation_rad = kRadPerDeg * r.number("rotation_deg", Range::any(), 0.0);
        if (const Json* seed = r.optional("seed")) {
            p.seed = static_cast<unsigned>(readInteger(*seed, where.key("seed"), 0, kMaxSeed));
        }
        r.finish();
        return p;
    }

    // Positions, heights, rotations and seeds all come, in that order per tree, from one
    // mt19937 seeded by the scatter's seed: the same file gives the same forest everywhere.
    void scatter(const Json& value, const Where& where, std::vector<TreePlacement>& out)
    {
        ObjectReader r(value, where);
        const std::string name = species(r);
        const auto count = readInteger(r.required("count"), where.key("count"), 0,
                                       kMaxScatterCount);

        const Json& region = r.required("region");
        const Where at = where.key("region");
        if (!region.is_array() || region.size() != 2) {
            at.fail("must be [[x0, y0], [x1, y1]]");
        }
        const Vec2 lo = readVec2(region[0], at.index(0)), hi = readVec2(region[1], at.index(1));
        if (lo.x > hi.x || lo.y > hi.y) at.fail("must have x0 <= x1 and y0 <= y1");
        // A tree is placed at x0 + u (x1 - x0): a width past a double's range places it at
        // infinity or NaN.
        if (!std::isfinite(hi.x - lo.x) || !std::isfinite(hi.y - lo.y)) {
            at.fail("is wider than a number can hold (x1 - x0 and y1 - y0 must be finite)");
        }

        double hMin = 0.0, hMax = 0.0;
        if (const Json* h = r.optional("height")) {
            const Where hw = where.key("height");
            if (h->is_array()) {
                const Vec2 range = readVec2(*h, hw);
                hMin = range.x;
                hMax = range.y;
                if (!(hMin > 0.0) || hMin > hMax) {
                    hw.fail("must be [min, max] with 0 < min <= max");
                }
            } else {
                hMin = hMax = readNumber(*h, hw, Range::atLeast(0));
            }
            if (hMax > 0.0) checkScalable(name, hw);
        }
        const double spacing = r.number("min_spacing", Range::atLeast(0), 0.0);
        unsigned seed = 1;
        if (const Json* s = r.optional("seed")) {
            seed = static_cast<unsigned>(readInteger(*s, where.key("seed"), 0, kMaxSeed));
        }
        // Trees drawn from this many variants (height, rotation, seed), each placed as a copy
        // of the first tree of its variant: instanced by the geometry method, grown once.
        long long variants = 0;  // 0: every tree its own
        if (const Json* v = r.optional("variants")) {
            variants = readInteger(*v, where.key("variants"), 1, std::max(1LL, count));
        }
        r.finish();

        std::mt19937 rng(seed);
        const std::size_t first = out.size();
        // Variants first, then each tree's position and variant, all from the one generator.
        std::vector<TreePlacement> drawn(static_cast<std::size_t>(variants));
        std::vector<long long> firstOf(drawn.size(), -1);
        for (TreePlacement& v : drawn) {
            v.species = name;
            v.height_cm = uniform(rng, hMin, hMax);
            v.rotation_rad = uniform(rng, 0.0, 2.0 * std::numbers::pi);
            v.seed = static_cast<unsigned>(rng());
        }
        for (long long i = 0; i < count; ++i) {
            Vec2 xy;
            for (int attempt = 0;; ++attempt) {
                if (attempt == kScatterAttempts) {
                    where.key("min_spacing")
                        .fail("cannot place " + std::to_string(count) + " trees " +
                              formatNumber(spacing) + " cm apart in the region (placed " +
                              std::to_string(i) + ")");
                }
                xy = Vec2(uniform(rng, lo.x, hi.x), uniform(rng, lo.y, hi.y));
                if (farFromOthers(xy, spacing, out, first)) break;
            }
            TreePlacement p;
            if (variants > 0) {
                const auto v = std::min(std::size_t(uniform(rng, 0.0, double(variants))),
                                        drawn.size() - 1);
                p = drawn[v];
                if (firstOf[v] < 0) {
                    firstOf[v] = static_cast<long long>(out.size());
                } else {
                    p.variantOf = firstOf[v];
                }
                p.base_cm = Vec3(xy, mScene.ground.heightAt(xy.x, xy.y));
                out.push_back(p);
                continue;
            }
            p.species = name;
            p.base_cm = Vec3(xy, mScene.ground.heightAt(xy.x, xy.y));
            p.height_cm = uniform(rng, hMin, hMax);
            p.rotation_rad = uniform(rng, 0.0, 2.0 * std::numbers::pi);
            p.seed = static_cast<unsigned>(rng());
            out.push_back(p);
        }
    }

private:
    static bool farFromOthers(const Vec2& xy, double spacing,
                              const std::vector<TreePlacement>& trees, std::size_t first)
    {
        for (std::size_t j = first; j < trees.size(); ++j) {
            const double dx = trees[j].base_cm.x - xy.x, dy = trees[j].base_cm.y - xy.y;
            if (dx * dx + dy * dy < spacing * spacing) return false;
        }
        return true;
    }

    const Scene& mScene;
    std::map<std::string, double> mHeights;  // natural height per species, for checkScalable
};

}  // namespace

std::vector<TreePlacement> readTrees(const Json& value, const Where& where, const Scene& scene)
{
    if (!value.is_array()) where.fail("must be an array of trees and scatters");
    PlacementReader reader(scene);
    std::vector<TreePlacement> trees;
    for (std::size_t i = 0; i < value.size(); ++i) {
        const Json& entry = value[i];
        const Where at = where.index(i);
        if (entry.is_object() && entry.contains("scatter")) {
            ObjectReader r(entry, at);
            reader.scatter(r.required("scatter"), at.key("scatter"), trees);
            r.finish();  // a scatter entry holds nothing else
        } else {
            trees.push_back(reader.placement(entry, at));
        }
    }
    return trees;
}

}  // namespace pine::scenes::detail
