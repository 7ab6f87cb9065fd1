// `vdbtrace compare`: what accuracy costs in time. The renders (compare_run.h), the camera
// dolly's flicker (dolly.h) and the report (compare_report.h), run in order into one folder.
#pragma once

#include "pine/vdbtrace/compare_run.h"

#include <filesystem>
#include <functional>
#include <string>

namespace pine::vdbtrace {

struct CompareOptions {
    std::filesystem::path sceneFile;
    std::filesystem::path outDir;
    CompareSettings settings;
    /// Adjusts the scene's render settings after it is read (the command line's model overrides).
    std::function<void(scenes::RenderSettings&)> model;
    int width = 0, height = 0;  ///< override of the camera's resolution (0: the scene's)
    /// Adds "self_shadowing" where the scene's effects name "shadows": the explicit needles
    /// always self-shadow, so a scene with "shadows" alone is compared with both
    /// (checkEffects); a scene without shadows is left as it is.
    bool addSelfShadowing = false;
    double maxMemoryBytes = 0.0;  ///< refuse, before any work, a run estimated to need more
    bool flicker = true;        ///< render the dolly (flicker.csv)
    std::string machine = "unknown machine";  ///< for the report: CPU, cores, threads
    CompareLog log;             ///< progress lines for a person; the last one sums up
    CompareLog warn;            ///< what went wrong but did not stop the run (null: to log)
    /// Draws error_vs_time.png and error_vs_scale.png from report.csv in the folder; true if
    /// it did. Null: no plot.
    std::function<bool(const std::filesystem::path& dir)> plot;
};

/// Runs the comparison into `outDir` (created): report.csv, trees.csv, report.md, flicker.csv,
/// each image as EXR + PNG preview + error map, error_vs_time.png and error_vs_scale.png if
/// `plot` draws them. Throws InputError if `outDir` cannot be written or the methods cannot
/// compute the scene's effects alike (before any work), and what loading and rendering throw.
CompareRun runCompare(const CompareOptions& options);

/// "WxH" -> width, height (both in [1, 16384], as a scene's camera); false if malformed.
bool parseResolution(const std::string& text, int& width, int& height);

}  // namespace pine::vdbtrace
