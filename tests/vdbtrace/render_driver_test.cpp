// The render loop every method shares, driven by a method whose fragments are known: what a
// pixel's RGBA and AOVs mean, whatever method supplied them.
#include "pine/vdbtrace/render_driver.h"
#include "pine/scenes/scene.h"
#include "pine/vdbtrace/progress_steps.h"

#include <gtest/gtest.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <mutex>
#include <vector>

#include <limits>

#include <cmath>

namespace pine::vdbtrace {
namespace {

// Four samples a pixel; sample s of pixel (x, y) meets the fragments `script` gives it.
class ScriptedMethod final : public ShadingMethod {
public:
    using Script = std::function<void(int x, int s, FrontToBack&)>;
    explicit ScriptedMethod(Script script) : mScript(std::move(script)) {}
    int samplesPerPixel() const override { return 4; }
    ConeRay sample(const ConeCamera&, int x, int, int s) const override
    {
        ConeRay r;
        r.origin = Vec3(double(x), double(s), 0.0);  // the tracer reads x and s back
        return r;
    }
    std::unique_ptr<RayTracer> rayTracer(RenderStats&) const override
    {
        struct Tracer final : RayTracer {
            const Script& script;
            explicit Tracer(const Script& s) : script(s) {}
            void trace(const ConeRay& ray, FrontToBack& composite) override
            {
                script(int(ray.origin.x), int(ray.origin.y), composite);
            }
        };
        return std::make_unique<Tracer>(mScript);
    }

private:
    Script mScript;
};

struct Frame {
    scenes::Scene scene;
    TracedScene traced;
    Frame()
    {
        scene = scenes::parseScene(R"({"name": "driver",
  "camera": {"position": [0, 0, 0], "look_at": [0, 1, 0], "up": [0, 0, 1], "fov_deg": 30,
             "resolution": [4, 2]},
  "lights": [{"type": "directional", "direction": [0, 0, 1]}], "ground": {"type": "none"},
  "species": {}, "trees": [], "effects": ["diffuse"]})",
                                   "driver.json");
        traced = buildTracedScene(scene);
    }
};

Fragment opaque(double t, double diffuse, int level, bool foliage)
{
    return Fragment{t, 1.0, Vec3(diffuse), Vec3(0.0), level, foliage};
}

TEST(RenderDriver, PixelIsTheMeanOfItsSamplesAndDepthWhereCoveragePassesHalf)
{
    // Pixel column x: x + 1 of the four samples meet an opaque fragment at t = 10 + s, the rest
    // nothing. Coverage passes 1/2 at the second-nearest hit when two or more hit.
    Frame f;
    const ScriptedMethod method([](int x, int s, FrontToBack& c) {
        if (s <= x) c.add(opaque(10.0 + s, 0.5, 2, true));
    });
    const RenderResult r = renderImage(f.traced, method, {});
    for (int x = 0; x < 4; ++x) {
        const double covered = (x + 1) / 4.0;
        EXPECT_FLOAT_EQ(r.image.pixel(x, 1)[3], float(covered));
        EXPECT_FLOAT_EQ(r.image.pixel(x, 1)[1], float(0.5 * covered));
        EXPECT_FLOAT_EQ(r.image.aovs.at("foliage")[std::size_t(4 + x)], float(covered));
        EXPECT_FLOAT_EQ(r.image.aovs.at("level")[std::size_t(4 + x)], 2.0f);
        // Not the mean of the samples' depths (a half-covered pixel at half the distance).
        // Where coverage never passes 1/2 there is no depth: infinitely far.
        EXPECT_EQ(r.image.aovs.at("depth")[std::size_t(4 + x)],
                  x == 0 ? std::numeric_limits<float>::infinity() : 11.0f)
            << "column " << x;
    }
    EXPECT_EQ(r.stats.coneRays, 4u * 8u);
    EXPECT_EQ(r.stats.pixelsPerLevel[2], 8u);  // every pixel, counted by its dominant level
}

TEST(RenderDriver, EveryPixelIsCountedByLevelEvenWithoutLevels)
{
    // The reference and geometry shade no level: their pixels count as level 0, so the counts
    // by level always sum to the pixels.
    Frame f;
    const ScriptedMethod method([](int, int, FrontToBack& c) { c.add(opaque(5.0, 0.2, 0, true)); });
    const RenderResult r = renderImage(f.traced, method, {});
    EXPECT_EQ(r.stats.pixelsPerLevel[0], 8u);
    for (const float level : r.image.aovs.at("level")) EXPECT_EQ(level, 0.0f);
}

TEST(RenderDriver, RadianceTooLargeForAFloatIsAnErrorNotAPixel)
{
    // The scene format bounds a light (scenes::kMaxLightValue), but a point light's 1 / d^2
    // near a surface is not bounded: a radiance past float's range is refused after the
    // render, naming how many values, never written as an infinite pixel.
    Frame f;
    const ScriptedMethod method(
        [](int x, int, FrontToBack& c) { c.add(opaque(5.0, x == 3 ? 1e39 : 0.5, 2, true)); });
    try {
        (void)renderImage(f.traced, method, {});
        ADD_FAILURE() << "an overflowed render was returned";
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("radiance overflowed: 6 pixel values"),
                  std::string::npos)
            << e.what();
    }
}

TEST(ProgressSteps, EachStepIsToldOnceEndingAtTheWhole)
{
    // Units finished on every thread, told in 50 steps: no step twice, the last at 1, and a
    // unit that finishes no new step tells nothing.
    for (const std::size_t total : {std::size_t(1000), std::size_t(7)}) {
        ProgressSteps steps(total, 50);
        std::mutex mutex;
        std::vector<double> told;
        tbb::parallel_for(std::size_t(0), total, [&](std::size_t) {
            double fraction;
            if (!steps.finished(fraction)) return;
            const std::lock_guard<std::mutex> lock(mutex);
            told.push_back(fraction);
        });
        ASSERT_FALSE(told.empty());
        EXPECT_LE(told.size(), std::min<std::size_t>(total, 50)) << total;
        EXPECT_EQ(*std::max_element(told.begin(), told.end()), 1.0) << total;
        std::vector<int> stepsTold;
        for (const double f : told)
            stepsTold.push_back(int(std::lround(f * double(total))) * 50 / int(total));
        std::sort(stepsTold.begin(), stepsTold.end());
        EXPECT_EQ(std::adjacent_find(stepsTold.begin(), stepsTold.end()), stepsTold.end())
            << "a step told twice";
    }
}

TEST(FrontToBack, CompositesOverInOrder)
{
    FrontToBack c;
    c.add(Fragment{1.0, 0.5, Vec3(0.25), Vec3(0.0), 1, true});
    c.add(Fragment{2.0, 0.5, Vec3(0.5), Vec3(0.1), 3, true});
    c.add(Fragment{3.0, 1.0, Vec3(0.1), Vec3(0.0), 0, false});
    const SampleValue v = c.value();
    EXPECT_DOUBLE_EQ(v.alpha, 1.0);
    EXPECT_DOUBLE_EQ(v.diffuse.x, 0.25 + 0.5 * 0.5 + 0.25 * 0.1);
    EXPECT_DOUBLE_EQ(v.specular.x, 0.5 * 0.1);
    EXPECT_DOUBLE_EQ(v.foliage, 0.75);
    EXPECT_DOUBLE_EQ(v.levelWeight[1], 0.5);
    EXPECT_DOUBLE_EQ(v.levelWeight[3], 0.25);
    EXPECT_DOUBLE_EQ(v.depth, 1.0);  // the first fragment brings coverage to 1/2
    EXPECT_TRUE(c.opaque());
}

}  // namespace
}  // namespace pine::vdbtrace
