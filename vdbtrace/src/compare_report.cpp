#include "pine/vdbtrace/compare_report.h"

#include "pine/vdbtrace/exr_output.h"
#include "pine/vdbtrace/preview.h"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <sstream>

namespace pine::vdbtrace {
namespace {

bool hasLevels(const CompareRow& row)
{
    return row.method == "multiscale" && !row.errors.byLevel.empty();
}

std::string speedSection(const std::vector<CompareRow>& rows)
{
    std::ostringstream s;
    const CompareRow* ms = findRow(rows, "multiscale", "auto");
    if (!ms) return "Multiscale (auto) was not rendered.\n";
    const CompareRow* cheapest = cheapestGeometryWithin(rows, ms->errors.rmse);
    const CompareRow* best = nullptr;
    for (const CompareRow& r : rows) {
        if (r.method == "geometry" && (!best || r.errors.rmse < best->errors.rmse)) best = &r;
    }
    s << "Multiscale (auto): RMSE " << formatNumber(ms->errors.rmse) << " in "
      << formatNumber(ms->seconds, 3) << " s.\n\n";
    if (cheapest) {
        const double ratio = cheapest->seconds / ms->seconds;
        s << "The cheapest geometry setting at equal or lower RMSE is " << cheapest->setting
          << " (RMSE " << formatNumber(cheapest->errors.rmse) << ", "
          << formatNumber(cheapest->seconds, 3)
          << " s, its BVH included): speed ratio (geometry s / multiscale s) **"
          << formatNumber(ratio, 3) << "**, i.e. "
          << (ratio >= 1.0 ? "multiscale is " + formatNumber(ratio, 3) + " times faster"
                           : "the geometry is " + formatNumber(1.0 / ratio, 3) + " times faster")
          << " at equal or lower error.\n";
    } else if (best) {
        s << "**No geometry setting of the sweep reached multiscale's RMSE** (the best, "
          << best->setting << ", has " << formatNumber(best->errors.rmse) << " in "
          << formatNumber(best->seconds, 3) << " s); no ratio is extrapolated.\n";
    }
    return s.str();
}

std::string levelSection(const std::vector<CompareRow>& rows)
{
    std::ostringstream s;
    const CompareRow* ms = findRow(rows, "multiscale", "auto");
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
          << (l[k].pixels ? formatNumber(l[k].rmse) : "-") << " | "
          << (l[k].relativePixels ? formatNumber(l[k].meanRelative) : "-") << " | "
          << formatNumber(100.0 * share, 3) << "% |\n";
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
        s << "Every foliage pixel is at the bough level: RMSE " << formatNumber(l[3].rmse)
          << "; nothing to set it against.\n";
    } else {
        s << "The bough level (section 6.6's linear law) has RMSE " << formatNumber(l[3].rmse)
          << " against " << formatNumber(rest) << " for the needle and cone levels pooled ("
          << formatNumber(l[3].rmse / std::max(rest, 1e-12), 3) << " times).";
        const CompareRow* l3 = findRow(rows, "multiscale", "L3");
        const CompareRow* l1 = findRow(rows, "multiscale", "L1");
        if (l3 && l1) {
            s << " Forced everywhere, the bough level's RMSE is " << formatNumber(l3->errors.rmse)
              << " against " << formatNumber(l1->errors.rmse) << " for the needle level.";
        }
        s << '\n';
    }
    return s.str();
}

}  // namespace

std::string reportCsv(const std::vector<CompareRow>& rows)
{
    std::ostringstream s;
    s << "method,setting,seconds,rmse,mean_relative,max_absolute,rmse_needle,rmse_cone,"
         "rmse_bough,prep_seconds\n";
    s << std::setprecision(6);
    for (const CompareRow& r : rows) {
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

std::string flickerCsv(const DollyFlicker& flicker)
{
    std::ostringstream csv;
    csv << "method,flicker,seconds_per_frame\n" << std::setprecision(6);
    for (const FlickerRow& f : flicker.rows) {
        csv << f.method << ',' << f.flicker << ',' << f.secondsPerFrame << '\n';
    }
    return csv.str();
}

double commonErrorScale(const std::vector<CompareRow>& rows)
{
    std::vector<float> all;
    for (const CompareRow& r : rows) {
        if (r.truth) continue;
        const auto& e = r.errors.error.aovs.at("error");
        all.insert(all.end(), e.begin(), e.end());
    }
    if (all.empty()) return 1.0;
    const std::size_t k = std::min(all.size() - 1, std::size_t(0.99 * double(all.size())));
    std::nth_element(all.begin(), all.begin() + std::ptrdiff_t(k), all.end());
    return std::max(double(all[k]), 1e-9);
}

void writeRowImages(const CompareRun& run, const std::filesystem::path& sceneFile,
                    const scenes::Scene& scene, double errorScale,
                    const std::filesystem::path& dir)
{
    const ConeCamera camera(scene.camera);
    for (const CompareRow& r : run.rows) {
        Metadata m = cameraMetadata(camera);
        m.insert(m.end(), {{"renderTimeSeconds", float(r.seconds)},
                           {"pine:scene", sceneFile.string()},
                           {"pine:method", r.method},
                           {"pine:setting", r.setting},
                           {"pine:render_seconds", float(r.seconds)}});
        writeExr(exrImage(r.image, camera, renderMethod(r.renderer),
                          EffectsPlan::from(scene.effects)),
                 dir / (r.stem() + ".exr"), m);
        writePreviewPng(r.image, scene.render.background, dir / (r.stem() + ".png"));
        if (!r.truth) writeErrorPng(r.errors, errorScale, dir / (r.stem() + ".error.png"));
    }
}

std::string reportMd(const CompareRun& run, const scenes::Scene& scene, const ReportInfo& c)
{
    const std::vector<CompareRow>& rows = run.rows;
    const CompareSettings& st = c.settings;
    std::ostringstream s;
    s << "# `vdbtrace compare`: " << c.sceneFile.filename().string() << "\n\n";
    s << "- scene: `" << c.sceneFile.string() << "`, " << scene.camera.width << " x "
      << scene.camera.height << " pixels\n";
    s << "- machine: " << c.machine << "\n";
    s << "- ground truth: geometry (explicit needles) at " << st.truthSamples << " spp\n";
    s << "- geometry:";
    for (int n : st.geometrySamples) s << ' ' << n;
    s << " spp; reference: voxels of";
    for (double h : st.voxelSizes_cm) s << ' ' << formatNumber(h);
    s << " cm, " << st.subpixels * st.subpixels << " rays per pixel; multiscale: levels forced "
      << "to 1, 2, 3 and automatic\n";
    s << "- scene build (trees grown, BVH): " << formatNumber(run.buildSeconds, 3)
      << " s, excluded from every time below; the multiscale times include the bough law's "
         "per-bough profiles, computed as the render first needs them\n\n";
    s << "## Error against time\n\n"
         "Seconds: wall clock of each render alone, including what the method alone needs "
         "first (prep: the geometry's Embree BVH, the reference's bake and light grids). Errors: "
         "linear "
         "luminance of premultiplied RGB against the ground truth (`compareImages`): RMSE over "
         "all pixels, mean relative over pixels brighter than 1% of the truth's mean, maximum, "
         "and for multiscale the RMSE over the pixels of each level.\n\n";
    s << "| method | setting | seconds | prep s | RMSE | mean relative | max | RMSE needle | "
         "RMSE cone | RMSE bough |\n|---|---|---|---|---|---|---|---|---|---|\n";
    for (const CompareRow& r : rows) {
        s << "| " << r.method << " | " << r.setting << " | " << formatNumber(r.seconds, 3) << " | "
          << (r.prepSeconds ? formatNumber(*r.prepSeconds, 3) : "") << " | "
          << formatNumber(r.errors.rmse) << " | " << formatNumber(r.errors.meanRelative) << " | "
          << formatNumber(r.errors.maxAbsolute);
        for (int level = 1; level <= 3; ++level) {
            s << " | ";
            if (hasLevels(r) && r.errors.byLevel[level].pixels) {
                s << formatNumber(r.errors.byLevel[level].rmse);
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
      << formatNumber(c.errorScale) << " (white), the 99th percentile of all errors, one scale for "
      << "all.\n\n| render | error map |\n|---|---|\n";
    for (const CompareRow& r : rows) {
        s << "| " << r.method << ' ' << r.setting << "<br>![" << r.stem() << "](" << r.stem()
          << ".png) | ";
        if (r.truth) {
            s << "(the ground truth)";
        } else {
            s << "![" << r.stem() << " error](" << r.stem() << ".error.png)";
        }
        s << " |\n";
    }
    if (c.flicker) {
        s << "\n## Temporal aliasing\n\n"
          << st.frames << " frames at " << c.flicker->width << " x " << c.flicker->height
          << ", the camera dollying away from its look-at point (distance x 1 to x "
          << formatNumber(st.dollyEnd)
          << "). **Flicker** = mean over pixels of the standard deviation, "
          << "over the frames, of the pixel's luminance (premultiplied RGB) about its "
          << "least-squares line in the frame index: the smooth change the dolly causes is "
          << "removed, the frame-to-frame jumps of aliasing needles remain. Edges that move "
          << "across pixels count in every method alike.\n\n"
          << "| method | flicker | seconds per frame |\n|---|---|---|\n";
        for (const FlickerRow& f : c.flicker->rows) {
            s << "| " << f.method << " | " << formatNumber(f.flicker) << " | "
              << formatNumber(f.secondsPerFrame, 3) << " |\n";
        }
        s << "\nThe same in [flicker.csv](flicker.csv).\n";
    }
    return s.str();
}

}  // namespace pine::vdbtrace
