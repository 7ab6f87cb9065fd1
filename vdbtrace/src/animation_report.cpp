#include "pine/vdbtrace/animation_report.h"

#include "pine/bake/resource_estimate.h"
#include "pine/support/atomic_file.h"
#include "pine/support/input_error.h"
#include "pine/vdbtrace/preview.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <iomanip>
#include <sstream>

namespace pine::vdbtrace {
namespace {

// The report's numbers: three significant digits.
std::string shown(double v)
{
    return formatNumber(v, 3);
}

// A breakdown's table cells: all pixels, then each level band ("-" where it has no pixels),
// each " value |".
std::string breakdownCells(const FlickerBreakdown& f)
{
    std::ostringstream cells;
    cells << ' ' << shown(f.flicker) << " |";
    for (std::size_t b = 0; b < f.perBand.size(); ++b) {
        cells << ' ' << (f.bandPixels[b] > 0 ? shown(f.perBand[b]) : std::string("-")) << " |";
    }
    return cells.str();
}

// A path's pixels change along curves (a trunk sweeping across them): each frame is measured
// against its neighbours' line (flicker.h).
constexpr int kPathWindow = 3;

std::string flickerCsv(const AnimationFlicker& a)
{
    std::ostringstream csv;
    csv << "method,band,pixels,flicker,error_flicker,seconds_per_frame,cpu_seconds_per_frame\n"
        << std::setprecision(6);
    for (const AnimationRow& r : a.rows) {
        // The error's flicker is empty without a truth (and on the truth's own row).
        const auto error = [&r](std::size_t band) {
            std::ostringstream v;
            v << std::setprecision(6);
            if (r.errorFlicker) {
                v << (band == 0 ? r.errorFlicker->flicker : r.errorFlicker->perBand[band - 1]);
            }
            return v.str();
        };
        csv << r.method << ",all," << std::size_t(a.width) * a.height << ',' << r.flicker.flicker
            << ',' << error(0) << ',' << r.secondsPerFrame << ',' << r.cpuSecondsPerFrame << '\n';
        for (std::size_t b = 0; b < r.flicker.perBand.size(); ++b) {
            csv << r.method << ',' << kLevelBandKeys[b] << ',' << r.flicker.bandPixels[b] << ','
                << r.flicker.perBand[b] << ',' << error(b + 1) << ',' << r.secondsPerFrame << ','
                << r.cpuSecondsPerFrame << '\n';
        }
    }
    return csv.str();
}

std::string framesCsv(const AnimationFlicker& a, const std::vector<int>& frameNumbers)
{
    std::ostringstream csv;
    csv << "frame,method,residual_rms,mean_luminance\n" << std::setprecision(6);
    for (const AnimationRow& r : a.rows) {
        for (std::size_t t = 0; t < frameNumbers.size(); ++t) {
            // Empty where undefined (the first and last frames have no line through their
            // neighbours), as flicker.csv leaves them: "nan" is no number a reader takes.
            const double residual = r.flicker.residualPerFrame[t];
            csv << frameNumbers[t] << ',' << r.method << ',';
            if (std::isfinite(residual)) csv << residual;
            csv << ',' << r.flicker.luminancePerFrame[t] << '\n';
        }
    }
    return csv.str();
}

// Each row's kept frames side by side, one row of frames per method, a 2-pixel gap of the
// background between them.
Image strip(const AnimationFlicker& a)
{
    constexpr int gap = 2;
    const int columns = int(a.rows.front().kept.size());
    const int rows = int(a.rows.size());
    Image out(columns * a.width + (columns - 1) * gap, rows * a.height + (rows - 1) * gap);
    for (int r = 0; r < rows; ++r) {
        for (int c = 0; c < columns; ++c) {
            const Image& frame = a.rows[std::size_t(r)].kept[std::size_t(c)];
            for (int y = 0; y < a.height; ++y) {
                std::copy_n(frame.pixel(0, y), 4 * a.width,
                            out.pixel(c * (a.width + gap), r * (a.height + gap) + y));
            }
        }
    }
    return out;
}

std::string reportMd(const AnimationFlicker& a, const AnimationCompareOptions& o,
                     const scenes::Scene& scene, const std::vector<int>& frameNumbers,
                     const std::vector<int>& stripFrames, bool plotted)
{
    std::ostringstream md;
    md << "# Temporal report: " << o.sceneFile.filename().string() << "\n\n"
       << "The scene's camera path, frames " << frameNumbers.front() << "-" << frameNumbers.back()
       << " (" << frameNumbers.size() << " frames, " << shown(scene.cameraPath.framesPerSecond)
       << " per second), " << a.width << " x " << a.height
       << ", rendered by each method with the same effects ("
       << (scene.effects.shadows ? "shadows and self-shadowing" : "no shadows")
       << "). Machine: " << o.machine << ".\n\n"
       << "**Flicker** is, for each pixel, how far its luminance at each frame departs from "
       << "the line through its two neighbouring frames, l(t) - (l(t-1) + l(t+1)) / 2, as a "
       << "root mean square over the frames divided by sqrt(1.5): for frames that jitter "
       << "independently it is their standard deviation, and any motion linear over three "
       << "frames counts for nothing; averaged over the pixels "
       << "(`vdbtrace/include/pine/vdbtrace/flicker.h`). Edges sweeping across pixels still "
       << "count, alike for every method; what differs between methods is their aliasing. "
       << "A band's flicker is the same mean over "
       << "the pixels of that band: a pixel's band is the level the multiscale render shades "
       << "it at, averaged over the frames with foliage there; the bands are the same pixels "
       << "for every method.\n\n";
    md << "| method | flicker, all pixels |";
    for (const char* band : kLevelBandNames) md << ' ' << band << " |";
    md << " render s / frame | CPU-s / frame |\n|---|---|";
    for (std::size_t b = 0; b < std::size(kLevelBandNames); ++b) md << "---|";
    md << "---|---|\n";
    for (const AnimationRow& r : a.rows) {
        md << "| " << r.method << " |" << breakdownCells(r.flicker) << ' '
           << shown(r.secondsPerFrame) << " | " << shown(r.cpuSecondsPerFrame) << " |\n";
    }
    md << "| pixels in the band | " << std::size_t(a.width) * a.height << " |";
    for (const std::size_t n : a.rows.front().flicker.bandPixels) md << ' ' << n << " |";
    md << " | |\n\n";
    const AnimationRow& ms = a.rows.front();
    for (std::size_t m = 1; m < a.rows.size(); ++m) {
        if (a.rows[m].truth) continue;
        md << "- " << a.rows[m].method << " flickers "
           << shown(a.rows[m].flicker.flicker / std::max(ms.flicker.flicker, 1e-30))
           << " times as much as " << ms.method << ".\n";
    }
    if (a.rows.back().truth) {
        const AnimationRow& truth = a.rows.back();
        md << "\n## Against the truth\n\n"
           << truth.method << " (geometry on its own sample seed) is the truth. Its own "
           << "flicker, " << shown(truth.flicker.flicker) << " (" << shown(truth.flicker.perBand[3])
           << " on the bough-level pixels), is the motion's: edges sweeping across pixels, "
           << "which every method shares. The **error flicker** is the flicker of each method's "
           << "frames less the truth's: the motion is in both and cancels, a bias that changes "
           << "smoothly along the path counts for nothing, and what remains is how the method's "
           << "error jumps from frame to frame, its temporal aliasing (plus the truth's own "
           << "noise, the same for every method).\n\n"
           << "| method | error flicker, all pixels |";
        for (const char* band : kLevelBandNames) md << ' ' << band << " |";
        md << "\n|---|---|";
        for (std::size_t b = 0; b < std::size(kLevelBandNames); ++b) md << "---|";
        md << "\n";
        for (const AnimationRow& r : a.rows) {
            if (!r.errorFlicker) continue;
            md << "| " << r.method << " |" << breakdownCells(*r.errorFlicker) << "\n";
        }
        md << "\n";
        for (std::size_t m = 1; m < a.rows.size(); ++m) {
            if (!a.rows[m].errorFlicker) continue;
            md << "- " << a.rows[m].method << "'s error flickers "
               << shown(a.rows[m].errorFlicker->flicker / std::max(ms.errorFlicker->flicker, 1e-30))
               << " times as much as " << ms.method << "'s.\n";
        }
    }
    md << "\n## Over the frames\n\n"
       << "Each frame's departure from the pixels' lines (root mean square over the pixels, "
       << "`frames.csv`): a frame that pops, a level switching over a whole tree, stands out "
       << "as a spike; a steady method stays flat.\n\n";
    if (plotted) {
        md << "![flicker over the frames](flicker_frames.png)\n\n";
    } else {
        md << "(No plot: matplotlib was not available or failed; frames.csv has the data.)\n\n";
    }
    md << "## Frames\n\n![frames](strip.png)\n\nRows: ";
    for (std::size_t m = 0; m < a.rows.size(); ++m) {
        md << (m ? ", " : "") << a.rows[m].method;
    }
    md << "; columns: frames";
    for (std::size_t k = 0; k < stripFrames.size(); ++k) {
        md << (k ? ", " : " ") << frameNumbers[std::size_t(stripFrames[k])];
    }
    md << ".\n\nRegenerate: `vdbtrace animate-compare " << o.sceneFile.string()
       << " --out-dir DIR --frames " << frameNumbers.front() << "-" << frameNumbers.back()
       << " --resolution " << a.width << "x" << a.height << " --strip " << stripFrames.size()
       << (o.truthSamples > 0 ? " --truth-samples " + std::to_string(o.truthSamples) : "")
       << (o.addSelfShadowing ? " --self-shadowing" : "")
       << "`, with the same model switches (the scene's own here: " << scene.render.model.boughLaw
       << " bough law, " << scene.render.model.layerModel << " layer model).\n";
    return md.str();
}

}  // namespace

AnimationFlicker runAnimationCompare(const AnimationCompareOptions& o)
{
    using Clock = std::chrono::steady_clock;
    const auto start = Clock::now();
    const auto log = [&](const std::string& line) {
        if (o.log) o.log(line);
    };
    // Its reports, the frames' strip and the plot.
    io::checkFolderSparesInputs(o.outDir,
                                [](const std::string& name) {
                                    return name == "report.md" || name == "flicker.csv" ||
                                           name == "frames.csv" || name == "strip.png" ||
                                           name == "flicker_frames.png";
                                },
                                {o.sceneFile});
    io::checkWritableFolder(o.outDir);
    loadImageIo();
    scenes::Scene scene =
        loadComparedScene(o.sceneFile, o.model, o.addSelfShadowing, o.width, o.height);
    if (scene.cameraPath.empty()) {
        throw InputError("'" + o.sceneFile.string() +
                         "' has no camera_path to compare the methods along "
                         "(docs/scene-format.md)");
    }
    const FrameRange range =
        o.frames ? *o.frames : FrameRange{scene.cameraPath.firstFrame, scene.cameraPath.lastFrame};
    if (range.count() < 3) {
        throw InputError("flicker needs at least 3 frames; frames " + std::to_string(range.first) +
                         "-" + std::to_string(range.last) + " are " +
                         std::to_string(range.count()));
    }
    std::vector<int> frameNumbers;
    std::vector<scenes::Camera> cameras;
    for (int f = range.first; f <= range.last; ++f) {
        frameNumbers.push_back(f);
        cameras.push_back(scene.cameraPath.at(f, scene.camera));
        // The file checks its own frames; --frames may name others.
        const std::string problem = scenes::cameraProblem(cameras.back());
        if (!problem.empty()) {
            throw InputError("--frames: at frame " + std::to_string(f) + " of '" +
                             o.sceneFile.string() + "'s camera_path, " + problem);
        }
    }
    // Evenly spaced from the first frame to the last.
    std::vector<int> stripFrames;
    const int stripCount = std::clamp(o.stripFrames, 1, range.count());
    if (stripCount != o.stripFrames && o.log) {
        o.log("--strip " + std::to_string(o.stripFrames) + ": the strip shows " +
              std::to_string(stripCount) + " frames, as many as there are");
    }
    for (int k = 0; k < stripCount; ++k) {
        stripFrames.push_back(stripCount == 1 ? 0 : k * (range.count() - 1) / (stripCount - 1));
    }
    const std::size_t sequences = std::size(kAnimationSequences) + (o.truthSamples > 0 ? 1 : 0);
    if (o.maxMemoryBytes > 0.0) {
        // The heavier method's render, plus every frame of every sequence held for the flicker.
        bake::ResourceEstimate needs = bake::estimateRender(scene, "geometry", 1.0);
        const double frameBytes = double(scene.camera.width) * scene.camera.height * 16.0;
        needs.parts.push_back({std::to_string(range.count()) + " frames x " +
                                   std::to_string(sequences) + " methods held",
                               frameBytes * range.count() * (double(sequences) + 0.25)});
        bake::checkMemory(needs, o.maxMemoryBytes, o.sceneFile.string());
    }
    log(o.sceneFile.string() + ": " + std::to_string(range.count()) + " frames at " +
        std::to_string(scene.camera.width) + " x " + std::to_string(scene.camera.height) + ", " +
        std::to_string(sequences) + " methods");
    const AnimationFlicker a =
        measureAnimationFlicker(scene, cameras, stripFrames, kPathWindow, o.truthSamples, log);

    io::writeTextAtomically(o.outDir / "flicker.csv", flickerCsv(a));
    io::writeTextAtomically(o.outDir / "frames.csv", framesCsv(a, frameNumbers));
    writePreviewPng(strip(a), scene.render.background, o.outDir / "strip.png");
    bool plotted = false;
    if (o.plot) {
        plotted = o.plot(o.outDir);
        if (!plotted) log("warning: plotting failed (frames.csv has the data)");
    }
    io::writeTextAtomically(o.outDir / "report.md",
                            reportMd(a, o, scene, frameNumbers, stripFrames, plotted));
    std::string summary = std::to_string(range.count()) + " frames x " +
                          std::to_string(a.rows.size()) + " methods in " +
                          shown(std::chrono::duration<double>(Clock::now() - start).count()) +
                          " s; flicker";
    for (const AnimationRow& r : a.rows) summary += " " + r.method + " " + shown(r.flicker.flicker);
    log(summary);
    return a;
}

}  // namespace pine::vdbtrace
