#include "pine/vdbtrace/compare.h"

#include "pine/bake/tree_boughs.h"
#include "pine/scenes/scene.h"
#include "pine/support/atomic_file.h"
#include "pine/vdbtrace/flicker.h"
#include "pine/vdbtrace/geometry_tracer.h"
#include "pine/vdbtrace/image_diff.h"
#include "pine/vdbtrace/multiscale_tracer.h"
#include "pine/vdbtrace/preview.h"
#include "pine/vdbtrace/reference_tracer.h"
#include "pine/vdbtrace/stats_json.h"
#include "pine/vdbtrace/traced_scene.h"

#include <tbb/task_arena.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <optional>
#include <random>
#include <sstream>
#include <thread>
#include <utility>

namespace pine::vdbtrace {
namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

double since(Clock::time_point start)
{
    return std::chrono::duration<double>(Clock::now() - start).count();
}

/// One render of the sweep and its error against the ground truth.
struct Row {
    Row(std::string m, std::string s) : method(std::move(m)), setting(std::move(s)) {}
    std::string method, setting;
    double seconds = 0.0;
    std::optional<double> prepSeconds;  ///< geometry's BVH, the reference's bake (in `seconds`)
    Image image;
    ImageErrors errors;
    bool truth = false;
    std::string stem() const { return method + "_" + setting; }
};

std::string num(double v, int digits = 4)
{
    std::ostringstream s;
    s << std::setprecision(digits) << v;
    return s.str();
}

std::string cpuModel()
{
    std::ifstream in("/proc/cpuinfo");
    std::string line;
    while (std::getline(in, line)) {
        if (line.rfind("model name", 0) == 0) {
            const auto colon = line.find(':');
            if (colon != std::string::npos) {
                return line.substr(line.find_first_not_of(' ', colon + 1));
            }
        }
    }
    return "unknown CPU";
}

fs::path plotScript()
{
    if (const char* env = std::getenv("PINE_PLOT_SCRIPT")) return env;
    return fs::path(PINE_SOURCE_DIR) / "scripts" / "plot_compare.py";
}

void progress(const Row& row)
{
    std::cerr << "vdbtrace compare: " << row.method << " " << row.setting << ": "
              << num(row.seconds, 3) << " s";
    if (row.prepSeconds) std::cerr << " (" << num(*row.prepSeconds, 3) << " s preparation)";
    if (!row.truth) std::cerr << ", rmse " << num(row.errors.rmse);
    std::cerr << '\n';
}

Row renderGeometryRow(const TracedScene& traced, int samples, const std::string& method)
{
    Row row{method, std::to_string(samples) + "spp"};
    GeometryOptions options;
    options.samples = samples;
    double bvh = 0.0;
    options.built = [&bvh](const GeometryBuild& b) { bvh = b.seconds; };
    const auto start = Clock::now();
    row.image = renderGeometry(traced, options).image;
    row.seconds = since(start);
    row.prepSeconds = bvh;
    return row;
}

Row renderReferenceRow(const TracedScene& traced, double voxel_cm, int subpixels)
{
    Row row{"reference", num(voxel_cm) + "cm"};
    const auto start = Clock::now();
    const bake::TreeGrids grids = bake::bakeScene(traced.trees, referenceBake(voxel_cm));
    row.prepSeconds = since(start);
    ReferenceOptions options;
    options.subpixels = subpixels;
    row.image = renderReference(traced, grids, options).image;
    row.seconds = since(start);
    return row;
}

Row renderMultiscaleRow(const TracedScene& traced, int level)
{
    Row row{"multiscale", level ? "L" + std::to_string(level) : "auto"};
    MultiscaleOptions options;
    options.forceLevel = level;
    const auto start = Clock::now();
    row.image = renderMultiscale(traced, options).image;
    row.seconds = since(start);
    return row;
}

bool hasLevels(const Row& row)
{
    return row.method == "multiscale" && !row.errors.byLevel.empty();
}

std::string reportCsv(const std::vector<Row>& rows)
{
    std::ostringstream s;
    s << "method,setting,seconds,rmse,mean_relative,max_absolute,rmse_needle,rmse_cone,"
         "rmse_bough,prep_seconds\n";
    s << std::setprecision(6);
    for (const Row& r : rows) {
        s << r.method << ',' << r.setting << ',' << r.seconds << ',' << r.errors.rmse << ','
          << r.errors.meanRelative << ',' << r.errors.maxAbsolute;
        for (int level = 1; level <= 3; ++level) {
            s << ',';
            if (hasLevels(r) && r.errors.byLevel[level].pixels) s << r.errors.byLevel[level].rmse;
        }
        s << ',';
        if (r.prepSeconds) s << *r.prepSeconds;
        s << '\n';
    }
    return s.str();
}

/// The error maps' common scale: the 99th percentile of every pixel's error over all renders
/// but the truth, so one outlier does not darken every map and equal colours mean equal error.
double commonErrorScale(const std::vector<Row>& rows)
{
    std::vector<float> all;
    for (const Row& r : rows) {
        if (r.truth) continue;
        const auto& e = r.errors.error.aovs.at("error");
        all.insert(all.end(), e.begin(), e.end());
    }
    if (all.empty()) return 1.0;
    const std::size_t k = std::min(all.size() - 1, std::size_t(0.99 * double(all.size())));
    std::nth_element(all.begin(), all.begin() + std::ptrdiff_t(k), all.end());
    return std::max(double(all[k]), 1e-9);
}

struct FlickerRow {
    std::string method;
    double flicker = 0.0, secondsPerFrame = 0.0;
};

/// The camera dollies away from its look-at point over `frames` frames, distance x 1 to x
/// `dollyEnd`; each method renders every frame (the scene rebuilt per frame: the per-bough
/// shading depends on the camera).
std::vector<FlickerRow> measureFlicker(const scenes::Scene& base, const CompareSettings& s,
                                       int& width, int& height)
{
    scenes::Scene scene = base;
    width = scene.camera.width = std::max(8, base.camera.width / s.frameDivisor);
    height = scene.camera.height = std::max(8, base.camera.height / s.frameDivisor);
    const scenes::Vec3 offset = base.camera.position_cm - base.camera.lookAt_cm;
    std::vector<FlickerRow> rows{{"multiscale_auto"}, {"geometry_1spp"}, {"geometry_4spp"}};
    std::vector<std::vector<Image>> frames(rows.size());
    for (int f = 0; f < s.frames; ++f) {
        const double t = s.frames > 1 ? double(f) / double(s.frames - 1) : 0.0;
        scene.camera.position_cm = base.camera.lookAt_cm + offset * (1.0 + (s.dollyEnd - 1.0) * t);
        const TracedScene traced = buildTracedScene(scene);
        for (std::size_t m = 0; m < rows.size(); ++m) {
            const auto start = Clock::now();
            Image image;
            if (m == 0) {
                image = renderMultiscale(traced).image;
            } else {
                GeometryOptions options;
                options.samples = m == 1 ? 1 : 4;
                image = renderGeometry(traced, options).image;
            }
            rows[m].secondsPerFrame += since(start) / double(s.frames);
            image.aovs.clear();  // only RGB is measured; 16 frames of AOVs would be memory
            frames[m].push_back(std::move(image));
        }
        std::cerr << "\rvdbtrace compare: dolly frame " << f + 1 << "/" << s.frames;
    }
    std::cerr << '\n';
    for (std::size_t m = 0; m < rows.size(); ++m) rows[m].flicker = temporalFlicker(frames[m]);
    return rows;
}

struct Context {
    Context(const CompareOptions& o, const scenes::Scene& s) : options(o), scene(s) {}
    const CompareOptions& options;
    const scenes::Scene& scene;
    double buildSeconds = 0.0;
    double errorScale = 0.0;
    bool plotted = false;
    std::vector<FlickerRow> flicker;
    int flickerWidth = 0, flickerHeight = 0;
};

const Row* find(const std::vector<Row>& rows, const std::string& method,
                const std::string& setting)
{
    for (const Row& r : rows) {
        if (r.method == method && r.setting == setting) return &r;
    }
    return nullptr;
}

/// The fastest geometry render of the sweep (not the truth) with RMSE <= `rmse`, or null.
const Row* cheapestGeometryWithin(const std::vector<Row>& rows, double rmse)
{
    const Row* cheapest = nullptr;
    for (const Row& r : rows) {
        if (r.method == "geometry" && r.errors.rmse <= rmse &&
            (!cheapest || r.seconds < cheapest->seconds)) {
            cheapest = &r;
        }
    }
    return cheapest;
}

std::string speedSection(const std::vector<Row>& rows)
{
    std::ostringstream s;
    const Row* ms = find(rows, "multiscale", "auto");
    if (!ms) return "Multiscale (auto) was not rendered.\n";
    const Row* cheapest = cheapestGeometryWithin(rows, ms->errors.rmse);
    const Row* best = nullptr;
    for (const Row& r : rows) {
        if (r.method == "geometry" && (!best || r.errors.rmse < best->errors.rmse)) best = &r;
    }
    s << "Multiscale (auto): RMSE " << num(ms->errors.rmse) << " in " << num(ms->seconds, 3)
      << " s.\n\n";
    if (cheapest) {
        const double ratio = cheapest->seconds / ms->seconds;
        s << "The cheapest geometry setting at equal or lower RMSE is " << cheapest->setting
          << " (RMSE " << num(cheapest->errors.rmse) << ", " << num(cheapest->seconds, 3)
          << " s, its BVH included): speed ratio (geometry s / multiscale s) **" << num(ratio, 3)
          << "**, i.e. "
          << (ratio >= 1.0 ? "multiscale is " + num(ratio, 3) + " times faster"
                           : "the geometry is " + num(1.0 / ratio, 3) + " times faster")
          << " at equal or lower error.\n";
    } else if (best) {
        s << "**No geometry setting of the sweep reached multiscale's RMSE** (the best, "
          << best->setting << ", has " << num(best->errors.rmse) << " in "
          << num(best->seconds, 3) << " s); no ratio is extrapolated.\n";
    }
    return s.str();
}

std::string levelSection(const std::vector<Row>& rows)
{
    std::ostringstream s;
    const Row* ms = find(rows, "multiscale", "auto");
    if (!ms || !hasLevels(*ms)) return "No multiscale level AOV: nothing to split.\n";
    const auto& l = ms->errors.byLevel;
    const char* names[4] = {"no foliage", "needle", "cone", "bough"};
    // Each level's share of the squared error says where the image's RMSE comes from.
    double total = 0.0;
    for (int k = 0; k < 4; ++k) total += double(l[k].pixels) * l[k].rmse * l[k].rmse;
    s << "RMSE of multiscale (auto) over the pixels of each level (the level covering each "
         "pixel, rounded), and each level's share of the image's squared error:\n\n"
         "| level | pixels | RMSE | mean relative | share of squared error |\n"
         "|---|---|---|---|---|\n";
    for (int k = 0; k < 4; ++k) {
        const double share = double(l[k].pixels) * l[k].rmse * l[k].rmse / std::max(total, 1e-30);
        s << "| " << names[k] << " | " << l[k].pixels << " | "
          << (l[k].pixels ? num(l[k].rmse) : "-") << " | "
          << (l[k].relativePixels ? num(l[k].meanRelative) : "-") << " | "
          << num(100.0 * share, 3) << "% |\n";
    }
    // Needle and cone levels pooled: the foliage shaded without the linear law.
    const double n12 = double(l[1].pixels + l[2].pixels);
    const double rest = n12 > 0.0 ? std::sqrt((double(l[1].pixels) * l[1].rmse * l[1].rmse +
                                               double(l[2].pixels) * l[2].rmse * l[2].rmse) /
                                              n12)
                                  : 0.0;
    s << '\n';
    if (l[3].pixels == 0) {
        s << "No pixel is shaded at the bough level in this view: the linear law does not show "
             "here.\n";
    } else if (n12 == 0.0) {
        s << "Every foliage pixel is at the bough level: RMSE " << num(l[3].rmse)
          << "; nothing to set it against.\n";
    } else {
        s << "The bough level (section 6.6's linear law) has RMSE " << num(l[3].rmse)
          << " against " << num(rest) << " for the needle and cone levels pooled ("
          << num(l[3].rmse / std::max(rest, 1e-12), 3) << " times).";
        const Row* l3 = find(rows, "multiscale", "L3");
        const Row* l1 = find(rows, "multiscale", "L1");
        if (l3 && l1) {
            s << " Forced everywhere, the bough level's RMSE is " << num(l3->errors.rmse)
              << " against " << num(l1->errors.rmse) << " for the needle level.";
        }
        s << '\n';
    }
    return s.str();
}

std::string reportMd(const std::vector<Row>& rows, const Context& c)
{
    const CompareSettings& st = c.options.settings;
    const scenes::Scene& scene = c.scene;
    std::ostringstream s;
    s << "# `vdbtrace compare`: " << c.options.sceneFile.filename().string() << "\n\n";
    s << "- scene: `" << c.options.sceneFile.string() << "`, " << scene.camera.width << " x "
      << scene.camera.height << " pixels\n";
    s << "- machine: " << cpuModel() << ", " << std::thread::hardware_concurrency()
      << " cores; " << tbb::this_task_arena::max_concurrency() << " threads\n";
    s << "- ground truth: geometry (explicit needles) at " << st.truthSamples << " spp\n";
    s << "- geometry:";
    for (int n : st.geometrySamples) s << ' ' << n;
    s << " spp; reference: voxels of";
    for (double h : st.voxelSizes_cm) s << ' ' << num(h);
    s << " cm, " << st.subpixels * st.subpixels << " rays per pixel; multiscale: levels forced "
      << "to 1, 2, 3 and automatic\n";
    s << "- scene build (trees grown, BVH, per-bough shading): " << num(c.buildSeconds, 3)
      << " s, once, excluded from every time below\n\n";
    s << "## Error against time\n\n"
         "Seconds: wall clock of each render alone, including what the method alone needs "
         "first (prep: the geometry's Embree BVH, the reference's bake). Errors: linear "
         "luminance of premultiplied RGB against the ground truth (`compareImages`): RMSE over "
         "all pixels, mean relative over pixels brighter than 1% of the truth's mean, maximum, "
         "and for multiscale the RMSE over the pixels of each level.\n\n";
    s << "| method | setting | seconds | prep s | RMSE | mean relative | max | RMSE needle | "
         "RMSE cone | RMSE bough |\n|---|---|---|---|---|---|---|---|---|---|\n";
    for (const Row& r : rows) {
        s << "| " << r.method << " | " << r.setting << " | "
          << num(r.seconds, 3) << " | " << (r.prepSeconds ? num(*r.prepSeconds, 3) : "")
          << " | " << num(r.errors.rmse) << " | " << num(r.errors.meanRelative) << " | "
          << num(r.errors.maxAbsolute);
        for (int level = 1; level <= 3; ++level) {
            s << " | ";
            if (hasLevels(r) && r.errors.byLevel[level].pixels) {
                s << num(r.errors.byLevel[level].rmse);
            }
        }
        s << " |\n";
    }
    s << "\nThe same in [report.csv](report.csv).\n\n";
    if (c.plotted) s << "![RMSE against seconds](error_vs_time.png)\n\n";
    s << "## Speed at equal error\n\n" << speedSection(rows) << '\n';
    s << "## Where the linear law's error shows\n\n" << levelSection(rows) << '\n';
    s << "## Images\n\nPreviews over the scene's background; error maps of the luminance error "
         "from 0 (black) to "
      << num(c.errorScale) << " (white), the 99th percentile of all errors, one scale for "
      << "all.\n\n| render | error map |\n|---|---|\n";
    for (const Row& r : rows) {
        s << "| " << r.method << ' ' << r.setting << "<br>![" << r.stem() << "](" << r.stem()
          << ".png) | ";
        if (r.truth) {
            s << "(the ground truth)";
        } else {
            s << "![" << r.stem() << " error](" << r.stem() << ".error.png)";
        }
        s << " |\n";
    }
    if (!c.flicker.empty()) {
        s << "\n## Temporal aliasing\n\n"
          << st.frames << " frames at " << c.flickerWidth << " x " << c.flickerHeight
          << ", the camera dollying away from its look-at point (distance x 1 to x "
          << num(st.dollyEnd) << "). **Flicker** = mean over pixels of the standard deviation, "
          << "over the frames, of the pixel's luminance (premultiplied RGB) about its "
          << "least-squares line in the frame index: the smooth change the dolly causes is "
          << "removed, the frame-to-frame jumps of aliasing needles remain. Edges that move "
          << "across pixels count in every method alike.\n\n"
          << "| method | flicker | seconds per frame |\n|---|---|---|\n";
        for (const FlickerRow& f : c.flicker) {
            s << "| " << f.method << " | " << num(f.flicker) << " | "
              << num(f.secondsPerFrame, 3) << " |\n";
        }
        s << "\nThe same in [flicker.csv](flicker.csv).\n";
    }
    return s.str();
}

}  // namespace

CompareSettings CompareSettings::forQuick(bool quick)
{
    CompareSettings s;
    if (quick) {
        s.truthSamples = 16;
        s.geometrySamples = {1, 4};
        s.voxelSizes_cm = {1.0, 0.5};
        s.frames = 8;
        s.frameDivisor = 2;
    }
    return s;
}

bool parseResolution(const std::string& text, int& width, int& height)
{
    int w = 0, h = 0, used = 0;
    if (std::sscanf(text.c_str(), "%dx%d%n", &w, &h, &used) != 2) return false;
    if (std::size_t(used) != text.size() || w < 1 || h < 1) return false;
    width = w;
    height = h;
    return true;
}

int runCompare(const CompareOptions& options)
{
    const auto start = Clock::now();
    const fs::path& dir = options.outDir;
    io::checkWritableFolder(dir);
    const CompareSettings& st = options.settings;
    scenes::Scene scene = scenes::loadScene(options.sceneFile);
    if (options.width > 0 && options.height > 0) {
        // fov_deg is vertical: the view is kept, and kept exactly when the aspect is.
        scene.camera.width = options.width;
        scene.camera.height = options.height;
    }
    Context c(options, scene);
    const auto buildStart = Clock::now();
    const TracedScene traced = buildTracedScene(scene);
    c.buildSeconds = since(buildStart);
    std::cerr << "vdbtrace compare: " << options.sceneFile.string() << ", "
              << scene.camera.width << "x" << scene.camera.height << ", scene built in "
              << num(c.buildSeconds, 3) << " s\n";

    std::vector<Row> rows;
    rows.push_back(renderGeometryRow(traced, st.truthSamples, "truth"));
    rows.back().truth = true;
    const Image truth = rows.front().image;  // a copy: `rows` grows
    const auto measure = [&](Row row) {
        row.errors = compareImages(row.image, truth);
        progress(row);
        rows.push_back(std::move(row));
    };
    rows.front().errors = compareImages(truth, truth);
    progress(rows.front());
    for (int n : st.geometrySamples) measure(renderGeometryRow(traced, n, "geometry"));
    for (double h : st.voxelSizes_cm) measure(renderReferenceRow(traced, h, st.subpixels));
    for (int level : st.levels) measure(renderMultiscaleRow(traced, level));

    c.errorScale = commonErrorScale(rows);
    const vdbtrace::Metadata metadata = {{"pine:scene", options.sceneFile.string()}};
    for (const Row& r : rows) {
        Metadata m = metadata;
        m.emplace_back("pine:method", r.method);
        m.emplace_back("pine:setting", r.setting);
        m.emplace_back("pine:render_seconds", std::to_string(r.seconds));
        writeExr(r.image, dir / (r.stem() + ".exr"), m);
        writePreviewPng(r.image, scene.render.background, dir / (r.stem() + ".png"));
        if (!r.truth) writeErrorPng(r.errors, c.errorScale, dir / (r.stem() + ".error.png"));
    }
    io::writeTextAtomically(dir / "report.csv", reportCsv(rows));

    if (options.plot) {
        const std::string cmd = "MPLBACKEND=Agg /usr/bin/python3 '" + plotScript().string() +
                                "' '" + dir.string() + "'";
        c.plotted = std::system(cmd.c_str()) == 0 && fs::exists(dir / "error_vs_time.png");
        if (!c.plotted) {
            std::cerr << "vdbtrace compare: warning: plotting failed (report.csv has the data)\n";
        }
    }
    if (options.flicker) {
        c.flicker = measureFlicker(scene, st, c.flickerWidth, c.flickerHeight);
        std::ostringstream csv;
        csv << "method,flicker,seconds_per_frame\n" << std::setprecision(6);
        for (const FlickerRow& f : c.flicker) {
            csv << f.method << ',' << f.flicker << ',' << f.secondsPerFrame << '\n';
            std::cerr << "vdbtrace compare: flicker " << f.method << " " << num(f.flicker)
                      << '\n';
        }
        io::writeTextAtomically(dir / "flicker.csv", csv.str());
    }
    io::writeTextAtomically(dir / "report.md", reportMd(rows, c));

    const Row* ms = find(rows, "multiscale", "auto");
    std::cerr << "vdbtrace compare: " << rows.size() << " renders";
    if (!c.flicker.empty()) std::cerr << " and " << st.frames << " dolly frames x 3";
    std::cerr << " in " << num(since(start), 3) << " s";
    if (ms) {
        std::cerr << "; multiscale (auto) rmse " << num(ms->errors.rmse) << " in "
                  << num(ms->seconds, 3) << " s";
        if (const Row* g = cheapestGeometryWithin(rows, ms->errors.rmse)) {
            std::cerr << ", speed ratio " << num(g->seconds / ms->seconds, 3) << " over geometry "
                      << g->setting;
        } else {
            std::cerr << ", no geometry setting as accurate";
        }
    }
    std::cerr << " -> " << (dir / "report.md").string() << '\n';
    return 0;
}

}  // namespace pine::vdbtrace
