#include "pine/vdbtrace/compare_run.h"

#include "pine/vdbtrace/methods.h"

#include <iomanip>
#include <sstream>

namespace pine::vdbtrace {
namespace {

CompareRow render(const TracedScene& traced, const std::string& method, std::string label,
                  std::string setting, const MethodSettings& settings)
{
    RenderResult r = renderMethod(method).render(traced, settings, {});
    CompareRow row;
    row.method = std::move(label);
    row.renderer = method;
    row.setting = std::move(setting);
    row.seconds = r.seconds;
    if (method != "multiscale") row.prepSeconds = r.prepSeconds;
    row.image = std::move(r.image);
    return row;
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

std::string formatNumber(double value, int digits)
{
    std::ostringstream s;
    s << std::setprecision(digits) << value;
    return s.str();
}

CompareRun runComparison(const scenes::Scene& scene, const CompareSettings& st,
                         const CompareLog& log)
{
    using Clock = std::chrono::steady_clock;
    CompareRun run;
    const auto buildStart = Clock::now();
    const TracedScene traced = buildTracedScene(scene);
    run.buildSeconds = std::chrono::duration<double>(Clock::now() - buildStart).count();
    if (log) log("scene built in " + formatNumber(run.buildSeconds, 3) + " s");

    const auto measure = [&](CompareRow row) {
        const CompareRow& truth = run.rows.empty() ? row : run.rows.front();
        row.errors = compareImages(row.image, truth.image);
        if (log) {
            std::string line = row.method + " " + row.setting + ": " +
                               formatNumber(row.seconds, 3) + " s";
            if (row.prepSeconds)
                line += " (" + formatNumber(*row.prepSeconds, 3) + " s preparation)";
            if (!row.truth) line += ", rmse " + formatNumber(row.errors.rmse);
            log(line);
        }
        run.rows.push_back(std::move(row));
    };
    MethodSettings s;
    s.geometry.samples = st.truthSamples;
    CompareRow truth =
        render(traced, "geometry", "truth", std::to_string(st.truthSamples) + "spp", s);
    truth.truth = true;
    measure(std::move(truth));
    for (int n : st.geometrySamples) {
        s.geometry.samples = n;
        measure(render(traced, "geometry", "geometry", std::to_string(n) + "spp", s));
    }
    s.reference.subpixels = st.subpixels;
    for (double h : st.voxelSizes_cm) {
        s.voxelSize_cm = h;
        measure(render(traced, "reference", "reference", formatNumber(h) + "cm", s));
    }
    for (int level : st.levels) {
        s.multiscale.forceLevel = level;
        // The bough law's profiles are computed as a render first needs them (traced_scene.h)
        // and belong to the multiscale method's time: each row starts from a scene of its own,
        // so that none inherits another's.
        const TracedScene fresh = buildTracedScene(scene);
        measure(render(fresh, "multiscale", "multiscale",
                       level ? "L" + std::to_string(level) : "auto", s));
    }
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

const CompareRow* cheapestGeometryWithin(const std::vector<CompareRow>& rows, double rmse)
{
    const CompareRow* cheapest = nullptr;
    for (const CompareRow& r : rows) {
        if (r.method == "geometry" && r.errors.rmse <= rmse &&
            (!cheapest || r.seconds < cheapest->seconds)) {
            cheapest = &r;
        }
    }
    return cheapest;
}

}  // namespace pine::vdbtrace
