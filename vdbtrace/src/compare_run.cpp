#include "pine/vdbtrace/compare_run.h"

#include "pine/support/input_error.h"
#include "pine/support/process_clock.h"
#include "pine/vdbtrace/error_budget.h"
#include "pine/vdbtrace/methods.h"

#include <algorithm>
#include <deque>
#include <fstream>
#include <iomanip>
#include <optional>
#include <sstream>

namespace pine::vdbtrace {
namespace {

// One setting the comparison times: the method, the scene each run renders from, and its runs
// so far (process CPU, wall and preparation seconds); for an error budget's row, the switch it
// measures.
struct Timed {
    std::function<const TracedScene&(int run)> sceneFor;
    std::string method, label, setting;
    MethodSettings settings;
    struct Run {
        double cpu, wall, prep;
    };
    std::vector<Run> runs;
    std::optional<BudgetSwitch> budget;
};

// Renders t once more; returns the render (every run renders the same image).
RenderResult renderOnce(Timed& t)
{
    const TracedScene& scene = t.sceneFor(int(t.runs.size()));
    const double cpu = io::processCpuSeconds();
    RenderResult r = renderMethod(t.method).render(scene, t.settings, {});
    t.runs.push_back({io::processCpuSeconds() - cpu, r.seconds, r.prepSeconds});
    return r;
}

// t's row with its first render's image and trees; its times come with timeRow.
CompareRow rowOf(const Timed& t, RenderResult first)
{
    CompareRow row;
    row.image = std::move(first.image);
    row.treeFoliage = std::move(first.treeFoliage);
    row.method = t.label;
    row.renderer = t.method;
    row.setting = t.setting;
    return row;
}

// The row's times from t's runs: the median run by CPU seconds, the least and the most.
void timeRow(CompareRow& row, Timed t)
{
    auto& runs = t.runs;
    std::sort(runs.begin(), runs.end(),
              [](const Timed::Run& a, const Timed::Run& b) { return a.cpu < b.cpu; });
    const Timed::Run& median = runs[runs.size() / 2];
    row.seconds = median.cpu;
    row.secondsMin = runs.front().cpu;
    row.secondsMax = runs.back().cpu;
    row.wallSeconds = median.wall;
    row.runs = int(runs.size());
    if (t.method != "multiscale") row.prepSeconds = median.prep;
}

// The load averages over 1, 5 and 15 minutes, as /proc/loadavg has them.
std::string loadAverages()
{
    std::ifstream in("/proc/loadavg");
    double a = 0, b = 0, c = 0;
    if (!(in >> a >> b >> c)) return "unknown";
    std::ostringstream s;
    s << a << ' ' << b << ' ' << c;
    return s.str();
}

// Biases against the truth, where both know their trees.
void measureTrees(CompareRow& row, const CompareRow& truth)
{
    if (row.treeFoliage.empty() || truth.treeFoliage.empty()) return;
    row.treeBiases = treeBiases(row.treeFoliage, truth.treeFoliage);
    row.trees = summarizeTreeBiases(row.treeBiases);
    const auto total = [](const std::vector<TreeFoliageSum>& sums) {
        TreeFoliageSum all;
        for (const TreeFoliageSum& t : sums) {
            all.coverage_px += t.coverage_px;
            all.luminance += t.luminance;
        }
        return all;
    };
    const TreeFoliageSum a = total(row.treeFoliage), b = total(truth.treeFoliage);
    // The luminance bias is undefined where the truth's foliage is black; its coverage's
    // stands.
    if (b.coverage_px > 0.0) row.foliageCoverageBias = a.coverage_px / b.coverage_px - 1.0;
    if (b.coverage_px > 0.0 && b.luminance > 0.0 && a.coverage_px > 0.0) {
        row.foliageLuminanceBias =
            (a.luminance / a.coverage_px) / (b.luminance / b.coverage_px) - 1.0;
    }
}

}  // namespace

void checkEffects(const scenes::Effects& effects)
{
    if (effects.shadows == effects.selfShadowing) return;
    const std::string named = effects.shadows ? "shadows" : "self_shadowing";
    const std::string missing = effects.shadows ? "self_shadowing" : "shadows";
    throw InputError("the scene names \"" + named + "\" without \"" + missing +
                     "\", which geometry and reference cannot render (their needles and "
                     "voxels shade through their own bough as through any other): add \"" +
                     missing + "\" to the scene's effects" +
                     (effects.shadows ? " (compare --self-shadowing adds it)" : "") +
                     " so that every method computes the same effects");
}

scenes::Scene loadComparedScene(const std::filesystem::path& file,
                                const std::function<void(scenes::RenderSettings&)>& model,
                                bool addSelfShadowing, int width, int height)
{
    scenes::Scene scene = scenes::loadScene(file);
    if (model) model(scene.render);
    if (addSelfShadowing) scene.effects.selfShadowing |= scene.effects.shadows;
    checkEffects(scene.effects);
    if (width > 0 && height > 0) {
        scene.camera.width = width;
        scene.camera.height = height;
    }
    return scene;
}

CompareSettings CompareSettings::forQuick(bool quick)
{
    CompareSettings s;
    if (quick) {
        s.truthSamples = 16;
        s.repeat = 1;
        s.geometrySamples = {1, 4};
        s.voxelSizes_cm = {1.0, 0.5};
        s.frames = 8;
        s.frameDivisor = 2;
    }
    return s;
}

std::string formatNumber(double value, int digits)
{
    std::ostringstream s;
    s << std::setprecision(digits) << value;
    return s.str();
}

CompareRun runComparison(const scenes::Scene& scene, const CompareSettings& st,
                         const CompareLog& log)
{
    checkEffects(scene.effects);
    using Clock = std::chrono::steady_clock;
    CompareRun run;
    run.load = loadAverages();
    const auto buildStart = Clock::now();
    const TracedScene traced = buildTracedScene(scene);
    run.buildSeconds = std::chrono::duration<double>(Clock::now() - buildStart).count();
    if (log) log("scene built in " + formatNumber(run.buildSeconds, 3) + " s");
    const auto built = [&](int) -> const TracedScene& { return traced; };
    // The bough law's profiles are computed as a multiscale render first needs them
    // (traced_scene.h) and belong to its time: each run starts from a scene of its own, so
    // that none inherits another's. One at a time: the last is let go before the next is built.
    std::optional<TracedScene> own;
    const auto builtAgainFrom = [&own](const scenes::Scene& from) {
        return [&own, &from](int) -> const TracedScene& {
            own.reset();
            own.emplace(buildTracedScene(from));
            return *own;
        };
    };

    // A row's errors and its trees' biases against the truth (the first row).
    const auto assess = [&](CompareRow& row) {
        const CompareRow& truth = run.rows.empty() ? row : run.rows.front();
        row.errors = compareImages(row.image, truth.image);
        measureTrees(row, truth);
    };
    const auto report = [&](const CompareRow& row) {
        if (!log) return;
        std::string line =
            row.method + " " + row.setting + ": " + formatNumber(row.seconds, 3) + " CPU-s";
        if (row.runs > 1) {
            line += " [" + formatNumber(row.secondsMin, 3) + ", " +
                    formatNumber(row.secondsMax, 3) + "]";
        }
        if (row.prepSeconds) line += " (" + formatNumber(*row.prepSeconds, 3) + " s preparation)";
        if (!row.truth) line += ", rmse " + formatNumber(row.errors.rmse);
        if (!row.truth && row.trees.luminance.defined) {
            line += ", per-tree luminance median " +
                    formatNumber(100.0 * row.trees.luminance.median, 3) + "%";
        }
        log(line);
    };
    MethodSettings s;
    s.geometry.samples = st.truthSamples;
    s.geometry.sampleSeed = st.truthSeed;
    {
        Timed t{built, "geometry", "truth", std::to_string(st.truthSamples) + "spp", s, {}, {}};
        RenderResult first = renderOnce(t);
        CompareRow truth = rowOf(t, std::move(first));
        timeRow(truth, std::move(t));
        truth.truth = true;
        assess(truth);
        report(truth);
        run.rows.push_back(std::move(truth));
    }
    if (st.truthCheckFactor > 0) {
        MethodSettings check = s;
        check.geometry.samples = st.truthSamples * st.truthCheckFactor;
        check.geometry.sampleSeed = st.truthSeed + 1;
        if (check.geometry.sampleSeed == 0) ++check.geometry.sampleSeed;
        const RenderResult r = renderMethod("geometry").render(traced, check, {});
        run.truthCheck =
            TruthCheck{check.geometry.samples, compareImages(run.rows.front().image, r.image)};
        if (log) {
            log("truth against " + std::to_string(check.geometry.samples) + " spp: rmse " +
                formatNumber(run.truthCheck->errors.rmse));
        }
    }

    // Every timed setting, in the report's order.
    std::vector<Timed> timed;
    s.geometry.sampleSeed = 0;
    for (int n : st.geometrySamples) {
        s.geometry.samples = n;
        timed.push_back({built, "geometry", "geometry", std::to_string(n) + "spp", s, {}, {}});
    }
    s.reference.subpixels = st.subpixels;
    for (double h : st.voxelSizes_cm) {
        s.voxelSize_cm = h;
        timed.push_back({built, "reference", "reference", formatNumber(h) + "cm", s, {}, {}});
    }
    for (int level : st.levels) {
        s.multiscale.forceLevel = level;
        timed.push_back({builtAgainFrom(scene),
                         "multiscale",
                         "multiscale",
                         level ? "L" + std::to_string(level) : "auto",
                         s,
                         {},
                         {}});
    }
    std::deque<scenes::Scene> switched;  // each budget row's scene, for all its runs
    if (st.budget) {
        // Each switch against the row rendered with the scene's own choices: multiscale
        // (auto), and the reference at the finest voxel size.
        const auto finest = std::min_element(st.voxelSizes_cm.begin(), st.voxelSizes_cm.end());
        const bool automatic = std::find(st.levels.begin(), st.levels.end(), 0) != st.levels.end();
        for (const BudgetSwitch& what : errorBudgetSwitches(scene.render.model)) {
            const bool reference = what.method == "reference";
            if (reference ? finest == st.voxelSizes_cm.end() : !automatic) continue;
            switched.push_back(scene);
            switched.back().render.model = what.model;
            s.multiscale.forceLevel = 0;
            if (reference) s.voxelSize_cm = *finest;
            timed.push_back({builtAgainFrom(switched.back()),
                             what.method,
                             "budget:" + what.method,
                             what.label,
                             s,
                             {},
                             what});
        }
    }
    // Round by round, each setting once a round: the machine's speed drifts over a comparison
    // (by a third and more on the shared 2-core machine), and runs back to back would put each
    // setting's runs in one stretch of it; spread over all of it, their ratios hold better.
    std::vector<CompareRow> rows(timed.size());
    const int rounds = std::max(1, st.repeat);
    for (int round = 0; round < rounds; ++round) {
        for (std::size_t i = 0; i < timed.size(); ++i) {
            RenderResult r = renderOnce(timed[i]);
            if (log && rounds > 1) {
                log("run " + std::to_string(round + 1) + "/" + std::to_string(rounds) + " " +
                    timed[i].label + " " + timed[i].setting + ": " +
                    formatNumber(timed[i].runs.back().cpu, 3) + " CPU-s");
            }
            if (round > 0) continue;  // every run renders the same image
            rows[i] = rowOf(timed[i], std::move(r));
            assess(rows[i]);
            if (timed[i].budget) rows[i].image = Image();  // only its numbers are reported
        }
    }
    for (std::size_t i = 0; i < timed.size(); ++i) {
        std::optional<BudgetSwitch> budget = std::move(timed[i].budget);
        timeRow(rows[i], std::move(timed[i]));
        report(rows[i]);
        if (budget) {
            run.budget.push_back({*budget, std::move(rows[i])});
        } else {
            run.rows.push_back(std::move(rows[i]));
        }
    }
    run.load += " before; " + loadAverages() + " after";
    return run;
}

const CompareRow* findRow(const std::vector<CompareRow>& rows, const std::string& method,
                          const std::string& setting)
{
    for (const CompareRow& r : rows) {
        if (r.method == method && r.setting == setting) return &r;
    }
    return nullptr;
}

double rmseAtScale(const CompareRow& row, int k)
{
    const ImageErrors::AtScale* a = row.errors.atScale(k);
    return a ? a->rmse : row.errors.rmse;
}

const CompareRow* cheapestGeometryWithin(const std::vector<CompareRow>& rows, double rmse, int k)
{
    const CompareRow* cheapest = nullptr;
    for (const CompareRow& r : rows) {
        if (r.method == "geometry" && rmseAtScale(r, k) <= rmse &&
            (!cheapest || r.seconds < cheapest->seconds)) {
            cheapest = &r;
        }
    }
    return cheapest;
}

}  // namespace pine::vdbtrace
