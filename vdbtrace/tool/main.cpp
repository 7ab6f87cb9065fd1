// vdbtrace: render a scene with the multiscale cone tracer, or benchmark it.
#include "pine/scenes/scene.h"
#include "pine/scenes/tree.h"
#include "pine/vdbtrace/image.h"
#include "pine/vdbtrace/multiscale_tracer.h"
#include "pine/vdbtrace/stats_json.h"
#include "pine/vdbtrace/traced_scene.h"

#include <CLI/CLI.hpp>
#include <tbb/global_control.h>
#include <tbb/task_arena.h>

#include <sys/resource.h>

#include <chrono>
#include <cstdio>
#include <iostream>
#include <memory>
#include <sstream>

namespace {

using namespace pine;
namespace fs = std::filesystem;

double peakMemoryMiB()
{
    rusage usage{};
    getrusage(RUSAGE_SELF, &usage);
    return double(usage.ru_maxrss) / 1024.0;  // Linux reports KiB
}

vdbtrace::RenderOptions withProgress(const std::string& what)
{
    vdbtrace::RenderOptions options;
    options.progress = [what](double fraction) {
        std::fprintf(stderr, "\rvdbtrace: %s %3d%%", what.c_str(), int(fraction * 100.0 + 0.5));
        std::fflush(stderr);
    };
    return options;
}

struct Loaded {
    scenes::Scene scene;
    vdbtrace::TracedScene traced;
};

std::unique_ptr<Loaded> load(const fs::path& file)
{
    auto loaded = std::make_unique<Loaded>();
    loaded->scene = scenes::loadScene(file);
    loaded->traced = vdbtrace::buildTracedScene(loaded->scene);
    return loaded;
}

std::string describe(const scenes::Scene& scene, const vdbtrace::TracedScene& traced)
{
    double needles = 0.0, branches = 0.0;
    for (const auto& tree : traced.trees) {
        needles += tree.counts().needles;
        branches += double(tree.counts().branches);
    }
    std::ostringstream s;
    s << scene.trees.size() << " trees, " << branches << " branches, " << needles << " needles";
    return s.str();
}

fs::path besideWith(const fs::path& image, const std::string& suffix)
{
    fs::path p = image;
    p.replace_extension();
    return p.string() + suffix;
}

int render(const fs::path& sceneFile, const std::string& method, const fs::path& out,
           const fs::path& statsFile, const std::vector<std::string>& aovs, int forceLevel)
{
    if (method != "multiscale") {
        std::cerr << "vdbtrace render: method '" << method
                  << "' is not available yet (only 'multiscale')\n";
        return 2;
    }
    vdbtrace::checkWritable(out);
    if (!statsFile.empty()) vdbtrace::checkWritable(statsFile);
    const auto loaded = load(sceneFile);
    std::cerr << "vdbtrace: " << sceneFile.string() << ": " << describe(loaded->scene, loaded->traced)
              << '\n';
    vdbtrace::RenderOptions options = withProgress("rendering");
    options.forceLevel = forceLevel;
    const vdbtrace::RenderResult result = vdbtrace::renderMultiscale(loaded->traced, options);
    std::cerr << '\n';

    const auto& s = loaded->scene;
    const nlohmann::json effects = vdbtrace::toJson(vdbtrace::EffectsPlan::from(s.effects));
    const vdbtrace::Metadata metadata = {
        {"pine:scene", sceneFile.string()},
        {"pine:method", method},
        {"pine:render_seconds", std::to_string(result.seconds)},
        {"pine:threads", std::to_string(tbb::this_task_arena::max_concurrency())},
        {"pine:effects", effects.dump()},
        {"pine:level_thresholds", "needle<" + std::to_string(s.render.needleLevelMax) +
                                      " cone<" + std::to_string(s.render.coneLevelMax) +
                                      " (footprint / cone spacing)"},
        {"pine:units", "cm"}};
    vdbtrace::writeExr(result.image, out, metadata);
    // The preview shows the scene's background behind what the cone did not cover.
    vdbtrace::Image preview = result.image;
    for (int y = 0; y < preview.height; ++y) {
        for (int x = 0; x < preview.width; ++x) {
            float* p = preview.pixel(x, y);
            for (int c = 0; c < 3; ++c) p[c] += (1.0f - p[3]) * float(s.render.background[c]);
            p[3] = 1.0f;
        }
    }
    vdbtrace::writePng(preview, besideWith(out, ".png"));
    for (const std::string& aov : aovs) {
        if (aov == "level") vdbtrace::writeLevelPng(result.image, besideWith(out, ".level.png"));
    }
    if (!statsFile.empty()) {
        nlohmann::json j = vdbtrace::toJson(result.stats);
        j["seconds"] = result.seconds;
        j["scene"] = sceneFile.string();
        j["method"] = method;
        j["effects"] = effects;
        j["resolution"] = {s.camera.width, s.camera.height};
        j["threads"] = tbb::this_task_arena::max_concurrency();
        vdbtrace::writeJsonAtomically(j, statsFile);
    }
    const auto& st = result.stats;
    std::cerr << "vdbtrace: " << out.string() << ": " << s.camera.width << "x" << s.camera.height
              << " in " << result.seconds << " s, " << st.coneRays << " cone rays, "
              << st.shadowRays << " shadow rays; pixels by level needle/cone/bough "
              << st.pixelsPerLevel[1] << "/" << st.pixelsPerLevel[2] << "/" << st.pixelsPerLevel[3]
              << '\n';
    return 0;
}

// Grows the trees (timed into `buildSeconds`), then renders: the result's `seconds` is the
// render alone.
vdbtrace::RenderResult timed(const scenes::Scene& scene, const std::string& label,
                             double* buildSeconds = nullptr)
{
    const auto start = std::chrono::steady_clock::now();
    const vdbtrace::TracedScene traced = vdbtrace::buildTracedScene(scene);
    if (buildSeconds) {
        *buildSeconds =
            std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    }
    vdbtrace::RenderResult r = vdbtrace::renderMultiscale(traced, withProgress(label));
    std::cerr << '\n';
    return r;
}

int bench(const fs::path& sceneFile, bool scaling)
{
    const scenes::Scene scene = scenes::loadScene(sceneFile);
    double buildSeconds = 0.0;
    const vdbtrace::RenderResult r = timed(scene, "bench", &buildSeconds);
    const auto& st = r.stats;
    const double pixels = double(st.coneRays);
    const auto share = [&](int level) { return double(st.pixelsPerLevel[level]) / pixels; };
    std::cout << "scene " << sceneFile.string() << " " << scene.camera.width << "x"
              << scene.camera.height << ", threads " << tbb::this_task_arena::max_concurrency()
              << "\nscene build seconds (trees grown, BVH, per-bough shading) " << buildSeconds
              << "\nrender seconds " << r.seconds << "\ncone rays per second " << pixels / r.seconds
              << "\npeak memory MiB " << peakMemoryMiB() << "\nshare of pixels: none "
              << share(0) << ", needle " << share(1) << ", cone " << share(2) << ", bough "
              << share(3) << '\n';
    if (!scaling) return 0;
    // Section 7: doubling N or halving dh must leave the cost of bough-level pixels unchanged.
    const auto perBoughPixel = [](const vdbtrace::RenderResult& x) {
        return x.stats.pixelsPerLevel[3]
                   ? double(x.stats.nanosecondsPerLevel[3]) / double(x.stats.pixelsPerLevel[3])
                   : 0.0;
    };
    scenes::Scene doubled = scene, halved = scene;
    for (auto& [name, sp] : doubled.species) {
        sp.needlesAtBase.perCone *= 2;
        sp.needlesAtTip.perCone *= 2;
    }
    for (auto& [name, sp] : halved.species) {
        sp.needlesAtBase.coneSpacing_cm /= 2;
        sp.needlesAtTip.coneSpacing_cm /= 2;
    }
    const vdbtrace::RenderResult d = timed(doubled, "N x 2");
    const vdbtrace::RenderResult h = timed(halved, "dh / 2");
    std::cout << "bough-level ns per pixel: base " << perBoughPixel(r) << ", N x 2 "
              << perBoughPixel(d) << ", dh / 2 " << perBoughPixel(h) << '\n';
    return 0;
}

}  // namespace

int main(int argc, char** argv)
{
    CLI::App app{"vdbtrace: the cone tracer of Meyer & Neyret's multiscale pine shaders"};
    app.require_subcommand(1);
    int threads = 0;
    app.add_option("--threads", threads, "Worker threads (default: all cores)")->check(CLI::NonNegativeNumber);

    fs::path sceneFile, out, statsFile;
    std::string method = "multiscale";
    std::vector<std::string> aovs;
    int forceLevel = 0;
    auto* renderCmd = app.add_subcommand("render", "Render a scene to EXR (+ PNG preview)");
    renderCmd->add_option("scene", sceneFile, "Scene file (JSON)")->required();
    renderCmd->add_option("--method", method, "multiscale (reference and geometry: later)");
    renderCmd->add_option("--out", out, "Output EXR; a PNG preview is written beside it")->required();
    renderCmd->add_option("--stats", statsFile, "Write render statistics as JSON");
    renderCmd->add_option("--aov", aovs, "Extra images: 'level' (Figure 12 false colours)")
        ->check(CLI::IsMember({"level"}));
    renderCmd->add_option("--force-level", forceLevel, "Shade every bough hit at level 1, 2 or 3")
        ->check(CLI::Range(0, 3));

    bool scaling = false;
    auto* benchCmd = app.add_subcommand("bench", "Time a render: seconds, cone rays/s, memory, levels");
    benchCmd->add_option("scene", sceneFile, "Scene file (JSON)")->required();
    benchCmd->add_flag("--scaling", scaling,
                       "Also render with N x 2 and dh / 2 (section 7's scaling claim)");

    try {
        app.parse(argc, argv);
    } catch (const CLI::ParseError& e) {
        if (e.get_exit_code() == 0) return app.exit(e);  // --help
        std::cerr << "vdbtrace: " << e.what() << " (see --help)\n";  // one line
        return 2;
    }
    std::unique_ptr<tbb::global_control> limit;
    if (threads > 0) {
        limit = std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism,
                                                      std::size_t(threads));
    }
    try {
        if (*renderCmd) return render(sceneFile, method, out, statsFile, aovs, forceLevel);
        return bench(sceneFile, scaling);
    } catch (const scenes::SceneError& e) {
        std::cerr << "vdbtrace: " << e.what() << '\n';
        return 2;
    } catch (const vdbtrace::ImageError& e) {
        std::cerr << "vdbtrace: " << e.what() << '\n';
        return 2;
    } catch (const std::exception& e) {
        std::cerr << "vdbtrace: " << e.what() << '\n';
        return 1;
    }
}
