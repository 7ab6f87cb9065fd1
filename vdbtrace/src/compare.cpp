#include "pine/vdbtrace/compare.h"

#include "pine/bake/resource_estimate.h"
#include "pine/support/atomic_file.h"
#include "pine/vdbtrace/compare_report.h"
#include "pine/vdbtrace/dolly.h"
#include "pine/vdbtrace/image.h"
#include "pine/vdbtrace/integer_list.h"

#include <algorithm>
#include <chrono>

namespace pine::vdbtrace {

bool parseResolution(const std::string& text, int& width, int& height)
{
    int v[2];
    if (!parseIntegers(text, 'x', v)) return false;
    constexpr int kMaxSide = 16384;  // a scene's camera.resolution allows no more
    if (v[0] < 1 || v[1] < 1 || v[0] > kMaxSide || v[1] > kMaxSide) return false;
    width = v[0];
    height = v[1];
    return true;
}

CompareRun runCompare(const CompareOptions& options)
{
    using Clock = std::chrono::steady_clock;
    const auto start = Clock::now();
    const auto log = [&](const std::string& line) {
        if (options.log) options.log(line);
    };
    const std::filesystem::path& dir = options.outDir;
    // Its reports, the rows' images and previews, the plots.
    io::checkFolderSparesInputs(
        dir,
        [](const std::string& name) {
            const std::string ext = std::filesystem::path(name).extension().string();
            return name == "report.md" || name == "report.csv" || name == "trees.csv" ||
                   name == "flicker.csv" || ext == ".exr" || ext == ".png";
        },
        {options.sceneFile});
    io::checkWritableFolder(dir);
    loadImageIo();
    scenes::Scene scene = loadComparedScene(
        options.sceneFile, options.model, options.addSelfShadowing, options.width, options.height);
    const CompareSettings& st = options.settings;
    if (options.maxMemoryBytes > 0.0) {
        // The truth's check and a budget row's image are held while they are measured.
        const std::size_t images =
            1 + st.geometrySamples.size() + st.voxelSizes_cm.size() + st.levels.size() + 1;
        const double smallest =
            st.voxelSizes_cm.empty()
                ? 1.0
                : *std::min_element(st.voxelSizes_cm.begin(), st.voxelSizes_cm.end());
        bake::checkMemory(bake::estimateCompare(scene, smallest, images), options.maxMemoryBytes,
                          options.sceneFile.string());
    }
    log(options.sceneFile.string() + ", " + std::to_string(scene.camera.width) + "x" +
        std::to_string(scene.camera.height));
    CompareRun run = runComparison(scene, st, log);

    ReportInfo info;
    info.sceneFile = options.sceneFile;
    info.settings = st;
    info.machine = options.machine;
    info.errorScale = commonErrorScale(run.rows);
    writeRowImages(run, options.sceneFile, scene, info.errorScale, dir);
    io::writeTextAtomically(dir / "report.csv", reportCsv(run));
    io::writeTextAtomically(dir / "trees.csv", treesCsv(run));
    if (options.plot) {
        info.plotted = options.plot(dir);
        info.treePlot = info.plotted && std::filesystem::exists(dir / "tree_bias.png");
        if (!info.plotted) {
            (options.warn ? options.warn : log)(
                "warning: plotting failed (report.csv has the data)");
        }
    }
    DollyFlicker flicker;
    if (options.flicker) {
        flicker = measureDollyFlicker(scene, st, log);
        for (const FlickerRow& f : flicker.rows) {
            log("flicker " + f.method + " " + formatNumber(f.flicker));
        }
        io::writeTextAtomically(dir / "flicker.csv", flickerCsv(flicker));
        info.flicker = &flicker;
    }
    io::writeTextAtomically(dir / "report.md", reportMd(run, scene, info));

    std::string summary = std::to_string(run.rows.size()) + " renders";
    if (!run.budget.empty()) {
        summary += ", " + std::to_string(run.budget.size()) + " for the error budget";
    }
    if (options.flicker) summary += " and " + std::to_string(st.frames) + " dolly frames x 3";
    summary += " in " +
               formatNumber(std::chrono::duration<double>(Clock::now() - start).count(), 3) +
               " s";
    if (const CompareRow* ms = findRow(run.rows, "multiscale", "auto")) {
        summary += "; multiscale (auto) rmse " + formatNumber(ms->errors.rmse) + " in " +
                   formatNumber(ms->seconds, 3) + " CPU-s";
        if (const CompareRow* g = cheapestGeometryWithin(run.rows, ms->errors.rmse)) {
            summary += ", speed ratio " + formatNumber(g->seconds / ms->seconds, 3) +
                       " over geometry " + g->setting;
        } else {
            summary += ", no geometry setting as accurate";
        }
    }
    log(summary + " -> " + (dir / "report.md").string());
    return run;
}

}  // namespace pine::vdbtrace
