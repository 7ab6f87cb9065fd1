// `vdbtrace compare`, the renders: one scene by every method at several settings, each timed
// and measured against the explicit-needle ground truth. Returns data; compare_report.h writes
// it and compare.h runs the whole.
#pragma once

#include "pine/scenes/scene.h"
#include "pine/vdbtrace/image.h"
#include "pine/vdbtrace/image_diff.h"

#include <functional>
#include <optional>
#include <string>
#include <vector>

namespace pine::vdbtrace {

/// What is rendered. `forQuick(false)` is the full sweep, `forQuick(true)` a short one.
struct CompareSettings {
    int truthSamples = 64;                        ///< geometry spp taken as the ground truth
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
    double seconds = 0.0;
    std::optional<double> prepSeconds;  ///< what the method prepared first (in `seconds`)
    Image image;
    ImageErrors errors;
    bool truth = false;
    std::string stem() const { return method + "_" + setting; }
};

struct CompareRun {
    std::vector<CompareRow> rows;  ///< the truth first
    double buildSeconds = 0.0;     ///< trees grown, BVH: not in rows
};

/// A line of progress for a person (one per render).
using CompareLog = std::function<void(const std::string&)>;

/// Renders `scene` with every method and setting of `settings` and measures each against the
/// truth. Throws what preparing and rendering throw.
CompareRun runComparison(const scenes::Scene& scene, const CompareSettings& settings,
                         const CompareLog& log);

/// A number for a person: `digits` significant digits.
std::string formatNumber(double value, int digits = 4);

/// The fastest geometry render of the sweep (not the truth) with RMSE <= `rmse`, or null.
const CompareRow* cheapestGeometryWithin(const std::vector<CompareRow>& rows, double rmse);
/// The row of `method` at `setting`, or null.
const CompareRow* findRow(const std::vector<CompareRow>& rows, const std::string& method,
                          const std::string& setting);

}  // namespace pine::vdbtrace
