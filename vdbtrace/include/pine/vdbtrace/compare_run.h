// `vdbtrace compare`, the renders: one scene by every method at several settings, each timed
// and measured against the explicit-needle ground truth. Returns data; compare_report.h writes
// it and compare.h runs the whole.
#pragma once

#include "pine/scenes/scene.h"
#include "pine/vdbtrace/error_budget.h"
#include "pine/vdbtrace/image.h"
#include "pine/vdbtrace/image_diff.h"
#include "pine/vdbtrace/tree_foliage.h"

#include <filesystem>
#include <functional>
#include <optional>
#include <string>
#include <vector>

namespace pine::vdbtrace {

/// What is rendered. `forQuick(false)` is the full sweep, `forQuick(true)` a short one.
struct CompareSettings {
    int truthSamples = 64;                        ///< geometry spp taken as the ground truth
    /// The truth's shift of the sample sequence (GeometryOptions::sampleSeed); the sweep's is
    /// 0. A truth sharing the sweep's first samples shares their noise and flatters them.
    unsigned truthSeed = 1;
    /// The truth is measured against a render of this many times its samples (another shift):
    /// its own error, which the methods' must exceed for theirs to mean anything. 0: none.
    int truthCheckFactor = 4;
    /// Runs of each render (odd: an even count takes the upper of the middle two); its time is
    /// the median run's by CPU seconds, with the least and the most (a shared machine's load
    /// moves single runs by a third). The runs go round by round, each setting once a round,
    /// so that every setting is timed across the whole comparison's drift, not in one stretch
    /// of it. The truth and its check are rendered once, first.
    int repeat = 3;
    /// Also render the error budget (error_budget.h): every alternative of every model
    /// choice alone, multiscale (auto) or the reference at the finest voxel size.
    bool budget = true;
    std::vector<int> geometrySamples{1, 4, 16};   ///< the geometry method's sweep
    std::vector<double> voxelSizes_cm{1.0, 0.5, 0.25};  ///< the reference's sweep
    int subpixels = 2;                            ///< reference rays per pixel along each axis
    std::vector<int> levels{1, 2, 3, 0};          ///< multiscale forced levels, 0: automatic
    int frames = 16;                              ///< the dolly's frames
    double dollyEnd = 1.3;   ///< last frame's camera distance / first frame's, same look-at
    int frameDivisor = 1;    ///< the dolly's frames at resolution / this

    static CompareSettings forQuick(bool quick);
};

/// One render of the sweep and its error against the ground truth.
struct CompareRow {
    std::string method, setting;  ///< as the report names them ("truth" among the methods)
    std::string renderer;         ///< the registered method that rendered it (methods.h)
    /// Process CPU seconds (all threads) of the median of the runs by CPU seconds, what the
    /// method prepares first included; the least and the most of the runs; the median run's
    /// wall seconds.
    double seconds = 0.0, secondsMin = 0.0, secondsMax = 0.0, wallSeconds = 0.0;
    int runs = 1;
    std::optional<double> prepSeconds;  ///< wall seconds the method prepared first
    Image image;
    ImageErrors errors;
    /// Each tree's foliage summed fragment by fragment (empty where the method knows no
    /// trees), and its biases against the truth's (trees of at least 20 pixels).
    std::vector<TreeFoliageSum> treeFoliage;
    std::vector<TreeBias> treeBiases;
    TreeBiasSummary trees;
    /// All the foliage together against the truth's: coverage and mean luminance, ratio - 1
    /// (unset where the method knows no trees).
    std::optional<double> foliageCoverageBias, foliageLuminanceBias;
    bool truth = false;
    std::string stem() const { return method + "_" + setting; }
};

/// The truth against a render of truthCheckFactor times its samples.
struct TruthCheck {
    int samples = 0;
    ImageErrors errors;
};

/// One approximation of the error budget and its render (its image dropped once measured).
struct BudgetRow {
    BudgetSwitch what;
    CompareRow row;
};

struct CompareRun {
    std::vector<CompareRow> rows;  ///< the truth first
    std::optional<TruthCheck> truthCheck;
    std::vector<BudgetRow> budget;
    double buildSeconds = 0.0;     ///< trees grown, BVH: not in rows
    std::string load;              ///< the machine's load averages before and after the renders
};

/// A line of progress for a person (one per render).
using CompareLog = std::function<void(const std::string&)>;

/// Renders `scene` with every method and setting of `settings` and measures each against the
/// truth. Throws InputError where the methods cannot compute the same effects (checkEffects),
/// and what preparing and rendering throw.
CompareRun runComparison(const scenes::Scene& scene, const CompareSettings& settings,
                         const CompareLog& log);

/// Every method must compute the effects the scene names, or the comparison measures the
/// effects, not the methods. Explicit needles and baked volumes shade through their own bough
/// as through any other, so "shadows" and "self_shadowing" come together or not at all:
/// throws InputError naming the methods that cannot otherwise.
void checkEffects(const scenes::Effects& effects);

/// The scene a comparison renders (`compare`, `animate-compare`): read, `model` (the command
/// line's overrides) applied, "self_shadowing" added where the effects name "shadows" if
/// `addSelfShadowing`, its effects checked (checkEffects), and the camera's resolution
/// replaced where `width` and `height` are > 0 (fov_deg is vertical: the view is kept, exactly
/// when the aspect is). Throws what loadScene and checkEffects throw.
scenes::Scene loadComparedScene(const std::filesystem::path& file,
                                const std::function<void(scenes::RenderSettings&)>& model,
                                bool addSelfShadowing, int width, int height);

/// A number for a person: `digits` significant digits.
std::string formatNumber(double value, int digits = 4);

/// A row's RMSE after box-downsampling by k (ImageErrors::byScale); per pixel where the image
/// has no whole k x k block.
double rmseAtScale(const CompareRow& row, int k);
/// The fastest geometry render of the sweep (not the truth) whose RMSE at scale k is at most
/// `rmse`, or null.
const CompareRow* cheapestGeometryWithin(const std::vector<CompareRow>& rows, double rmse,
                                         int k = 1);
/// The row of `method` at `setting`, or null.
const CompareRow* findRow(const std::vector<CompareRow>& rows, const std::string& method,
                          const std::string& setting);

}  // namespace pine::vdbtrace
