// `vdbtrace compare`, the report: what runComparison measured, as a person and a plot script
// read it (report.csv, report.md, flicker.csv, each image with its error map).
#pragma once

#include "pine/vdbtrace/compare_run.h"
#include "pine/vdbtrace/dolly.h"

#include <filesystem>
#include <string>

namespace pine::vdbtrace {

/// What the report says besides the rows.
struct ReportInfo {
    std::filesystem::path sceneFile;
    CompareSettings settings;
    std::string machine;              ///< CPU, cores and threads, as the tool found them
    double errorScale = 1.0;          ///< luminance error shown white in every error map
    bool plotted = false;             ///< error_vs_time.png and error_vs_scale.png exist
    bool treePlot = false;            ///< tree_bias.png exists
    const DollyFlicker* flicker = nullptr;  ///< null: no dolly was rendered
};

/// One row a render: method, setting, CPU seconds (median, least, most), wall and prep
/// seconds, errors (overall, by level, at every scale), foliage and per-tree biases; then the
/// truth's own error against its check as the row `truth_check`.
std::string reportCsv(const CompareRun& run);
/// One row a method's tree: coverage and mean foliage luminance, its own and the truth's.
std::string treesCsv(const CompareRun& run);
std::string flickerCsv(const DollyFlicker& flicker);
/// `scene` as rendered (its resolution).
std::string reportMd(const CompareRun& run, const scenes::Scene& scene, const ReportInfo& info);

/// The error maps' common scale: the 99th percentile of every pixel's error over all renders
/// but the truth, so one outlier does not darken every map and equal colours mean equal error.
double commonErrorScale(const std::vector<CompareRow>& rows);

/// Each row's EXR (as `render` writes it, exr_output.h, with its method and setting in the
/// header), PNG preview over the scene's background and, but for the truth, its error map at
/// `errorScale`, into `dir`.
void writeRowImages(const CompareRun& run, const std::filesystem::path& sceneFile,
                    const scenes::Scene& scene, double errorScale,
                    const std::filesystem::path& dir);

}  // namespace pine::vdbtrace
