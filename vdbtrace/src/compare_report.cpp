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

// The scale at which "equal error" is stated besides per pixel (issue: a fair comparison).
constexpr int kNamedScale = 4;

std::string percent(double fraction)
{
    return std::isnan(fraction) ? "-" : formatNumber(100.0 * fraction, 3) + "%";
}

// A number in the CSV files: empty where it is undefined (NaN), as they leave missing values.
struct Csv {
    double value;
};
std::ostream& operator<<(std::ostream& s, Csv c)
{
    if (!std::isnan(c.value)) s << c.value;
    return s;
}

std::string scaleSection(const CompareRun& run, bool plotted)
{
    std::ostringstream s;
    s << "Both images box-downsampled by k (each whole k x k block's mean; "
         "`ImageErrors::byScale`), then the luminance error over the blocks. A method's noise "
         "falls as 1 / k, its bias stays.\n\n| method | setting |";
    for (const int k : kErrorScales) s << " RMSE k=" << k << " |";
    for (const int k : kErrorScales) s << " MAE k=" << k << " |";
    s << "\n|---|---|";
    for (std::size_t i = 0; i < 2 * std::size(kErrorScales); ++i) s << "---|";
    s << '\n';
    for (const CompareRow& r : run.rows) {
        if (r.truth) continue;
        s << "| " << r.method << " | " << r.setting << " |";
        for (const int k : kErrorScales) {
            const ImageErrors::AtScale* a = r.errors.atScale(k);
            s << ' ' << (a ? formatNumber(a->rmse) : "-") << " |";
        }
        for (const int k : kErrorScales) {
            const ImageErrors::AtScale* a = r.errors.atScale(k);
            s << ' ' << (a ? formatNumber(a->mae) : "-") << " |";
        }
        s << '\n';
    }
    if (run.truthCheck) {
        s << "| truth's own error | against " << run.truthCheck->samples << " spp |";
        for (const int k : kErrorScales) {
            const ImageErrors::AtScale* a = run.truthCheck->errors.atScale(k);
            s << ' ' << (a ? formatNumber(a->rmse) : "-") << " |";
        }
        for (const int k : kErrorScales) {
            const ImageErrors::AtScale* a = run.truthCheck->errors.atScale(k);
            s << ' ' << (a ? formatNumber(a->mae) : "-") << " |";
        }
        s << '\n';
    }
    if (plotted) s << "\n![RMSE against scale](error_vs_scale.png)\n";
    return s.str();
}

std::string truthSection(const CompareRun& run, const CompareSettings& st)
{
    std::ostringstream s;
    s << "The truth is the geometry method (explicit needles) at " << st.truthSamples
      << " samples per pixel on its own shift of the sample sequence (seed " << st.truthSeed
      << "; the sweep's renders use seed 0), so that its noise is independent of theirs.";
    if (!run.truthCheck) {
        s << " Its convergence was not checked (truthCheckFactor 0).\n";
        return s.str();
    }
    const double own = run.truthCheck->errors.rmse;
    double least = -1.0;
    const CompareRow* closest = nullptr;
    for (const CompareRow& r : run.rows) {
        if (!r.truth && (!closest || r.errors.rmse < least)) {
            least = r.errors.rmse;
            closest = &r;
        }
    }
    s << " Against a render of " << run.truthCheck->samples
      << " samples per pixel (another seed) its own RMSE is " << formatNumber(own) << " per pixel";
    if (const ImageErrors::AtScale* a = run.truthCheck->errors.atScale(kNamedScale)) {
        s << " and " << formatNumber(a->rmse) << " at k = " << kNamedScale;
    }
    const double f = double(run.truthCheck->samples) / st.truthSamples;
    s << " (the check's own noise is in it: with f = " << formatNumber(f)
      << " times the samples, sqrt(1 + 1 / f) = " << formatNumber(std::sqrt(1.0 + 1.0 / f), 3)
      << " times the truth's alone).";
    if (closest) {
        s << " The closest render of the sweep, " << closest->method << ' ' << closest->setting
          << ", has " << formatNumber(least) << " per pixel: ";
        if (own <= least / 3.0) {
            s << "the truth's own error is at most a third of it, so the truth is converged "
                 "enough for this comparison.";
        } else {
            s << "**the truth's own error is more than a third of it: the truth is not "
                 "converged enough to rank the closest renders**; use more truth samples.";
        }
    }
    s << '\n';
    return s.str();
}

// Every row the CSVs list: the sweep's (the truth too if `truth`), then the budget's.
std::vector<const CompareRow*> sweepThenBudget(const CompareRun& run, bool truth)
{
    std::vector<const CompareRow*> rows;
    for (const CompareRow& r : run.rows) {
        if (truth || !r.truth) rows.push_back(&r);
    }
    for (const BudgetRow& b : run.budget) rows.push_back(&b.row);
    return rows;
}

// "value (change)" of a switched row against its own.
std::string withChange(double value, double own, bool asPercent)
{
    const double d = value - own;
    if (std::isnan(d)) return asPercent ? percent(value) : formatNumber(value);  // undefined
    if (asPercent) {
        return percent(value) + " (" + (d >= 0.0 ? "+" : "") + formatNumber(100.0 * d, 3) + " pts)";
    }
    return formatNumber(value) + " (" + (d >= 0.0 ? "+" : "") + formatNumber(d, 3) + ")";
}

std::string budgetLine(const std::string& what, const std::string& paper, const std::string& method,
                       const CompareRow& row, const CompareRow& own)
{
    std::ostringstream s;
    s << "| " << what << " | " << paper << " | " << method << " | "
      << withChange(row.errors.rmse, own.errors.rmse, false) << " | "
      << withChange(rmseAtScale(row, kNamedScale), rmseAtScale(own, kNamedScale), false) << " | ";
    if (row.trees.trees && own.trees.trees) {
        s << withChange(row.trees.luminance.median, own.trees.luminance.median, true) << " | "
          << row.trees.luminance.beyond << " (" << own.trees.luminance.beyond << ") | ";
    } else {
        s << " | | ";
    }
    if (row.foliageLuminanceBias && own.foliageLuminanceBias) {
        s << withChange(*row.foliageLuminanceBias, *own.foliageLuminanceBias, true);
    }
    const double saved = own.seconds - row.seconds;
    s << " | " << formatNumber(row.seconds, 3) << " (" << (saved >= 0.0 ? "saves " : "costs ")
      << formatNumber(100.0 * std::abs(saved) / std::max(own.seconds, 1e-12), 4) << "%) |\n";
    return s.str();
}

std::string budgetSection(const CompareRun& run)
{
    std::ostringstream s;
    const CompareRow* ownMultiscale = findRow(run.rows, "multiscale", "auto");
    const CompareRow* finest = nullptr;
    for (const CompareRow& r : run.rows) {
        if (r.method == "reference" &&
            (!finest || std::stod(r.setting) < std::stod(finest->setting))) {
            finest = &r;
        }
    }
    if (run.budget.empty() && !finest) return "No error budget was rendered.\n";
    s << "Each approximation switched alone from the scene's own choice (`error_budget.h`: "
         "every alternative of every model choice, the paper's marked), and every choice the "
         "paper's at once, against the render with the scene's own choices (multiscale auto; "
         "the reference at its finest voxels): its error per pixel and at k = "
      << kNamedScale
      << ", its per-tree bias (median, trees beyond 3%), the bias of all its foliage, and "
         "its CPU time, each with its change (a negative added error: the switch is nearer "
         "the truth). The reference's voxel size is the last rows'.\n\n"
         "| approximation | the paper's | method | RMSE (added) | RMSE k="
      << kNamedScale
      << " (added) | per-tree luminance median | trees > 3% (own) | all foliage luminance | "
         "CPU s |\n"
         "|---|---|---|---|---|---|---|---|---|\n";
    for (const BudgetRow& b : run.budget) {
        const CompareRow* own = b.what.method == "reference" ? finest : ownMultiscale;
        if (!own) continue;
        s << budgetLine(b.what.label, b.what.paper ? "yes" : "", b.what.method, b.row, *own);
    }
    for (const CompareRow& r : run.rows) {
        if (finest && r.method == "reference" && &r != finest) {
            s << budgetLine("voxel size " + r.setting + " (not " + finest->setting + ")", "",
                            "reference", r, *finest);
        }
    }
    return s.str();
}

std::string treeSection(const CompareRun& run, bool treePlot)
{
    std::ostringstream s;
    const CompareRow& truth = run.rows.front();
    if (truth.treeFoliage.empty()) return "The truth knows no trees: no per-tree bias.\n";
    s << "Each tree's foliage summed fragment by fragment by each render (a pixel two trees "
         "share gives each its part; `tree_foliage_tally.h`): its coverage and its mean "
         "foliage luminance against the truth's, for the trees the truth shows over at least "
         "20 pixels ("
      << truth.treeFoliage.size() << " trees shown, ";
    std::size_t compared = 0;
    for (const CompareRow& r : run.rows) compared = std::max(compared, r.trees.trees);
    s << compared << " compared). Median, worst (with its tree) and trees off by more than "
      << "3%; \"all foliage\" sums every tree. Every tree's numbers: trees.csv.\n\n"
         "| method | setting | all foliage: coverage | luminance | per tree, luminance: "
         "median | worst | > 3% | coverage: median | worst | > 3% |\n"
         "|---|---|---|---|---|---|---|---|---|---|\n";
    for (const CompareRow& r : run.rows) {
        if (r.truth) continue;
        s << "| " << r.method << " | " << r.setting << " | ";
        if (!r.foliageCoverageBias || !r.trees.trees) {
            s << "(knows no trees) | | | | | | | |\n";
            continue;
        }
        const auto& l = r.trees.luminance;
        const auto& c = r.trees.coverage;
        // "-" where no tree's bias is defined (every tree black in the truth).
        const auto worst = [](const TreeBiasSummary::Spread& spread) {
            return spread.defined
                       ? percent(spread.worst) + " (tree " + std::to_string(spread.worstTree) + ")"
                       : std::string("-");
        };
        s << percent(*r.foliageCoverageBias) << " | "
          << (r.foliageLuminanceBias ? percent(*r.foliageLuminanceBias) : "-") << " | "
          << percent(l.median) << " | " << worst(l) << " | " << l.beyond << " | "
          << percent(c.median) << " | " << worst(c) << " | " << c.beyond << " |\n";
    }
    if (treePlot) s << "\n![Bias per tree](tree_bias.png)\n";
    // The trees a reader should look at first: multiscale's farthest from the truth.
    const CompareRow* ms = findRow(run.rows, "multiscale", "auto");
    if (ms && !ms->treeBiases.empty()) {
        std::vector<const TreeBias*> worst;
        for (const TreeBias& t : ms->treeBiases) worst.push_back(&t);
        std::sort(worst.begin(), worst.end(), [](const TreeBias* a, const TreeBias* b) {
            // Undefined biases (a black tree in the truth) last.
            const double x = std::abs(a->luminanceBias), y = std::abs(b->luminanceBias);
            return std::isnan(y) ? !std::isnan(x) : x > y;
        });
        worst.resize(std::min<std::size_t>(worst.size(), 5));
        s << "\nMultiscale (auto)'s trees farthest from the truth in luminance:";
        for (const TreeBias* t : worst) {
            s << (t == worst.front() ? " " : "; ") << "tree " << t->truth.tree << " ("
              << std::lround(t->truth.coverage) << " px of foliage) "
              << (std::isnan(t->luminanceBias) ? "luminance undefined (black in the truth)"
                                               : percent(t->luminanceBias))
              << ", coverage " << percent(t->coverageBias);
        }
        s << ".\n";
    }
    return s.str();
}

std::string speedAt(const std::vector<CompareRow>& rows, int k)
{
    std::ostringstream s;
    const CompareRow* ms = findRow(rows, "multiscale", "auto");
    if (!ms) return "Multiscale (auto) was not rendered.\n";
    const double e = rmseAtScale(*ms, k);
    const CompareRow* cheapest = cheapestGeometryWithin(rows, e, k);
    s << "- **" << (k == 1 ? "per pixel (k = 1)" : "at k = " + std::to_string(k))
      << "**: multiscale (auto) RMSE " << formatNumber(e) << " in " << formatNumber(ms->seconds, 3)
      << " CPU-s. ";
    if (cheapest) {
        const double ratio = cheapest->seconds / ms->seconds;
        s << "The cheapest geometry setting at equal or lower RMSE is " << cheapest->setting << " ("
          << formatNumber(rmseAtScale(*cheapest, k)) << ", " << formatNumber(cheapest->seconds, 3)
          << " CPU-s, its BVH included): speed ratio "
          << "(geometry / multiscale) **" << formatNumber(ratio, 3) << "**, "
          << (ratio >= 1.0 ? "multiscale " + formatNumber(ratio, 3) + " times faster"
                           : "geometry " + formatNumber(1.0 / ratio, 3) + " times faster")
          << ".\n";
    } else {
        const CompareRow* best = nullptr;
        for (const CompareRow& r : rows) {
            if (r.method == "geometry" && (!best || rmseAtScale(r, k) < rmseAtScale(*best, k)))
                best = &r;
        }
        s << "**No geometry setting of the sweep reaches it**";
        if (best) {
            s << " (the best, " << best->setting << ", has " << formatNumber(rmseAtScale(*best, k))
              << " in " << formatNumber(best->seconds, 3) << " CPU-s)";
        }
        s << "; no ratio is extrapolated.\n";
    }
    return s.str();
}

std::string speedSection(const std::vector<CompareRow>& rows)
{
    return speedAt(rows, 1) + speedAt(rows, kNamedScale) + '\n' +
           "At k = " + std::to_string(kNamedScale) +
           " a block of pixels averages the needles' texture, as a viewer a little farther "
           "away sees it: a per-pixel noise falls by k there, a bias does not, so a method "
           "that is noisy but unbiased gains on one that is smooth but biased.\n";
}

std::string levelSection(const std::vector<CompareRow>& rows)
{
    std::ostringstream s;
    const CompareRow* ms = findRow(rows, "multiscale", "auto");
    if (!ms || !hasLevels(*ms)) return "No multiscale level AOV: nothing to split.\n";
    const auto& l = ms->errors.byLevel;
    const char* names[4] = {"no foliage (ground and its shadows, sky, branches)", "needle",
                            "cone", "bough"};
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
          << (std::isnan(l[k].meanRelative) ? "-" : formatNumber(l[k].meanRelative)) << " | "
          << formatNumber(100.0 * share, 3) << "% |\n";
    }
    // Needle and cone levels pooled: the foliage shaded without a bough law.
    const double n12 = double(l[1].pixels + l[2].pixels);
    const double rest = n12 > 0.0 ? std::sqrt((double(l[1].pixels) * l[1].rmse * l[1].rmse +
                                               double(l[2].pixels) * l[2].rmse * l[2].rmse) /
                                              n12)
                                  : 0.0;
    s << '\n';
    if (l[3].pixels == 0) {
        s << "No pixel is shaded at the bough level in this view: the bough law does not show "
             "here.\n";
    } else if (n12 == 0.0) {
        s << "Every foliage pixel is at the bough level: RMSE " << formatNumber(l[3].rmse)
          << "; nothing to set it against.\n";
    } else {
        s << "The bough level (the bough law, `render.bough_law`) has RMSE "
          << formatNumber(l[3].rmse)
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

std::string reportCsv(const CompareRun& run)
{
    std::ostringstream s;
    s << "method,setting,seconds,seconds_min,seconds_max,wall_seconds,runs,prep_seconds,rmse,"
         "mean_relative,max_absolute,rmse_needle,rmse_cone,rmse_bough";
    for (const int k : kErrorScales) s << ",rmse_k" << k;
    for (const int k : kErrorScales) s << ",mae_k" << k;
    s << ",foliage_coverage_bias,foliage_luminance_bias,trees,"
         "tree_luminance_median,"
         "tree_luminance_worst,tree_luminance_worst_tree,trees_luminance_beyond_3pct,"
         "tree_coverage_median,tree_coverage_worst,tree_coverage_worst_tree,"
         "trees_coverage_beyond_3pct\n";
    s << std::setprecision(9);
    const auto errorColumns = [&](const ImageErrors& e) {
        for (const int k : kErrorScales) {
            s << ',';
            if (const ImageErrors::AtScale* a = e.atScale(k)) s << a->rmse;
        }
        for (const int k : kErrorScales) {
            s << ',';
            if (const ImageErrors::AtScale* a = e.atScale(k)) s << a->mae;
        }
    };
    for (const CompareRow* row : sweepThenBudget(run, true)) {
        const CompareRow& r = *row;
        s << r.method << ',' << r.setting << ',' << r.seconds << ',' << r.secondsMin << ','
          << r.secondsMax << ',' << r.wallSeconds << ',' << r.runs << ',';
        if (r.prepSeconds) s << *r.prepSeconds;
        s << ',' << r.errors.rmse << ',' << Csv{r.errors.meanRelative} << ','
          << r.errors.maxAbsolute;
        for (int level = 1; level <= 3; ++level) {
            s << ',';
            if (hasLevels(r) && r.errors.byLevel[level].pixels) s << r.errors.byLevel[level].rmse;
        }
        errorColumns(r.errors);
        s << ',';
        if (r.foliageCoverageBias) s << *r.foliageCoverageBias;
        s << ',';
        if (r.foliageLuminanceBias) s << *r.foliageLuminanceBias;
        if (r.trees.trees) {
            const auto& l = r.trees.luminance;
            const auto& c = r.trees.coverage;
            // A worst tree only where some tree's bias is defined.
            const auto worstTree = [](const TreeBiasSummary::Spread& spread) {
                return spread.defined ? std::to_string(spread.worstTree) : std::string();
            };
            s << ',' << r.trees.trees << ',' << Csv{l.median} << ',' << Csv{l.worst} << ','
              << worstTree(l) << ',' << l.beyond << ',' << Csv{c.median} << ',' << Csv{c.worst}
              << ',' << worstTree(c) << ',' << c.beyond;
        } else {
            s << ",,,,,,,,,";
        }
        s << '\n';
    }
    if (run.truthCheck) {
        const ImageErrors& e = run.truthCheck->errors;
        s << "truth_check," << run.truthCheck->samples << "spp,,,,,,," << e.rmse << ','
          << Csv{e.meanRelative} << ',' << e.maxAbsolute << ",,,";
        errorColumns(e);
        s << ",,,,,,,,,,,\n";
    }
    return s.str();
}

std::string treesCsv(const CompareRun& run)
{
    std::ostringstream s;
    s << "method,setting,tree,coverage_px,coverage_px_truth,coverage_bias,luminance,"
         "luminance_truth,luminance_bias\n"
      << std::setprecision(9);
    // The truth's own biases are 0 by definition.
    for (const CompareRow* row : sweepThenBudget(run, false)) {
        const CompareRow& r = *row;
        for (const TreeBias& t : r.treeBiases) {
            s << r.method << ',' << r.setting << ',' << t.truth.tree << ',' << t.image.coverage
              << ',' << t.truth.coverage << ',' << Csv{t.coverageBias} << ',' << t.image.luminance
              << ',' << t.truth.luminance << ',' << Csv{t.luminanceBias} << '\n';
        }
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
        if (!r.treeFoliage.empty()) {
            addTreeFoliage(m, r.treeFoliage, camera.width(), camera.height());
        }
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
    s << "- load averages (1, 5, 15 min): " << run.load << "\n";
    s << "- effects, the same for every method:";
    for (const auto& [on, name] : {std::pair{scene.effects.diffuse, "diffuse"},
                                   std::pair{scene.effects.specular, "specular"},
                                   std::pair{scene.effects.shadows, "shadows"},
                                   std::pair{scene.effects.selfShadowing, "self_shadowing"}}) {
        if (on) s << ' ' << name;
    }
    s << " (`checkEffects`: explicit needles and baked volumes shadow and self-shadow "
         "together, so a scene naming one alone is refused)\n";
    s << "- ground truth: geometry (explicit needles) at " << st.truthSamples << " spp, seed "
      << st.truthSeed << "\n";
    s << "- geometry:";
    for (int n : st.geometrySamples) s << ' ' << n;
    s << " spp; reference: voxels of";
    for (double h : st.voxelSizes_cm) s << ' ' << formatNumber(h);
    s << " cm, " << st.subpixels * st.subpixels << " rays per pixel; multiscale: levels forced "
      << "to 1, 2, 3 and automatic\n";
    s << "- times: process CPU seconds (all threads) of each render, the median of " << st.repeat
      << " run(s) by CPU seconds [the least, the most], the runs made round by round (each "
         "setting once a round; the truth one run, first), what the method "
         "prepares first "
         "included (prep: the geometry's Embree BVH, the reference's bake and light grids, in "
         "wall seconds); the multiscale times include the bough law's per-bough profiles, "
         "computed as the render first needs them, each run from a scene of its own\n";
    s << "- scene build (trees grown, BVH): " << formatNumber(run.buildSeconds, 3)
      << " s wall, excluded from every time below\n\n";
    s << "## The truth\n\n" << truthSection(run, st) << '\n';
    s << "## Error against time\n\n"
         "Errors: linear luminance of premultiplied RGB against the ground truth "
         "(`compareImages`): RMSE over all pixels, mean relative over pixels brighter than 1% "
         "of the truth's mean, maximum, and for multiscale the RMSE over the pixels of each "
         "level.\n\n";
    s << "| method | setting | CPU s | [least, most] | wall s | prep s | RMSE | mean relative | "
         "max | RMSE needle | RMSE cone | RMSE bough |\n"
         "|---|---|---|---|---|---|---|---|---|---|---|---|\n";
    for (const CompareRow& r : rows) {
        s << "| " << r.method << " | " << r.setting << " | " << formatNumber(r.seconds, 3) << " | ";
        if (r.runs > 1) {
            s << '[' << formatNumber(r.secondsMin, 3) << ", " << formatNumber(r.secondsMax, 3)
              << ']';
        }
        s << " | " << formatNumber(r.wallSeconds, 3) << " | "
          << (r.prepSeconds ? formatNumber(*r.prepSeconds, 3) : "") << " | "
          << formatNumber(r.errors.rmse) << " | "
          << (std::isnan(r.errors.meanRelative) ? "-" : formatNumber(r.errors.meanRelative))
          << " | " << formatNumber(r.errors.maxAbsolute);
        for (int level = 1; level <= 3; ++level) {
            s << " | ";
            if (hasLevels(r) && r.errors.byLevel[level].pixels) {
                s << formatNumber(r.errors.byLevel[level].rmse);
            }
        }
        s << " |\n";
    }
    s << "\nEvery number of this report is in "
         "[report.csv](report.csv) (the truth's own error "
         "as the row `truth_check`), each tree's in [trees.csv](trees.csv).\n\n";
    if (c.plotted) s << "![RMSE against CPU seconds](error_vs_time.png)\n\n";
    s << "## Error at every scale\n\n" << scaleSection(run, c.plotted) << '\n';
    s << "## Speed at equal error\n\n" << speedSection(rows) << '\n';
    s << "## Bias per tree\n\n" << treeSection(run, c.treePlot) << '\n';
    s << "## Error budget\n\n" << budgetSection(run) << '\n';
    s << "## Where the bough law's error shows\n\n" << levelSection(rows) << '\n';
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
