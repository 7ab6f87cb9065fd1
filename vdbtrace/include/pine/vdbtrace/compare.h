// `vdbtrace compare`: what accuracy costs in time. One scene rendered by every method at
// several settings, each timed and measured against the explicit-needle ground truth, and the
// temporal aliasing of a camera dolly; written as CSV, images, a plot and a report to read.
#pragma once

#include <filesystem>
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

struct CompareOptions {
    std::filesystem::path sceneFile;
    std::filesystem::path outDir;
    CompareSettings settings;
    int width = 0, height = 0;  ///< override of the camera's resolution (0: the scene's)
    bool plot = true;           ///< run scripts/plot_compare.py for error_vs_time.png
    bool flicker = true;        ///< render the dolly (flicker.csv)
};

/// Runs the comparison into `outDir` (created): report.csv, report.md, flicker.csv, each image
/// as EXR + PNG preview + error map, error_vs_time.png. Progress on stderr, one summary line
/// last. Returns 0. Throws InputError if `outDir` cannot be written (before any work), and
/// what loading and rendering throw. Failed plotting only warns.
int runCompare(const CompareOptions& options);

/// "WxH" -> width, height (both >= 1); false if malformed.
bool parseResolution(const std::string& text, int& width, int& height);

}  // namespace pine::vdbtrace
