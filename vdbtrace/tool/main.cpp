// vdbtrace: render a scene with the multiscale cone tracer, benchmark it, or compare methods.
#include "pine/bake/extinction_law.h"
#include "pine/bake/resource_estimate.h"
#include "pine/bake/tree_boughs.h"
#include "pine/bake/tree_grids.h"
#include "pine/scenes/scene.h"
#include "pine/scenes/tree.h"
#include "pine/support/atomic_file.h"
#include "pine/support/fnv1a.h"
#include "pine/support/folder_lock.h"
#include "pine/support/plot_script.h"
#include "pine/support/process_clock.h"
#include "pine/support/progress.h"
#include "pine/support/tool_main.h"
#include "pine/vdbtrace/animation_report.h"
#include "pine/vdbtrace/compare.h"
#include "pine/vdbtrace/cone_camera.h"
#include "pine/vdbtrace/exr_output.h"
#include "pine/vdbtrace/frame_parts.h"
#include "pine/vdbtrace/frame_sequence.h"
#include "pine/vdbtrace/geometry_tracer.h"
#include "pine/vdbtrace/image.h"
#include "pine/vdbtrace/image_diff.h"
#include "pine/vdbtrace/integer_list.h"
#include "pine/vdbtrace/layer_model.h"
#include "pine/vdbtrace/methods.h"
#include "pine/vdbtrace/multiscale_tracer.h"
#include "pine/vdbtrace/preview.h"
#include "pine/vdbtrace/ranks.h"
#include "pine/vdbtrace/reference_tracer.h"
#include "pine/vdbtrace/scene_growth.h"
#include "pine/vdbtrace/stats_json.h"
#include "pine/vdbtrace/traced_scene.h"
#include "pine/vdbtrace/tree_foliage.h"

#include <sched.h>
#include <tbb/global_control.h>
#include <tbb/task_arena.h>
#include <CLI/CLI.hpp>

#include <algorithm>
#include <cctype>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <functional>
#include <iostream>
#include <limits>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <set>
#include <sstream>
#include <thread>

namespace {

using namespace pine;
namespace fs = std::filesystem;

/// Options whose progress `shown` reports.
vdbtrace::RenderOptions withProgress(tool::Progress& shown)
{
    vdbtrace::RenderOptions options;
    options.progress = [&shown](double fraction) { shown.update(fraction); };
    return options;
}

/// A method's preparation (RenderOptions::preparing), each stage a progress line of its own
/// ("vdbtrace: lighting 1234 voxels  40%"), ended when done, before the pixels' line begins.
class PreparingShown {
public:
    void operator()(const std::string& stage, double fraction)
    {
        const std::lock_guard<std::mutex> lock(mMutex);
        if (stage != mStage) {
            if (mShown) mShown->finish();
            mShown.emplace("vdbtrace: " + stage);
            mStage = stage;
        }
        mShown->update(fraction);
        if (fraction >= 1.0) mShown->finish();
    }

private:
    std::mutex mMutex;
    std::string mStage;
    std::optional<tool::Progress> mShown;
};

// The command line's choice of models, over the scene's (render.preset and the keys after
// it): --paper first, then each law named.
struct ModelOverrides {
    bool paper = false;
    std::string boughLaw, layerModel, extinctionLaw, shadowOrigin, bark, layerCorrelation,
        needleEnds, occluderProfile;
    double levelBlend = 0.0;    ///< 0: the scene's
    double coneLevelMax = 0.0;  ///< 0: the scene's
    double pixelSplitQ = -1.0;  ///< < 0: the scene's

    void add(CLI::App& cmd)
    {
        cmd.add_flag("--paper", paper,
                     "Every approximation as the paper prints it (render.preset \"paper\"): "
                     "bough law linear, layer model paper, extinction law layer, shadow origin "
                     "axis, no level blend, bark line, level 3 from q = 1, layer correlation "
                     "independent, needle ends flat, occluder profile even");
        cmd.add_option("--bough-law", boughLaw, "multiscale level 3's law (render.bough_law)")
            ->check(CLI::IsMember(vdbtrace::boughLawNames()));
        cmd.add_option("--layer-model", layerModel,
                       "multiscale: a layer's opacity (render.layer_model)")
            ->check(CLI::IsMember(vdbtrace::layerModelNames()));
        cmd.add_option("--extinction-law", extinctionLaw,
                       "reference: the law of the bake, without --grids, whose files name "
                       "theirs (render.extinction_law)")
            ->check(CLI::IsMember(bake::extinctionLawNames()));
        cmd.add_option("--shadow-origin", shadowOrigin,
                       "multiscale: where a bough hit's shadow cone stands for; bough: "
                       "levels 2-3 read each bough's shadows, traced once a frame "
                       "(render.shadow_origin)")
            ->check(CLI::IsMember(vdbtrace::shadowOriginNames()));
        cmd.add_option("--level-blend", levelBlend,
                       "multiscale: the band about each level threshold over which two levels "
                       "are mixed, as a ratio of q (1: none; render.level_blend)")
            ->check(tool::numberIn(1.0, 2.0));
        cmd.add_option("--bark", bark,
                       "multiscale: solid (the needles' roots inside the branch are hidden) or "
                       "line (the branch is the bough's axis, the paper's; render.bark)")
            ->check(CLI::IsMember(vdbtrace::barkNames()));
        cmd.add_option("--layer-correlation", layerCorrelation,
                       "multiscale: self-shadowing through the fibre layers; needles (the view's "
                       "and the light's lines through one cone meet the same needles: the hot "
                       "spot) or independent (the paper's; render.layer_correlation)")
            ->check(CLI::IsMember(vdbtrace::layerCorrelationNames()));
        cmd.add_option("--occluder-profile", occluderProfile,
                       "multiscale: a bough's opacity from a light along its axis; cones (where "
                       "its cones' needles reach, so that a chain of short boughs shades as one "
                       "long bough) or even (the strip's mean all along, the paper's; "
                       "render.occluder_profile)")
            ->check(CLI::IsMember(vdbtrace::occluderProfileNames()));
        cmd.add_option("--needle-ends", needleEnds,
                       "geometry: the explicit needles' ends; open (a needle is its side, as "
                       "section 4 shades it and every level models it) or flat (solid "
                       "flat-capped cylinders, whose end discs reflect; render.needle_ends)")
            ->check(CLI::IsMember(vdbtrace::needleEndNames()));
        cmd.add_option("--cone-level-max", coneLevelMax,
                       "multiscale: level 3 (the bough a volume) from this footprint over cone "
                       "spacing q on, level 2 below; the paper's 1 (render.cone_level_max)")
            ->check(tool::positiveNumber());
        cmd.add_option("--pixel-split-q", pixelSplitQ,
                       "multiscale: a pixel whose cone (or corners) shows a bough at a footprint "
                       "over cone spacing q above this is traced as k x k narrower cones, k = "
                       "ceil(q / this) up to 4; 0: one cone a pixel, the paper's "
                       "(render.pixel_split_q)")
            ->check(tool::numberIn(0.0, 1e6));
    }
    /// The overrides applied to `render`'s models, then checked against its thresholds as the
    /// scene parser checks the scene's keys. @throw InputError
    void apply(scenes::RenderSettings& render) const
    {
        scenes::ModelChoices& m = render.model;
        if (paper) m = scenes::ModelChoices::paper();
        if (!boughLaw.empty()) m.boughLaw = boughLaw;
        if (!layerModel.empty()) m.layerModel = layerModel;
        if (!extinctionLaw.empty()) m.extinctionLaw = extinctionLaw;
        if (!shadowOrigin.empty()) m.shadowOrigin = shadowOrigin;
        if (levelBlend > 0.0) m.levelBlend = levelBlend;
        if (!bark.empty()) m.bark = bark;
        if (!layerCorrelation.empty()) m.layerCorrelation = layerCorrelation;
        if (!needleEnds.empty()) m.needleEnds = needleEnds;
        if (!occluderProfile.empty()) m.occluderProfile = occluderProfile;
        if (coneLevelMax > 0.0) m.coneLevelMax = coneLevelMax;
        if (pixelSplitQ >= 0.0) m.pixelSplitQ = pixelSplitQ;
        if (!(m.coneLevelMax > render.needleLevelMax)) {
            std::ostringstream message;
            message << "cone_level_max " << m.coneLevelMax
                    << " (from --cone-level-max or --paper) must exceed the scene's "
                       "needle_level_max ("
                    << render.needleLevelMax << ")";
            throw InputError(message.str());
        }
        // The two bands must not overlap: a band given here too wide for the thresholds is
        // refused, and the scene's (or the default) narrowed to what thresholds moved closer
        // allow, so that the header records the band drawn.
        const double widest = render.widestLevelBlend();
        if (m.levelBlend > widest) {
            if (levelBlend > 0.0) {
                std::ostringstream message;
                message << "--level-blend " << levelBlend
                        << " must be at most sqrt(cone_level_max / needle_level_max) (" << widest
                        << ") for cone_level_max " << m.coneLevelMax << " and needle_level_max "
                        << render.needleLevelMax;
                throw InputError(message.str());
            }
            tool::info() << "vdbtrace: level_blend " << m.levelBlend << " narrowed to " << widest
                         << " to keep the bands about needle_level_max " << render.needleLevelMax
                         << " and cone_level_max " << m.coneLevelMax << " apart\n";
            m.levelBlend = widest;
        }
    }
};

struct Loaded {
    scenes::Scene scene;
    vdbtrace::TracedScene traced;
};

/// The scene read, `adjust`ed (the command line's overrides), then `check`ed (what the work
/// will need), then grown for the tracer.
std::unique_ptr<Loaded> load(const fs::path& file, const ModelOverrides& model,
                             const std::function<void(const scenes::Scene&)>& check = {},
                             const std::function<void(scenes::Scene&)>& adjust = {},
                             const vdbtrace::TracedSceneParts& parts = {})
{
    auto loaded = std::make_unique<Loaded>();
    loaded->scene = scenes::loadScene(file);
    model.apply(loaded->scene.render);
    if (adjust) adjust(loaded->scene);
    if (check) check(loaded->scene);
    loaded->traced = vdbtrace::buildTracedScene(loaded->scene, parts);
    return loaded;
}

std::string describe(const scenes::Scene& scene, const vdbtrace::TracedScene& traced)
{
    double needles = 0.0, branches = 0.0;
    for (const scenes::TreeCounts& counts : traced.treeCounts) {
        needles += counts.needles;
        branches += double(counts.branches);
    }
    // Needle counts are expected values (cones times needles per cone, which may vary along a
    // bough): shown whole, as counts.
    const auto counted = [](double n, const char* one, const char* many) {
        if (!(n < 1e15)) {  // past what a long long holds exactly (or at all)
            char text[32];
            std::snprintf(text, sizeof text, "%.3g ", n);
            return text + std::string(many);
        }
        const auto whole = static_cast<long long>(std::llround(n));
        return std::to_string(whole) + " " + (whole == 1 ? one : many);
    };
    return counted(double(scene.trees.size()), "tree", "trees") + ", " +
           counted(branches, "branch", "branches") + ", " + counted(needles, "needle", "needles");
}

/// Refuses grids baked from a tree this scene does not hold (another scene's, or this one's
/// before it changed): the files record which tree they are and a digest of its boughs.
void checkBakedFrom(const fs::path& file, const bake::BakeProvenance& from, const Loaded& loaded,
                    const fs::path& sceneFile)
{
    if (from.treeDigest.empty()) return;  // a grid from elsewhere, already warned of
    const auto& trees = loaded.traced.trees;
    const std::string origin = "'" + file.string() + "' was baked from tree " +
                               std::to_string(from.tree) + " of '" + from.scene + "'";
    if (from.tree < 0 || std::size_t(from.tree) >= trees.size()) {
        throw InputError(origin + ", which '" + sceneFile.string() + "' does not have (it has " +
                         std::to_string(trees.size()) + "): bake this scene");
    }
    if (bake::treeDigest(bake::treeBoughs(trees[std::size_t(from.tree)])) != from.treeDigest) {
        throw InputError(origin + ", whose boughs differ from those of tree " +
                         std::to_string(from.tree) + " of '" + sceneFile.string() +
                         "': bake this scene");
    }
}

/// "x0,y0,x1,y1", integers with 0 <= x0 < x1 and 0 <= y0 < y1.
bool parseCrop(const std::string& text, vdbtrace::PixelWindow& window)
{
    int v[4];
    if (!vdbtrace::parseIntegers(text, ',', v)) return false;
    if (v[0] < 0 || v[1] < 0 || v[2] <= v[0] || v[3] <= v[1]) return false;
    window = {v[0], v[1], v[2], v[3]};
    return true;
}

fs::path besideWith(const fs::path& image, const std::string& suffix)
{
    fs::path p = image;
    p.replace_extension();
    return p.string() + suffix;
}

/// Every file `render` writes for one frame: its EXR, the previews beside it and its stats.
struct FrameFiles {
    fs::path exr, preview, levelPreview;  ///< NAME.exr, NAME.png, NAME.level.png
    fs::path stats;                       ///< empty without --stats
    bool levels = false;                  ///< whether the level preview is written (--aov level)

    FrameFiles(const fs::path& exrFile, fs::path statsFile, bool withLevels)
        : exr(exrFile),
          preview(besideWith(exrFile, ".png")),
          levelPreview(besideWith(exrFile, ".level.png")),
          stats(std::move(statsFile)),
          levels(withLevels)
    {
    }
    /// The previews this frame writes.
    std::vector<fs::path> previews() const
    {
        return levels ? std::vector<fs::path>{preview, levelPreview}
                      : std::vector<fs::path>{preview};
    }
};

/// What `render` changes of the scene's camera and frame from the command line.
struct FrameOverrides {
    int width = 0, height = 0;      ///< --resolution (0: the scene's)
    vdbtrace::PixelWindow crop;     ///< --crop (empty: the whole frame)
};

constexpr double kMiB = 1024.0 * 1024.0;
/// The least a render keeps its law profiles within, by itself, to fit --max-memory: below it
/// most would be computed again and again.
constexpr double kLeastLawCache_bytes = 16.0 * kMiB;

/// What `--law-cache MIB` keeps the law profiles within, in bytes: all of them (infinity)
/// without it.
double lawCacheBytes(double lawCacheMiB)
{
    return lawCacheMiB > 0.0 ? lawCacheMiB * kMiB : std::numeric_limits<double>::infinity();
}

/// A method's parts of the traced scene, its law profiles within `--law-cache MIB`.
vdbtrace::TracedSceneParts partsWithin(const vdbtrace::RenderMethod& method, double lawCacheMiB)
{
    vdbtrace::TracedSceneParts parts = method.parts;
    if (lawCacheMiB > 0.0) parts.lawProfileBudget_bytes = std::size_t(lawCacheBytes(lawCacheMiB));
    return parts;
}

/// What names a frame's render, so that a resumed job keeps only frames rendered as it would
/// render them: the renderer's own bytes (a rebuilt vdbtrace may shade otherwise), the scene
/// file's bytes, the grids' manifests (their checksums) and every option that changes a pixel.
std::string frameJobDigest(const fs::path& sceneFile, const std::string& methodName,
                           const vdbtrace::MethodSettings& settings,
                           const std::vector<fs::path>& gridFiles, const ModelOverrides& model,
                           const FrameOverrides& frame, const std::vector<std::string>& aovs)
{
    io::Fnv1a64 hash;
    const auto addFile = [&hash](const fs::path& file) {
        std::ifstream in(file, std::ios::binary);
        hash.update(in);
        hash.update(file.filename().string());  // a missing file still says so
    };
    addFile("/proc/self/exe");
    addFile(sceneFile);
    for (const fs::path& g : gridFiles) addFile(g.string() + ".json");
    const nlohmann::json job = {
        {"method", methodName},
        {"voxel_size", settings.voxelSize_cm},
        {"subpixels", settings.reference.subpixels},
        {"samples", settings.geometry.samples},
        {"sample_seed", settings.geometry.sampleSeed},
        {"primitive", int(settings.geometry.primitive)},
        {"force_level", settings.multiscale.forceLevel},
        {"paper", model.paper},
        {"bough_law", model.boughLaw},
        {"layer_model", model.layerModel},
        {"extinction_law", model.extinctionLaw},
        {"shadow_origin", model.shadowOrigin},
        {"bark", model.bark},
        {"layer_correlation", model.layerCorrelation},
        {"needle_ends", model.needleEnds},
        {"occluder_profile", model.occluderProfile},
        {"level_blend", model.levelBlend},
        {"pixel_split_q", model.pixelSplitQ},
        {"cone_level_max", model.coneLevelMax},
        {"resolution", {frame.width, frame.height}},
        {"crop", {frame.crop.x0, frame.crop.y0, frame.crop.x1, frame.crop.y1}},
        {"aovs", aovs}};
    hash.update(job.dump());
    return io::Fnv1a64::hex(hash.value());
}

/// Whether `file` is a frame this job rendered: written whole (frames are renamed into place
/// complete) and recording `job`.
bool frameComplete(const fs::path& file, const std::string& job)
{
    std::error_code error;
    if (!fs::exists(file, error)) return false;
    vdbtrace::Metadata metadata;
    try {
        vdbtrace::readExr(file, &metadata);
    } catch (const vdbtrace::ImageError&) {
        return false;  // damaged: rendered again
    }
    for (const auto& [key, value] : metadata) {
        if (key == "pine:job") {
            const auto* text = std::get_if<std::string>(&value);
            return text && *text == job;
        }
    }
    return false;
}

/// Whether `file` is a frame's stats this job wrote (they record the job as its EXR does): a
/// stats file of another job, or a damaged one, is written again with its frame.
bool statsComplete(const fs::path& file, const std::string& job)
{
    std::ifstream in(file);
    const nlohmann::json j = nlohmann::json::parse(in, nullptr, /*allow_exceptions=*/false);
    return j.is_object() && j.contains("job") && j["job"] == job;
}

int render(const fs::path& sceneFile, const std::string& methodName, const fs::path& out,
           const fs::path& statsFile, const std::vector<std::string>& aovs,
           vdbtrace::MethodSettings settings, const std::vector<fs::path>& gridFiles,
           const ModelOverrides& model, const FrameOverrides& frame, double maxMemoryGiB,
           double lawCacheMiB, const std::optional<vdbtrace::FrameRange>& frameRange,
           vdbtrace::Ranks& ranks)
{
    using Clock = std::chrono::steady_clock;
    const auto started = Clock::now();
    const bool animation = frameRange.has_value();
    const bool leader = ranks.rank() == 0;
    // The ranks on one machine share its memory.
    const double memoryLimit = bake::memoryLimit(maxMemoryGiB) / ranks.sizeOnThisMachine();
    const vdbtrace::RenderMethod& method = vdbtrace::renderMethod(methodName);
    vdbtrace::TracedSceneParts parts = partsWithin(method, lawCacheMiB);
    // The extension decides the format: only EXR holds the render (its PNG goes beside it).
    const auto lowered = [](std::string text) {
        for (char& c : text) c = char(std::tolower(static_cast<unsigned char>(c)));
        return text;
    };
    const std::string extension = lowered(out.extension().string());
    if (lowered(out.filename().string()) == ".exr") {  // hidden, without an extension
        throw InputError("--out '" + out.string() + "': the file needs a name before .exr");
    }
    if (extension != ".exr") {
        throw InputError("--out '" + out.string() + "': the render is written as OpenEXR and " +
                         "its name must end in .exr (a PNG preview is written beside it)");
    }
    const bool levelPng = std::find(aovs.begin(), aovs.end(), "level") != aovs.end();
    if (levelPng && !method.levels) {
        throw InputError("--aov level: method '" + methodName +
                         "' has no levels (multiscale shades at the paper's levels)");
    }
    // A frame's files: NAME.####.exr and its previews, stats as STATS.####.json. All are
    // checked before the render: a folder named as a preview was found only after it, which
    // it lost (and with --aov level, after the preview was written).
    const auto filesOf = [&](std::optional<int> f) {
        if (!f) return FrameFiles(out, statsFile, levelPng);
        return FrameFiles(
            vdbtrace::frameFile(out, *f),
            statsFile.empty() ? statsFile : vdbtrace::frameFile(statsFile, *f, ".json"), levelPng);
    };
    const FrameFiles first = filesOf(animation ? std::optional(frameRange->first) : std::nullopt);
    // Only the leader writes (the other ranks' machines may not see its folders).
    if (leader) {
        io::checkWritable(first.exr);
        for (const fs::path& preview : first.previews()) io::checkWritableName(preview);
        if (!first.stats.empty()) io::checkWritable(first.stats);
    }
    std::vector<fs::path> inputs = {sceneFile};
    for (const fs::path& g : gridFiles) {
        inputs.push_back(g);
        inputs.push_back(g.string() + ".json");
    }
    // The one clash the user cannot see in the names given: --stats named as a preview.
    for (const fs::path& preview : first.previews()) {
        if (!first.stats.empty() && io::sameFile(first.stats, preview)) {
            throw InputError("--stats '" + first.stats.string() +
                             "' is the preview written beside '" + first.exr.string() +
                             "': give the stats another name");
        }
    }
    std::vector<fs::path> firstOutputs = first.previews();
    firstOutputs.insert(firstOutputs.begin(), first.exr);
    firstOutputs.push_back(first.stats);
    io::checkOutputsApart(firstOutputs, inputs);
    if (animation) {  // every frame's files, not only the first's
        std::set<std::string> images, stats;
        for (int f = frameRange->first + 1; f <= frameRange->last; ++f) {
            const FrameFiles files = filesOf(f);
            images.insert(files.exr.filename().string());
            for (const fs::path& preview : files.previews()) {
                images.insert(preview.filename().string());
                if (leader) io::checkWritableName(preview);
            }
            if (leader) io::checkWritableName(files.exr);
            if (!files.stats.empty()) {
                stats.insert(files.stats.filename().string());
                if (leader) io::checkWritableName(files.stats);
            }
        }
        const auto among = [](const std::set<std::string>& names) {
            return [&names](const std::string& name) { return names.count(name) > 0; };
        };
        io::checkFolderSparesInputs(io::folderOf(out), among(images), inputs);
        if (!statsFile.empty()) {
            io::checkFolderSparesInputs(io::folderOf(statsFile), among(stats), inputs);
        }
    }
    if (leader) vdbtrace::loadImageIo();  // the others send their images to it
    // Frames of an interrupted job already rendered as this one would are kept, with their
    // stats if this job asks for them (else rendered again to write them): the leader looks,
    // every rank hears which are left.
    const std::string job =
        animation ? frameJobDigest(sceneFile, methodName, settings, gridFiles, model, frame, aovs)
                  : std::string();
    std::vector<int> toRender;
    if (animation) {
        if (leader) {
            toRender = vdbtrace::framesLeft(*frameRange, [&](int f) {
                const FrameFiles files = filesOf(f);
                return frameComplete(files.exr, job) &&
                       (files.stats.empty() || statsComplete(files.stats, job));
            });
        }
        vdbtrace::Bytes list(toRender.size() * sizeof(int));
        std::memcpy(list.data(), toRender.data(), list.size());
        ranks.broadcast(list, 0);
        toRender.resize(list.size() / sizeof(int));
        std::memcpy(toRender.data(), list.data(), list.size());
        const int done = frameRange->count() - int(toRender.size());
        if (done > 0) {
            tool::info() << "vdbtrace: " << done << " of " << frameRange->count()
                         << " frames already rendered by this job, kept\n";
        }
        if (toRender.empty()) {
            tool::info() << "vdbtrace: nothing left to render\n";
            return 0;
        }
    }
    // Baked files first: a damaged one is refused before any work.
    std::optional<bake::TreeGrids> baked;
    std::vector<bake::BakeProvenance> bakedFrom;
    if (methodName == "reference" && !gridFiles.empty()) {
        std::vector<bake::TreeGrids> trees;
        for (const fs::path& file : gridFiles) {
            bake::ReadGrids read = bake::readTreeGrids(file, memoryLimit);
            // Only a tree checkBakedFrom can check (by its digest) names the file's voxels.
            if (read.provenance.treeDigest.empty()) read.grids.tree.reset();
            if (!read.unverified.empty()) {
                std::cerr << "vdbtrace: warning: '" << file.string() << "': " << read.unverified
                          << '\n';
            }
            trees.push_back(std::move(read.grids));
            bakedFrom.push_back(std::move(read.provenance));
        }
        baked = bake::mergeTreeGrids(trees);  // checked against manifests or their metadata
        settings.grids = &*baked;
    }
    // The frame this rank renders first: the traced scene is built for it.
    const int firstOfMine =
        animation ? toRender[std::min(toRender.size() - 1, std::size_t(ranks.rank()))] : 0;
    const auto loaded = load(
        sceneFile, model,
        [&](const scenes::Scene& scene) {
            const vdbtrace::PixelWindow& c = frame.crop;
            if (!c.empty() && (c.x1 > scene.camera.width || c.y1 > scene.camera.height)) {
                throw InputError("--crop " + std::to_string(c.x0) + "," + std::to_string(c.y0) +
                                 "," + std::to_string(c.x1) + "," + std::to_string(c.y1) +
                                 " reaches outside the " + std::to_string(scene.camera.width) +
                                 " x " + std::to_string(scene.camera.height) + " frame");
            }
            const double voxelsRead = baked ? bake::allocatedVoxels(*baked) : 0.0;
            const auto estimate = [&](double lawProfiles_bytes) {
                return bake::estimateRender(
                    scene, methodName, settings.voxelSize_cm, voxelsRead,
                    settings.geometry.primitive == vdbtrace::NeedlePrimitive::Curve,
                    lawProfiles_bytes);
            };
            const double limit = memoryLimit;
            bake::ResourceEstimate needs = estimate(lawCacheBytes(lawCacheMiB));
            // Without --law-cache, profiles that would not fit are kept within what is left,
            // as --law-cache would keep them: the same image, some recomputed. (Each estimate
            // grows a tree a species: the one without profiles only where it is needed.)
            const double left = methodName == "multiscale" && !(lawCacheMiB > 0.0) &&
                                        needs.bytes() > limit
                                    ? limit - estimate(0.0).bytes()
                                    : 0.0;
            if (left >= kLeastLawCache_bytes) {
                parts.lawProfileBudget_bytes = std::size_t(left);
                needs = estimate(left);
                tool::info() << "vdbtrace: keeping the boughs' law profiles within "
                             << bake::formatBytes(left) << " (as --law-cache would) to stay "
                             << "under --max-memory " << bake::formatBytes(limit) << '\n';
            }
            bake::checkMemory(needs, limit, sceneFile.string());
        },
        [&](scenes::Scene& scene) {
            if (frame.width > 0) {
                scene.camera.width = frame.width;
                scene.camera.height = frame.height;
            }
            if (!animation) return;
            if (scene.cameraPath.empty()) {
                throw InputError("--frames: '" + sceneFile.string() +
                                 "' has no camera_path (docs/scene-format.md) to move along");
            }
            // The file checks its own frames; --frames may name others, where the camera
            // holds or a smooth path overshoots.
            for (const int f : toRender) {
                const std::string problem =
                    scenes::cameraProblem(scene.cameraPath.at(f, scene.camera));
                if (!problem.empty()) {
                    throw InputError("--frames: at frame " + std::to_string(f) + " of '" +
                                     sceneFile.string() + "'s camera_path, " + problem);
                }
            }
            scene.camera = scene.cameraPath.at(firstOfMine, scene.camera);
        },
        parts);
    std::map<int, fs::path> treesRead;  // a tree given twice would be drawn twice
    for (std::size_t i = 0; i < bakedFrom.size(); ++i) {
        checkBakedFrom(gridFiles[i], bakedFrom[i], *loaded, sceneFile);
        if (bakedFrom[i].treeDigest.empty()) continue;
        const auto [at, fresh] = treesRead.emplace(bakedFrom[i].tree, gridFiles[i]);
        if (!fresh) {
            throw InputError("--grids: '" + at->second.string() + "' and '" +
                             gridFiles[i].string() + "' are both tree " +
                             std::to_string(bakedFrom[i].tree) + " of '" + sceneFile.string() +
                             "'");
        }
    }
    if (!treesRead.empty() && treesRead.size() < loaded->traced.treeCounts.size()) {
        std::cerr << "vdbtrace: warning: --grids holds " << treesRead.size() << " of the "
                  << loaded->traced.treeCounts.size() << " trees of '" << sceneFile.string()
                  << "': the others render without foliage\n";
    }
    if (baked) {
        tool::info() << "vdbtrace: " << baked->layerOpacity->activeVoxelCount() << " voxels of "
                     << baked->voxelSize_cm << " cm read\n";
    }
    tool::info() << "vdbtrace: " << sceneFile.string() << ": "
                 << describe(loaded->scene, loaded->traced) << '\n';
    settings.geometry.built = [](const vdbtrace::GeometryBuild& b) {
        tool::info() << "vdbtrace: " << b.needles << " needles and " << b.branches
                     << " branches as cylinders";
        if (b.variants) {
            tool::info() << ", " << b.variantNeedles << " needles of " << b.variants
                         << " variants instanced at " << b.instancedTrees << " trees";
        }
        tool::info() << ", BVH built in " << b.seconds << " s ("
                     << double(b.primitiveBytes) / (1 << 20) << " MiB of cylinders, Embree peak "
                     << double(b.embreePeakBytes) / (1 << 20) << " MiB)\n";
    };
    if (methodName == "reference" && !baked) {
        tool::info() << "vdbtrace: baking the boughs at " << settings.voxelSize_cm << " cm\n";
    }
    const scenes::Camera still = loaded->scene.camera;
    const scenes::CameraPath& path = loaded->scene.cameraPath;
    // The traced scene is prepared for one camera (each bough's law sees it): again per frame.
    // What this rank's renders kept (law profiles, shadow columns) is read before it goes.
    std::optional<int> tracedFor = animation ? std::optional<int>(firstOfMine) : std::nullopt;
    nlohmann::json kept;
    const auto renderAt = [&](std::optional<int> f, const vdbtrace::PixelWindow& window,
                              bool last) {
        if (f != tracedFor) {
            loaded->traced = vdbtrace::TracedScene();  // never two at once: --max-memory holds one
            loaded->scene.camera = path.at(*f, still);
            loaded->traced = vdbtrace::buildTracedScene(loaded->scene, parts);
            tracedFor = f;
        }
        tool::Progress rendering(f ? "vdbtrace: frame " + std::to_string(*f)
                                   : std::string("vdbtrace: rendering"));
        vdbtrace::RenderOptions options = withProgress(rendering);
        PreparingShown preparing;
        options.preparing = std::ref(preparing);
        options.window = window;
        vdbtrace::RenderResult result = method.render(loaded->traced, settings, options);
        rendering.finish();
        const vdbtrace::LawProfileCounts profiles = vdbtrace::lawProfileCounts(loaded->traced);
        const std::size_t columnsBytes = vdbtrace::lightColumnsBytes(loaded->traced);
        const auto counted = [](const vdbtrace::ProfileCounts& c) {
            return nlohmann::json{
                {"computed", c.computed}, {"dropped", c.dropped}, {"bytes", c.bytes}};
        };
        kept = nlohmann::json::object();
        if (profiles.views.computed + profiles.fromLights.computed > 0) {
            kept["law_profiles"] = {{"views", counted(profiles.views)},
                                    {"from_lights", counted(profiles.fromLights)},
                                    {"peak_bytes", profiles.peakBytes}};
        }
        if (columnsBytes > 0) kept["shadow_columns_bytes"] = columnsBytes;
        // What is written is the image alone: the traced scene (most of a landscape's
        // memory) goes before the files are made.
        if (last) {
            loaded->traced = vdbtrace::TracedScene();
            tracedFor = -1;
        }
        return result;
    };
    const auto& s = loaded->scene;
    const nlohmann::json effects = vdbtrace::toJson(vdbtrace::EffectsPlan::from(s.effects));
    // The law profiles and shadow columns are this rank's: told where one rank rendered all.
    const auto write = [&](const vdbtrace::RenderResult& result, std::optional<int> f, bool local) {
        const FrameFiles files = filesOf(f);
        scenes::Camera seen = s.camera;
        if (f) seen = path.at(*f, still);
        const vdbtrace::ConeCamera camera(seen);
        const nlohmann::json methodSettings = method.describe(s, settings);
        // As compositors and pbrt-v4 read an EXR: render time, samples (pbrt-v4's names) and
        // OpenEXR's camera matrices, typed; the rest under pine:, numbers as numbers.
        vdbtrace::Metadata metadata = vdbtrace::cameraMetadata(camera);
        metadata.insert(metadata.end(), {{"renderTimeSeconds", float(result.seconds)},
                                         {"samplesPerPixel", method.samplesPerPixel(settings)},
                                         {"pine:scene", sceneFile.string()},
                                         {"pine:method", methodName},
                                         {"pine:render_seconds", float(result.seconds)},
                                         {"pine:prep_seconds", float(result.prepSeconds)},
                                         {"pine:threads", tbb::this_task_arena::max_concurrency()},
                                         {"pine:ranks", ranks.size()},
                                         {"pine:effects", effects.dump()},
                                         {"pine:units", "cm"}});
        // samplesPerPixel is the method's per pixel; the multiscale split traces more where
        // its pixels ask (render.pixel_split_q): the mean over this image.
        const double pixels = double(result.image.width) * double(result.image.height);
        metadata.emplace_back("pine:cones_per_pixel",
                              float(pixels > 0.0 ? double(result.stats.coneRays) / pixels : 0.0));
        if (f) {
            metadata.emplace_back("pine:frame", *f);
            metadata.emplace_back("pine:fps", float(path.framesPerSecond));
            metadata.emplace_back("pine:job", job);
        }
        if (!result.treeFoliage.empty()) {
            vdbtrace::addTreeFoliage(metadata, result.treeFoliage, camera.width(), camera.height());
        }
        for (const auto& [key, value] : methodSettings.items()) {
            if (value.is_number_integer()) {
                metadata.emplace_back("pine:" + key, value.get<int>());
            } else if (value.is_number()) {
                metadata.emplace_back("pine:" + key, value.get<float>());
            } else if (value.is_string()) {
                metadata.emplace_back("pine:" + key, value.get<std::string>());
            } else {
                metadata.emplace_back("pine:" + key, value.dump());
            }
        }
        const vdbtrace::Image exr = vdbtrace::exrImage(result.image, camera, method,
                                                       vdbtrace::EffectsPlan::from(s.effects));
        // The previews and stats are put in place before the EXR, so that a failure among them
        // leaves the previous EXR and never a new one beside an old preview; a frame under its
        // final name is whole. Runs writing into one folder take turns, so that these files
        // come from one run.
        const auto writeBeside = [&] {
            // The preview shows the scene's background behind what the cone did not cover.
            vdbtrace::writePreviewPng(result.image, s.render.background, files.preview);
            if (files.levels) vdbtrace::writeLevelPng(result.image, files.levelPreview);
            if (!files.stats.empty()) {
                nlohmann::json j = vdbtrace::toJson(result.stats);
                j["seconds"] = result.seconds;
                j["scene"] = sceneFile.string();
                j["method"] = methodName;
                j["effects"] = effects;
                j["resolution"] = {s.camera.width, s.camera.height};
                if (!frame.crop.empty()) {
                    j["crop"] = {frame.crop.x0, frame.crop.y0, frame.crop.x1, frame.crop.y1};
                }
                if (f) {
                    j["frame"] = *f;
                    j["job"] = job;  // as the EXR's pine:job: what a resumed job keeps
                }
                j["threads"] = tbb::this_task_arena::max_concurrency();
                j["ranks"] = ranks.size();
                // The law profiles and shadow columns are this rank's: told where it
                // rendered the whole image.
                if (local) j.update(kept);
                j.update(methodSettings);
                vdbtrace::writeJsonAtomically(j, files.stats);
            }
        };
        const io::FolderLock turn(io::FolderLock::of(files.exr), [&] {
            tool::info() << "vdbtrace: waiting for another run writing into '"
                         << io::FolderLock::of(files.exr).string() << "'\n";
        });
        // A killed run's temporaries (live ones wait for the lock), the level preview's too
        // where this run writes none.
        for (const fs::path& file : {files.exr, files.preview, files.levelPreview}) {
            io::removeStaleTemporaries(file);
        }
        vdbtrace::writeExr(exr, files.exr, metadata, writeBeside);
        const auto& st = result.stats;
        tool::info() << "vdbtrace: " << files.exr.string() << ": " << result.image.width << "x"
                     << result.image.height << " in " << result.seconds << " s, " << st.coneRays
                     << " cone rays, " << st.shadowRays << " shadow rays; pixels by level "
                     << "needle/cone/bough " << st.pixelsPerLevel[1] << "/" << st.pixelsPerLevel[2]
                     << "/" << st.pixelsPerLevel[3] << '\n';
    };

    const vdbtrace::PixelWindow whole =
        frame.crop.empty() ? vdbtrace::PixelWindow{0, 0, s.camera.width, s.camera.height}
                           : frame.crop;
    const int rankCount = ranks.size(), me = ranks.rank();
    const std::vector<std::optional<int>> images =
        animation ? std::vector<std::optional<int>>(toRender.begin(), toRender.end())
                  : std::vector<std::optional<int>>{std::nullopt};
    if (rankCount > 1 && images.size() == 1) {
        // One image, many ranks: bands of whole tile rows, put together by the leader.
        const auto bands = vdbtrace::rowBands(whole, rankCount, vdbtrace::RenderOptions().tileSize);
        std::optional<vdbtrace::RenderResult> mine;
        if (std::size_t(me) < bands.size()) {
            mine = renderAt(images[0], bands[std::size_t(me)], true);
        }
        if (!leader && mine) ranks.send(0, vdbtrace::packRender(*mine));
        if (leader) {
            std::vector<vdbtrace::RenderResult> bandRenders;
            bandRenders.push_back(std::move(*mine));
            for (std::size_t q = 1; q < bands.size(); ++q) {
                bandRenders.push_back(vdbtrace::unpackRender(ranks.receive(int(q))));
            }
            write(vdbtrace::joinBands(std::move(bandRenders), bands, whole), images[0], false);
        }
    } else {
        // Frames dealt round-robin (a dolly's near and far frames spread over the ranks), one
        // round at a time: the leader writes its own, then each other rank's as it arrives.
        for (std::size_t round = 0; round < images.size(); round += std::size_t(rankCount)) {
            const std::size_t mine = round + std::size_t(me);
            std::optional<vdbtrace::RenderResult> result;
            if (mine < images.size()) {
                result = renderAt(images[mine], frame.crop,
                                  mine + std::size_t(rankCount) >= images.size());
            }
            if (!leader && result) ranks.send(0, vdbtrace::packRender(*result));
            if (!leader) continue;
            write(*result, images[mine], rankCount == 1);
            for (int q = 1; q < rankCount && round + std::size_t(q) < images.size(); ++q) {
                write(vdbtrace::unpackRender(ranks.receive(q)), images[round + std::size_t(q)],
                      false);
            }
        }
    }
    // Every rank's CPU time, summed: what the frames cost the machines.
    const double cpuSeconds = ranks.sum(io::processCpuSeconds());
    if (leader && (animation || rankCount > 1)) {
        const double wall = std::chrono::duration<double>(Clock::now() - started).count();
        const char* what = animation ? (images.size() == 1 ? " frame" : " frames") : " image";
        tool::info() << "vdbtrace: " << images.size() << what << " in " << wall << " s, "
                     << cpuSeconds << " CPU-s on " << rankCount
                     << (rankCount == 1 ? " rank" : " ranks") << " ("
                     << double(images.size()) / cpuSeconds << " per CPU-second)\n";
    }
    return 0;
}

/// `body` on every rank of `ranks`. Alone, as any command. Under mpirun: the ranks on one
/// machine share its cores (each takes its share unless --threads says), only the leader
/// speaks of progress, and an error on any rank ends the whole job at once, naming the rank
/// (the others would wait for it for ever).
int renderOnRanks(vdbtrace::Ranks& ranks, CLI::App& app, const std::function<int()>& body)
{
    if (ranks.size() == 1) return body();
    std::unique_ptr<tbb::global_control> share;
    if (app.get_option("--threads")->count() == 0) {
        // mpirun may bind a rank to fewer cores (Open MPI 4 binds to one core a rank with 2
        // ranks or fewer): its TBB threads follow the binding, and a rank bound to less than
        // its share is told so.
        const int cores = int(std::max(1u, std::thread::hardware_concurrency()));
        const int shareOfCores = std::max(1, cores / ranks.sizeOnThisMachine());
        cpu_set_t mask;
        CPU_ZERO(&mask);
        const int bound = sched_getaffinity(0, sizeof mask, &mask) == 0 ? CPU_COUNT(&mask) : cores;
        if (bound < shareOfCores && ranks.rank() == 0) {
            std::cerr << "vdbtrace: warning: mpirun bound each rank to " << bound << " of the "
                      << shareOfCores << " cores it could use (mpirun --bind-to none lets it)\n";
        }
        share = std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism,
                                                      std::size_t(std::min(bound, shareOfCores)));
    }
    if (ranks.rank() != 0) tool::setQuiet(true);
    const auto fail = [&](const std::string& what, int status) {
        // In one write: mpirun relays a rank's stderr as it comes and prints its MPI_ABORT
        // banner between two pieces of a line written piece by piece.
        tool::errorLine("vdbtrace: rank " + std::to_string(ranks.rank()) + " of " +
                        std::to_string(ranks.size()) + ": " + what + " (ending the job)");
        ranks.abort(status);
    };
    try {
        return body();
    } catch (const InputError& e) {
        fail(e.what(), 2);
    } catch (const std::bad_alloc&) {
        fail("out of memory", 2);
    } catch (const std::exception& e) {
        fail(e.what(), 1);
    }
    return 1;  // fail() does not return
}

std::string machineDescription();

// One timed render of `method`: the scene built (trees grown, BVH: not timed), then the render,
// its wall and CPU seconds (the process's, all threads: a bough law's profiles and a method's
// own preparation, as the geometry's Embree BVH, included).
struct BenchRun {
    vdbtrace::RenderResult result;
    vdbtrace::LawProfileCounts profiles;  ///< multiscale: the law profiles it computed
    std::size_t columnsBytes = 0;         ///< its lights' shadow columns (light_columns.h)
    double wallSeconds = 0.0, cpuSeconds = 0.0, buildSeconds = 0.0;
    std::size_t trees = 0, boughs = 0;
    double needles = 0.0;  ///< expected count (cones times needles per cone)
};

// `lawCacheMiB` > 0 bounds the law profiles as `render --law-cache` does (multiscale's: the
// other methods compute none).
BenchRun benchRun(const scenes::Scene& scene, const std::string& method,
                  const vdbtrace::MethodSettings& settings, const std::string& label,
                  double lawCacheMiB)
{
    using Clock = std::chrono::steady_clock;
    BenchRun run;
    const auto built = Clock::now();
    const vdbtrace::TracedScene traced =
        vdbtrace::buildTracedScene(scene, partsWithin(vdbtrace::renderMethod(method), lawCacheMiB));
    run.buildSeconds = std::chrono::duration<double>(Clock::now() - built).count();
    run.trees = traced.treeCounts.size();
    run.boughs = traced.boughs.size();
    for (const scenes::TreeCounts& counts : traced.treeCounts) run.needles += counts.needles;
    tool::Progress shown("vdbtrace: " + label);
    const double cpu = io::processCpuSeconds();
    const auto start = Clock::now();
    run.result = vdbtrace::renderMethod(method).render(traced, settings, withProgress(shown));
    run.wallSeconds = std::chrono::duration<double>(Clock::now() - start).count();
    run.cpuSeconds = io::processCpuSeconds() - cpu;
    run.profiles = vdbtrace::lawProfileCounts(traced);
    run.columnsBytes = vdbtrace::lightColumnsBytes(traced);
    return run;
}

// The median of `runs` by CPU seconds, with the spread of the CPU seconds.
struct BenchSummary {
    BenchRun median;
    double cpuMin = 0.0, cpuMax = 0.0;
};

BenchSummary summarize(std::vector<BenchRun> runs)
{
    std::sort(runs.begin(), runs.end(),
              [](const BenchRun& a, const BenchRun& b) { return a.cpuSeconds < b.cpuSeconds; });
    BenchSummary out;
    out.cpuMin = runs.front().cpuSeconds;
    out.cpuMax = runs.back().cpuSeconds;
    out.median = std::move(runs[runs.size() / 2]);
    return out;
}

// One method's runs of a benchmark, and how each is made.
struct Benched {
    std::string method, label;
    vdbtrace::MethodSettings settings;
    double lawCacheMiB = 0.0;
    std::vector<BenchRun> runs;
};

// Each method `repeats` times, round by round (every method once a round), so that each is
// timed across the whole benchmark's drift in the machine's speed, not in one stretch of it.
// A run keeps its numbers, not its image: the benchmark reads none.
void benchInRounds(const scenes::Scene& scene, std::vector<Benched>& methods, int repeats)
{
    for (int i = 0; i < repeats; ++i) {
        for (Benched& m : methods) {
            BenchRun run = benchRun(scene, m.method, m.settings,
                                    repeats > 1 ? m.label + " " + std::to_string(i + 1) : m.label,
                                    m.lawCacheMiB);
            run.result.image = vdbtrace::Image();
            m.runs.push_back(std::move(run));
        }
    }
}

int bench(const fs::path& sceneFile, bool scaling, const ModelOverrides& model,
          int geometrySamples, vdbtrace::NeedlePrimitive primitive, int repeats,
          const fs::path& jsonFile, int width, int height, double lawCacheMiB)
{
    if (!jsonFile.empty()) {
        io::checkWritable(jsonFile);
        io::checkOutputsApart({jsonFile}, {sceneFile});
    }
    const double startupCpu = io::processCpuSeconds();
    scenes::Scene scene = scenes::loadScene(sceneFile);
    model.apply(scene.render);
    if (width > 0) {  // --resolution: the same view, its vertical field kept
        scene.camera.width = width;
        scene.camera.height = height;
    }
    vdbtrace::MethodSettings settings;
    std::vector<Benched> methods{{"multiscale", "multiscale", settings, lawCacheMiB, {}}};
    if (geometrySamples > 0) {
        vdbtrace::MethodSettings g;
        g.geometry.samples = geometrySamples;
        g.geometry.primitive = primitive;
        methods.push_back(
            {"geometry", "geometry " + std::to_string(geometrySamples) + " spp", g, 0.0, {}});
    }
    benchInRounds(scene, methods, repeats);
    const BenchSummary ms = summarize(std::move(methods[0].runs));
    const vdbtrace::RenderResult& r = ms.median.result;
    const auto& st = r.stats;
    // Pixels by level; a split pixel traces more than one cone (render.pixel_split_q).
    const double pixels = double(scene.camera.width) * double(scene.camera.height);
    const auto share = [&](int level) { return double(st.pixelsPerLevel[level]) / pixels; };
    std::cout << "scene " << sceneFile.string() << " " << scene.camera.width << "x"
              << scene.camera.height << ", threads " << tbb::this_task_arena::max_concurrency()
              << ", CPU seconds the median of " << repeats << " run(s)"
              << "\nstart-up CPU seconds (libraries loaded, arguments) " << startupCpu
              << "\nscene build seconds (trees grown, BVH; not in the times below) "
              << ms.median.buildSeconds << "\nmultiscale render: CPU seconds "
              << ms.median.cpuSeconds << " [" << ms.cpuMin << ", " << ms.cpuMax
              << "], wall seconds " << ms.median.wallSeconds
              << " (the bough law's profiles included)"
              << "\ncone rays per second (wall) " << double(st.coneRays) / ms.median.wallSeconds
              << ", per pixel " << double(st.coneRays) / pixels << "\nshare of pixels: none "
              << share(0) << ", needle " << share(1) << ", cone " << share(2) << ", bough "
              << share(3) << '\n';
    const vdbtrace::LawProfileCounts& profiles = ms.median.profiles;
    std::cout << "law profiles: views " << profiles.views.computed << " computed, "
              << profiles.views.dropped << " dropped; from the lights "
              << profiles.fromLights.computed << " computed, " << profiles.fromLights.dropped
              << " dropped; at most " << double(profiles.peakBytes) / kMiB << " MiB kept";
    if (lawCacheMiB > 0.0) std::cout << " (--law-cache " << lawCacheMiB << " MiB)";
    std::cout << '\n';
    nlohmann::json j;
    j["scene"] = sceneFile.string();
    j["resolution"] = {scene.camera.width, scene.camera.height};
    j["threads"] = tbb::this_task_arena::max_concurrency();
    j["machine"] = machineDescription();
    j["repeats"] = repeats;
    j["startup_cpu_seconds"] = startupCpu;
    j["build_seconds"] = ms.median.buildSeconds;
    const auto describeRun = [](const BenchSummary& b) {
        return nlohmann::json{{"cpu_seconds", b.median.cpuSeconds},
                              {"cpu_seconds_min", b.cpuMin},
                              {"cpu_seconds_max", b.cpuMax},
                              {"wall_seconds", b.median.wallSeconds}};
    };
    j["multiscale"] = describeRun(ms);
    j["multiscale"]["model"] = vdbtrace::renderMethod("multiscale").describe(scene, settings);
    j["multiscale"]["cones_per_pixel"] = double(st.coneRays) / pixels;
    j["multiscale"]["pixel_share"] = {{"none", share(0)}, {"needle", share(1)},
                                      {"cone", share(2)}, {"bough", share(3)}};
    j["multiscale"]["law_profiles"] = {
        {"views", {{"computed", profiles.views.computed}, {"dropped", profiles.views.dropped}}},
        {"from_lights",
         {{"computed", profiles.fromLights.computed}, {"dropped", profiles.fromLights.dropped}}},
        {"peak_bytes", profiles.peakBytes}};
    if (lawCacheMiB > 0.0) j["multiscale"]["law_cache_mib"] = lawCacheMiB;
    if (ms.median.columnsBytes > 0) {
        j["multiscale"]["shadow_columns_bytes"] = ms.median.columnsBytes;
        std::cout << "shadow columns " << double(ms.median.columnsBytes) / kMiB << " MiB\n";
    }
    if (geometrySamples > 0) {
        const vdbtrace::MethodSettings& g = methods[1].settings;
        const std::string& label = methods[1].label;
        const BenchSummary geo = summarize(std::move(methods[1].runs));
        const double ratio = ms.median.cpuSeconds / geo.median.cpuSeconds;
        std::cout << label << " render: CPU seconds " << geo.median.cpuSeconds << " ["
                  << geo.cpuMin << ", " << geo.cpuMax << "], wall seconds "
                  << geo.median.wallSeconds << " (its BVH build included)"
                  << "\nCPU ratio multiscale / geometry " << ratio << '\n';
        j["geometry"] = describeRun(geo);
        j["geometry"].update(vdbtrace::renderMethod("geometry").describe(scene, g));
        j["cpu_ratio_multiscale_over_geometry"] = ratio;
    }
    if (scaling) {
        // Section 7: doubling N or halving dh must leave the cost of bough-level pixels
        // unchanged. A bough's law profiles are computed by whichever pixel (of any level)
        // first needs them, so here they are all computed before each render and timed apart.
        const auto perBoughPixel = [](const vdbtrace::RenderResult& x) {
            return x.stats.pixelsPerLevel[3] ? double(x.stats.nanosecondsPerLevel[3]) /
                                                   double(x.stats.pixelsPerLevel[3])
                                             : 0.0;
        };
        scenes::Scene doubled = scene, halved = scene;
        for (auto& [name, sp] : doubled.species) {
            sp.needlesAtBase.perCone *= 2;
            sp.needlesAtTip.perCone *= 2;
        }
        for (auto& [name, sp] : halved.species) {
            sp.needlesAtBase.coneSpacing_cm /= 2;
            sp.needlesAtTip.coneSpacing_cm /= 2;
        }
        const auto scaled = [&](const scenes::Scene& s, const std::string& label,
                                double& lawCpuSeconds) {
            const vdbtrace::TracedScene traced = vdbtrace::buildTracedScene(s);
            const double cpu = io::processCpuSeconds();
            vdbtrace::computeLawProfiles(traced);
            lawCpuSeconds = io::processCpuSeconds() - cpu;
            tool::Progress shown("vdbtrace: " + label);
            return perBoughPixel(
                vdbtrace::renderMultiscale(traced, settings.multiscale, withProgress(shown)));
        };
        double lawBase, lawDoubled, lawHalved;
        const double base = scaled(scene, "as is", lawBase);
        const double d = scaled(doubled, "N x 2", lawDoubled);
        const double h = scaled(halved, "dh / 2", lawHalved);
        std::cout << "bough-level ns per pixel (the law's profiles computed before): as is "
                  << base << ", N x 2 " << d << ", dh / 2 " << h
                  << "\nthe law's profiles of every bough, CPU seconds: as is " << lawBase
                  << ", N x 2 " << lawDoubled << ", dh / 2 " << lawHalved << '\n';
        j["bough_level_ns_per_pixel"] = {
            {"base", base}, {"needles_x2", d}, {"spacing_half", h}};
        j["law_profiles_cpu_seconds"] = {
            {"base", lawBase}, {"needles_x2", lawDoubled}, {"spacing_half", lawHalved}};
    }
    const double peak = tool::peakMemoryMiB();
    std::cout << "peak memory MiB (the process, every run) " << peak << '\n';
    j["peak_memory_mib"] = peak;
    if (!jsonFile.empty()) vdbtrace::writeJsonAtomically(j, jsonFile);
    return 0;
}

// `bench --grow`: the scene grown step by step along one axis (scene_growth.h), each step's
// scene written into `dir` and rendered by each method in this process, its CPU seconds and
// its own peak of resident memory (reset before each render) recorded; the growth exponents
// of both fitted over the steps. Writes growth.json and growth.csv, and growth.png through
// scripts/plot_growth.py unless `plot` is false.
int benchGrowth(const fs::path& sceneFile, const std::string& axisName, int steps, double factor,
                const fs::path& dir, const ModelOverrides& model, int geometrySamples,
                vdbtrace::NeedlePrimitive primitive, int repeats, bool plot, double maxMemoryGiB,
                int width, int height, double lawCacheMiB)
{
    const vdbtrace::GrowthAxis axis = vdbtrace::growthAxis(axisName);
    // Validates the document the steps are grown from; its models describe the run.
    scenes::Scene asIs = scenes::loadScene(sceneFile);
    model.apply(asIs.render);
    std::ifstream in(sceneFile);
    nlohmann::json document = nlohmann::json::parse(in, nullptr, true, true);
    if (width > 0) document["camera"]["resolution"] = {width, height};  // --resolution
    // Every step grown and read before any work: a step the parser refuses (a scatter that
    // no longer fits its min_spacing, a resolution over the limit) stops it now.
    std::vector<nlohmann::json> grown;
    std::vector<scenes::Scene> stepScenes;
    for (int k = 0; k < steps; ++k) {
        grown.push_back(vdbtrace::growScene(document, axis, std::pow(factor, k)));
        const fs::path name = "step-" + std::to_string(k) + ".json";
        try {
            stepScenes.push_back(scenes::parseScene(grown.back().dump(), name));
            const scenes::Scene& step = stepScenes.back();
            const bool instanced = primitive == vdbtrace::NeedlePrimitive::Curve;
            for (const char* method : {"multiscale", "geometry"}) {
                if (std::string(method) == "geometry" && geometrySamples == 0) continue;
                // The multiscale profiles within --law-cache, as the runs will keep them.
                bake::checkMemory(bake::estimateRender(step, method, 0.0, 0.0, instanced,
                                                       lawCacheBytes(lawCacheMiB)),
                                  bake::memoryLimit(maxMemoryGiB), method);
            }
        } catch (const std::exception& e) {
            std::ostringstream where;
            where << "--grow " << axisName << ", step " << k << " (x" << std::pow(factor, k)
                  << "): " << e.what();
            throw InputError(where.str());
        }
    }
    io::checkFolderSparesInputs(
        dir,
        [](const std::string& name) {
            const bool step = name.rfind("step-", 0) == 0 && fs::path(name).extension() == ".json";
            return step || name == "growth.json" || name == "growth.csv" || name == "growth.png";
        },
        {sceneFile});
    io::checkWritableFolder(dir);
    const bool ownPeaks = tool::resetPeakMemory();
    if (!ownPeaks) {
        std::cerr << "vdbtrace bench: cannot reset the peak of resident memory here; each "
                     "step's memory is the process's peak so far\n";
    }
    std::vector<std::string> methods = {"multiscale"};
    if (geometrySamples > 0) methods.push_back("geometry");
    nlohmann::json rows = nlohmann::json::array();
    std::vector<double> scale;
    std::map<std::string, std::vector<double>> cpu, memory;
    std::cout << "step  scale  trees  boughs  needles  pixels  method  CPU-s  wall-s  peak-MiB\n";
    for (int k = 0; k < steps; ++k) {
        const double f = std::pow(factor, k);
        const fs::path stepFile = dir / ("step-" + std::to_string(k) + ".json");
        io::writeTextAtomically(stepFile, grown[std::size_t(k)].dump(1) + "\n");
        scenes::Scene& scene = stepScenes[std::size_t(k)];
        scene.source = stepFile;
        model.apply(scene.render);
        scale.push_back(f);
        for (const std::string& method : methods) {
            vdbtrace::MethodSettings settings;
            settings.geometry.samples = geometrySamples;
            settings.geometry.primitive = primitive;
            tool::resetPeakMemory();
            // One method at a time: each step's peak memory is its own.
            std::vector<Benched> one{
                {method, "step " + std::to_string(k) + " " + method, settings, lawCacheMiB, {}}};
            benchInRounds(scene, one, repeats);
            const BenchSummary b = summarize(std::move(one[0].runs));
            const double peak = tool::peakMemoryMiBSinceReset();
            const BenchRun& r = b.median;
            cpu[method].push_back(r.cpuSeconds);
            memory[method].push_back(peak);
            const long long pixels = (long long)scene.camera.width * scene.camera.height;
            std::cout << k << "  " << f << "  " << r.trees << "  " << r.boughs << "  "
                      << std::llround(r.needles) << "  " << pixels << "  " << method << "  "
                      << r.cpuSeconds << "  " << r.wallSeconds << "  " << peak << std::endl;
            rows.push_back({{"step", k}, {"scale", f}, {"method", method},
                            {"scene", stepFile.string()}, {"trees", r.trees},
                            {"boughs", r.boughs}, {"needles", r.needles}, {"pixels", pixels},
                            {"cpu_seconds", r.cpuSeconds}, {"cpu_seconds_min", b.cpuMin},
                            {"cpu_seconds_max", b.cpuMax}, {"wall_seconds", r.wallSeconds},
                            {"build_seconds", r.buildSeconds}, {"peak_memory_mib", peak}});
        }
    }
    nlohmann::json exponents;
    for (const std::string& method : methods) {
        const double e = vdbtrace::growthExponent(scale, cpu[method]);
        const double m = vdbtrace::growthExponent(scale, memory[method]);
        exponents[method] = {{"cpu_seconds", e}, {"peak_memory_mib", m}};
        std::cout << method << ": CPU seconds grow as scale^" << e << ", peak memory as scale^"
                  << m << '\n';
    }
    nlohmann::json j;
    j["scene"] = sceneFile.string();
    j["axis"] = axisName;
    j["factor"] = factor;
    j["threads"] = tbb::this_task_arena::max_concurrency();
    j["machine"] = machineDescription();
    j["repeats"] = repeats;
    j["memory_per_step"] = ownPeaks;
    j["model"] = vdbtrace::renderMethod("multiscale").describe(asIs, {});
    if (lawCacheMiB > 0.0) j["law_cache_mib"] = lawCacheMiB;
    j["rows"] = rows;
    j["exponents"] = exponents;
    vdbtrace::writeJsonAtomically(j, dir / "growth.json");
    std::ostringstream csv;
    csv << "step,scale,method,trees,boughs,needles,pixels,cpu_seconds,wall_seconds,"
           "peak_memory_mib\n";
    for (const auto& r : rows) {
        csv << r["step"] << ',' << r["scale"] << ',' << r["method"].get<std::string>() << ','
            << r["trees"] << ',' << r["boughs"] << ',' << r["needles"] << ',' << r["pixels"]
            << ',' << r["cpu_seconds"] << ',' << r["wall_seconds"] << ','
            << r["peak_memory_mib"] << '\n';
    }
    io::writeTextAtomically(dir / "growth.csv", csv.str());
    if (plot && !tool::runPlotScript(tool::plotScript("plot_growth.py"), dir)) {
        std::cerr << "vdbtrace bench: growth.png not written (python3 with matplotlib "
                     "missing?); growth.json and growth.csv are\n";
    }
    tool::info() << "vdbtrace: growth along " << axisName << " over " << steps
                 << " steps written to " << dir.string() << '\n';
    return 0;
}

std::string machineDescription()
{
    std::string cpu = "unknown CPU";
    std::ifstream in("/proc/cpuinfo");
    for (std::string line; std::getline(in, line);) {
        const auto colon = line.find(':');
        if (line.rfind("model name", 0) == 0 && colon != std::string::npos) {
            cpu = line.substr(line.find_first_not_of(' ', colon + 1));
            break;
        }
    }
    return cpu + ", " + std::to_string(std::thread::hardware_concurrency()) + " cores; " +
           std::to_string(tbb::this_task_arena::max_concurrency()) + " threads";
}

// Runs of a timed render: odd, so that the median is one run.
CLI::Validator oddRuns()
{
    return CLI::Validator(
        [](std::string& text) -> std::string {
            try {
                std::size_t used = 0;
                const int k = std::stoi(text, &used);
                if (used == text.size() && k >= 1 && k <= 15 && k % 2 == 1) return {};
            } catch (const std::exception&) {
            }
            return "must be an odd number from 1 to 15 (the median is one run), got '" + text +
                   "'";
        },
        "odd in [1, 15]");
}

bool plotCompare(const fs::path& dir)
{
    return tool::runPlotScript(tool::plotScript("plot_compare.py"), dir) &&
           fs::exists(dir / "error_vs_time.png") && fs::exists(dir / "error_vs_scale.png");
}

int diff(const fs::path& a, const fs::path& b, const fs::path& outDir, double scale)
{
    if (outDir.empty()) throw InputError("--out: no folder named");
    io::checkFolderSparesInputs(outDir,
                                [](const std::string& name) {
                                    return name == "error.exr" || name == "error.png" ||
                                           name == "errors.json";
                                },
                                {a, b});
    // The images read and compared before the folder is made: a refused pair leaves nothing.
    vdbtrace::Metadata imageHeader, referenceHeader;
    const vdbtrace::Image image = vdbtrace::readExr(a, &imageHeader),
                          reference = vdbtrace::readExr(b, &referenceHeader);
    const vdbtrace::ImageErrors errors =
        vdbtrace::compareImages(image, reference, a.string(), b.string());
    io::checkWritableFolder(outDir);
    io::checkWritable(outDir / "error.exr");
    io::checkWritableName(outDir / "error.png");
    io::checkWritableName(outDir / "errors.json");
    const double shown = scale > 0.0 ? scale : std::max(errors.maxAbsolute, 1e-12);
    vdbtrace::writeExr(errors.error, outDir / "error.exr",
                       {{"pine:image", a.string()}, {"pine:reference", b.string()}});
    vdbtrace::writeErrorPng(errors, shown, outDir / "error.png");
    nlohmann::json j = errors.toJson();
    j["image"] = a.string();
    j["reference"] = b.string();
    j["png_scale"] = shown;
    // Per tree: fragment by fragment where both renders summed their trees so
    // (tree_foliage_tally.h), else over the regions of the reference's "tree" AOV.
    std::string worst;
    const auto imageTrees = vdbtrace::treeFoliageOf(imageHeader, a.string(), &image);
    const auto referenceTrees = vdbtrace::treeFoliageOf(referenceHeader, b.string(), &reference);
    const bool byFragments = imageTrees && referenceTrees;
    if (byFragments || (reference.aovs.count("tree") && reference.aovs.count("foliage") &&
                        image.aovs.count("foliage"))) {
        const std::vector<vdbtrace::TreeBias> trees =
            byFragments ? vdbtrace::treeBiases(*imageTrees, *referenceTrees)
                        : vdbtrace::treeBiases(image, reference);
        j["tree_attribution"] = byFragments ? "fragments" : "regions";
        nlohmann::json rows = nlohmann::json::array();
        const vdbtrace::TreeBias* worstLuminance = nullptr;
        const vdbtrace::TreeBias* worstCoverage = nullptr;
        for (const vdbtrace::TreeBias& t : trees) {
            nlohmann::json row = {{"tree", t.truth.tree},
                                  {"coverage", t.image.coverage},
                                  {"coverage_reference", t.truth.coverage},
                                  {"coverage_bias", t.coverageBias},
                                  {"luminance", t.image.luminance},
                                  {"luminance_reference", t.truth.luminance},
                                  {"luminance_bias", t.luminanceBias}};
            if (!byFragments) row["pixels"] = t.truth.pixels;  // of its region
            rows.push_back(row);
            // An undefined bias (NaN, null in the JSON: the tree is black in the reference) is
            // no tree's worst.
            if (!std::isnan(t.luminanceBias) &&
                (!worstLuminance ||
                 std::abs(t.luminanceBias) > std::abs(worstLuminance->luminanceBias))) {
                worstLuminance = &t;
            }
            if (!worstCoverage ||
                std::abs(t.coverageBias) > std::abs(worstCoverage->coverageBias)) {
                worstCoverage = &t;
            }
        }
        j["trees"] = rows;
        if (worstCoverage) {
            std::ostringstream s;
            s << "; " << trees.size() << " trees, worst luminance bias ";
            if (worstLuminance) {
                s << 100.0 * worstLuminance->luminanceBias << "% (tree "
                  << worstLuminance->truth.tree << ")";
            } else {
                s << "undefined (every tree black in the reference)";
            }
            s << ", worst coverage bias " << 100.0 * worstCoverage->coverageBias << "% (tree "
              << worstCoverage->truth.tree << ")";
            worst = s.str();
        }
    }
    vdbtrace::writeJsonAtomically(j, outDir / "errors.json");
    std::ostringstream meanRelative;
    if (std::isnan(errors.meanRelative)) {
        meanRelative << "undefined (a black reference)";
    } else {
        meanRelative << errors.meanRelative;
    }
    std::ostringstream black;
    for (const vdbtrace::ImageErrors::BlackFoliage& atK : errors.blackFoliage) {
        if (atK.k > 4) break;  // beyond a bough's width
        black << (atK.k == 1 ? "; foliage black where the reference's is lit: " : ", ") << atK.black
              << " of " << atK.blocks;
        if (atK.k == 1) {
            black << " pixels";
        } else {
            black << " blocks of " << atK.k << "x" << atK.k;
        }
    }
    std::cerr << "vdbtrace diff: rmse " << errors.rmse << ", mean relative " << meanRelative.str()
              << ", max " << errors.maxAbsolute << worst << black.str() << " -> " << outDir.string()
              << " (error.exr, error.png scaled 0.." << shown << ", errors.json)\n";
    return 0;
}

/// The render options that belong to one method.
constexpr std::pair<const char*, const char*> kMethodOptions[] = {
    {"--voxel-size", "reference"},  {"--grids", "reference"},
    {"--subpixels", "reference"},   {"--samples", "geometry"},
    {"--sample-seed", "geometry"},  {"--needle-primitive", "geometry"},
    {"--force-level", "multiscale"}, {"--law-cache", "multiscale"}};

/// --max-memory (GiB) on `cmd`, for `task` ("a render").
void addMaxMemory(CLI::App& cmd, double& gib, const std::string& task)
{
    cmd.add_option("--max-memory", gib,
                   "Refuse, before any work, " + task + " estimated to need more memory than "
                   "this, in GiB (default: 80% of this machine's, " +
                       bake::formatBytes(bake::defaultMemoryLimit()) + ")")
        ->check(tool::positiveNumber());
}

/// --resolution WxH on `cmd`, checked as vdbtrace::parseResolution reads it (`example` in the
/// message of a refused one).
void addResolution(CLI::App& cmd, std::string& text, const std::string& help,
                   const std::string& example)
{
    cmd.add_option("--resolution", text, help)->check([example](const std::string& value) {
        int w = 0, h = 0;
        return vdbtrace::parseResolution(value, w, h)
                   ? std::string()
                   : "expected WxH, each at most 16384, e.g. " + example;
    });
}

/// --needle-primitive on `cmd`: what the geometry method's Embree walks.
void addNeedlePrimitive(CLI::App& cmd, vdbtrace::NeedlePrimitive& primitive)
{
    cmd.add_option_function<std::string>(
           "--needle-primitive",
           [&primitive](const std::string& name) {
               primitive = name == "curve" ? vdbtrace::NeedlePrimitive::Curve
                                           : vdbtrace::NeedlePrimitive::Cylinder;
           },
           "geometry: curve (Embree's native flat-capped cone curves, single precision) or "
           "cylinder (user geometry intersected in double precision, slower)")
        ->check(CLI::IsMember({"curve", "cylinder"}))
        ->default_str("curve");
}

}  // namespace

int main(int argc, char** argv)
{
    // Before any thread: under mpirun, MPI starts here (ranks.h); alone, one rank.
    std::unique_ptr<vdbtrace::Ranks> ranks;
    try {
        ranks = vdbtrace::jobRanks(argc, argv);
    } catch (const std::exception& e) {
        std::cerr << "vdbtrace: " << e.what() << '\n';
        return 2;
    }
    CLI::App app{"vdbtrace: the cone tracer of Meyer & Neyret's multiscale pine shaders"};
    app.require_subcommand(1);

    fs::path sceneFile, out, statsFile;
    double maxMemoryGiB = 0.0;  // 0: bake::defaultMemoryLimit()
    std::string method = "multiscale";
    std::vector<std::string> aovs;
    auto* renderCmd = app.add_subcommand("render", "Render a scene to EXR (+ PNG preview)");
    renderCmd->add_option("scene", sceneFile, "Scene file (JSON)")->required();
    std::string methods;
    for (const vdbtrace::RenderMethod& m : vdbtrace::renderMethods()) {
        methods += (methods.empty() ? "" : "; ") + std::string(m.name) + ": " + m.description;
    }
    renderCmd->add_option("--method", method, methods)->capture_default_str();
    vdbtrace::MethodSettings settings;
    std::vector<fs::path> gridFiles;
    renderCmd
        ->add_option("--voxel-size", settings.voxelSize_cm,
                     "reference: voxel size of the baked boughs, cm")
        ->capture_default_str()
        ->check(tool::positiveNumber());
    renderCmd->add_option("--grids", gridFiles,
                          "reference: baked .vdb files (bake tree/scene) instead of baking now")
        ->check(CLI::ExistingFile);
    renderCmd
        ->add_option("--subpixels", settings.reference.subpixels,
                     "reference: rays per pixel along each axis (the cone's footprint)")
        ->capture_default_str()
        ->check(tool::wholeNumberIn(1, 16));
    renderCmd
        ->add_option("--samples", settings.geometry.samples, "geometry: point samples per pixel")
        ->capture_default_str()
        ->check(tool::wholeNumberIn(1, 65536));
    renderCmd->add_option("--sample-seed", settings.geometry.sampleSeed,
                          "geometry: another shift of the sample sequence, for an independent "
                          "render with the same error statistics")
        ->capture_default_str();
    addNeedlePrimitive(*renderCmd, settings.geometry.primitive);
    renderCmd->add_option("--out", out, "Output EXR; a PNG preview is written beside it")
        ->required();
    renderCmd->add_option("--stats", statsFile, "Write render statistics as JSON");
    FrameOverrides frame;
    std::string renderResolution, crop;
    addResolution(*renderCmd, renderResolution,
                  "WxH instead of the camera's (same view, vertical field kept)", "640x480");
    renderCmd->add_option("--crop", crop,
                          "Only pixels [x0, x1) x [y0, y1) of the frame, as x0,y0,x1,y1 (row 0 "
                          "at the top): the EXR's data window, each pixel as in the whole frame")
        ->check([](const std::string& text) {
            vdbtrace::PixelWindow w;
            return parseCrop(text, w) ? std::string()
                                      : "expected x0,y0,x1,y1 with 0 <= x0 < x1 and 0 <= y0 < y1";
        });
    std::string framesText;
    renderCmd->add_option("--frames", framesText,
                          "Render frames A-B (or A) of the scene's camera_path as OUT.####.exr "
                          "(+ previews); frames this job already rendered are kept, so an "
                          "interrupted job resumes. Under mpirun the frames are dealt over the "
                          "ranks; one image alone is cut into bands of rows");
    addMaxMemory(*renderCmd, maxMemoryGiB, "a render");
    renderCmd->add_option("--aov", aovs, "Extra images: 'level' (Figure 12 false colours)")
        ->check(CLI::IsMember({"level"}));
    ModelOverrides model;
    model.add(*renderCmd);
    renderCmd
        ->add_option("--force-level", settings.multiscale.forceLevel,
                     "multiscale: shade every bough hit at level 1, 2 or 3")
        ->check(tool::wholeNumberIn(0, 3));
    double lawCacheMiB = 0.0;  // 0: keep every profile
    renderCmd
        ->add_option("--law-cache", lawCacheMiB,
                     "multiscale: MiB the boughs' law profiles (views, shadows) may keep "
                     "(default: all, or what --max-memory leaves them); the oldest are "
                     "dropped and computed again, the same, if asked again (a landscape: "
                     "1.3 GB kept, 64 MiB enough)")
        ->check(tool::numberIn(1.0, 1e7));

    bool scaling = false;
    auto* benchCmd = app.add_subcommand(
        "bench", "Time multiscale against geometry in one run: CPU and wall seconds, their "
                 "ratio, cone rays/s, memory, levels");
    benchCmd->add_option("scene", sceneFile, "Scene file (JSON)")->required();
    benchCmd->add_flag("--scaling", scaling,
                       "Also render with N x 2 and dh / 2 (section 7's scaling claim)");
    int benchGeometrySamples = 4, benchRepeats = 1;
    fs::path benchJson;
    benchCmd
        ->add_option("--geometry-samples", benchGeometrySamples,
                     "Samples per pixel of the geometry render timed beside it (0: none)")
        ->check(tool::wholeNumberIn(0, 4096))
        ->capture_default_str();
    vdbtrace::NeedlePrimitive benchPrimitive = vdbtrace::NeedlePrimitive::Curve;
    addNeedlePrimitive(*benchCmd, benchPrimitive);
    benchCmd
        ->add_option("--repeat", benchRepeats,
                     "Runs of each render (odd), round by round (each method once a "
                     "round); the times are the median by CPU seconds, with the least and the "
                     "most")
        ->check(oddRuns())
        ->capture_default_str();
    benchCmd->add_option("--json", benchJson, "Also write every number as JSON");
    double benchLawCacheMiB = 0.0;  // 0: keep every profile
    benchCmd
        ->add_option("--law-cache", benchLawCacheMiB,
                     "MiB the multiscale runs' law profiles may keep, as render --law-cache "
                     "(default: all); the stats count those computed again")
        ->check(tool::numberIn(1.0, 1e7));
    std::string benchResolution;
    addResolution(*benchCmd, benchResolution,
                  "WxH instead of the camera's (same view, vertical field kept; with --grow, "
                  "of the first step)",
                  "2560x1920");
    std::string growAxis;
    int growSteps = 4;
    double growFactor = 2.0;
    fs::path growDir;
    bool growNoPlot = false;
    CLI::Option* grow =
        benchCmd
            ->add_option("--grow", growAxis,
                         "Instead, grow the scene step by step and time both methods at each: "
                         "trees-region (more trees, same region), trees-density (more trees, "
                         "larger region), resolution (pixels) or needles (needles per cm of "
                         "branch); writes the steps' scenes, growth.json, growth.csv and "
                         "growth.png into --grow-dir")
            ->check(CLI::IsMember(vdbtrace::growthAxisNames()));
    // Without --grow these would be ignored without a word.
    benchCmd->add_option("--grow-steps", growSteps, "Steps of --grow, the first the scene as is")
        ->check(tool::wholeNumberIn(2, 8))
        ->capture_default_str()
        ->needs(grow);
    benchCmd
        ->add_option("--grow-factor", growFactor,
                     "What each step of --grow multiplies: trees, pixels or needles")
        ->check(tool::numberIn(1.1, 16.0))
        ->capture_default_str()
        ->needs(grow);
    benchCmd->add_option("--grow-dir", growDir, "Folder for --grow's outputs")->needs(grow);
    benchCmd->add_flag("--no-plot", growNoPlot, "--grow: no growth.png (no python3 needed)")
        ->needs(grow);
    addMaxMemory(*benchCmd, maxMemoryGiB, "a step of --grow");
    model.add(*benchCmd);

    fs::path diffA, diffB, diffOut;
    double diffScale = 0.0;
    auto* diffCmd = app.add_subcommand("diff", "Per-pixel error of IMAGE against REFERENCE");
    diffCmd->add_option("image", diffA, "EXR to judge")->required()->check(CLI::ExistingFile);
    diffCmd->add_option("reference", diffB, "EXR taken as right")
        ->required()
        ->check(CLI::ExistingFile);
    diffCmd->add_option("--out", diffOut, "Folder for error.exr, error.png, errors.json")
        ->required();
    diffCmd->add_option("--scale", diffScale, "Error shown white in error.png (default: the max)")
        ->check(tool::numberIn(0.0, std::numeric_limits<double>::infinity()));

    vdbtrace::CompareOptions compare;
    bool quick = false, noPlot = false, noBudget = false;
    std::string resolution;
    auto* compareCmd =
        app.add_subcommand("compare",
                           "Every method and setting against the geometry ground truth: CPU time, "
                           "error at every scale, bias per tree, flicker (report.md, report.csv, "
                           "trees.csv, images, error_vs_time.png, error_vs_scale.png)");
    compareCmd->add_option("scene", compare.sceneFile, "Scene file (JSON)")->required();
    compareCmd->add_option("--out-dir", compare.outDir, "Folder for the report and images")
        ->required();
    compareCmd->add_flag("--quick", quick,
                         "Fewer settings (truth 16 spp checked against 64, geometry 1 and 4 "
                         "spp, voxels 1 and 0.5 cm, one run each; the error budget still "
                         "rendered) and an 8-frame dolly at half resolution");
    addResolution(*compareCmd, resolution, "WxH instead of the camera's (same view)", "64x48");
    compareCmd->add_flag("--no-plot", noPlot,
                         "Skip error_vs_time.png and error_vs_scale.png (matplotlib)");
    int truthSamples = 0, compareRepeat = 0;
    compareCmd
        ->add_option("--truth-samples", truthSamples,
                     "Samples per pixel of the ground truth (default 64, 16 with --quick); it "
                     "is checked against 4 times as many")
        ->check(tool::wholeNumberIn(1, 4096));
    compareCmd
        ->add_option("--repeat", compareRepeat,
                     "Runs of each render, round by round (each setting once a round), timed "
                     "as the median by CPU seconds (odd; default 3, 1 with --quick)")
        ->check(oddRuns());
    compareCmd->add_flag("--no-budget", noBudget,
                         "Skip the error budget (each model choice's alternatives alone)");
    compareCmd->add_flag("--self-shadowing", compare.addSelfShadowing,
                         "Add self_shadowing where the scene's effects name shadows: the "
                         "explicit needles always self-shadow, so a scene with shadows alone "
                         "is refused without it");
    addMaxMemory(*compareCmd, maxMemoryGiB, "a comparison");
    model.add(*compareCmd);

    vdbtrace::AnimationCompareOptions animate;
    std::string animateFrames, animateResolution;
    bool animateNoPlot = false;
    auto* animateCmd = app.add_subcommand(
        "animate-compare",
        "The scene's camera path rendered by multiscale and by geometry at 1 and 4 spp: "
        "flicker per method and per level band, over the frames, and a strip of frames "
        "(report.md, flicker.csv, frames.csv, flicker_frames.png, strip.png)");
    animateCmd->add_option("scene", animate.sceneFile, "Scene file (JSON) with a camera_path")
        ->required();
    animateCmd->add_option("--out-dir", animate.outDir, "Folder for the report")->required();
    animateCmd->add_option("--frames", animateFrames,
                           "Frames A-B of the path (default: the path's own; at least 3)");
    addResolution(*animateCmd, animateResolution,
                  "WxH instead of the camera's (same view, vertical field kept)", "320x240");
    animateCmd->add_option("--strip", animate.stripFrames, "Frames shown in strip.png")
        ->capture_default_str()
        ->check(tool::wholeNumberIn(1, 16));
    animateCmd->add_flag("--self-shadowing", animate.addSelfShadowing,
                         "Add self_shadowing where the scene's effects name shadows (the "
                         "explicit needles always self-shadow; a scene with shadows alone is "
                         "refused without it)");
    animateCmd->add_flag("--no-plot", animateNoPlot, "Skip flicker_frames.png");
    animateCmd
        ->add_option("--truth-samples", animate.truthSamples,
                     "Also render geometry at N samples a pixel (its own seed) as the truth, and "
                     "each method's error flicker against it: the camera's motion cancels (0: "
                     "none)")
        ->capture_default_str()
        ->check(tool::wholeNumberIn(0, 65536));
    addMaxMemory(*animateCmd, maxMemoryGiB, "a temporal comparison");
    model.add(*animateCmd);

    return tool::run("vdbtrace", app, argc, argv, [&] {
        if (*renderCmd) {
            // An option of another method would be ignored: refused, so that no one believes
            // a multiscale render took 4 samples.
            for (const auto& [option, owner] : kMethodOptions) {
                if (renderCmd->count(option) && method != owner) {
                    throw InputError(std::string(option) + " applies to --method " + owner +
                                     ", not " + method);
                }
            }
            if (renderCmd->count("--voxel-size")) bake::checkVoxelSize(settings.voxelSize_cm);
            if (!renderResolution.empty()) {
                vdbtrace::parseResolution(renderResolution, frame.width, frame.height);
            }
            if (!crop.empty()) parseCrop(crop, frame.crop);
            std::optional<vdbtrace::FrameRange> frames;
            if (!framesText.empty()) frames = vdbtrace::parseFrameRange(framesText);
            return renderOnRanks(*ranks, app, [&] {
                return render(sceneFile, method, out, statsFile, aovs, settings, gridFiles, model,
                              frame, maxMemoryGiB, lawCacheMiB, frames, *ranks);
            });
        }
        if (ranks->size() > 1) {
            throw InputError(
                "only render splits its work over mpirun's ranks: run the other "
                "commands as one process");
        }
        if (*diffCmd) return diff(diffA, diffB, diffOut, diffScale);
        if (*animateCmd) {
            if (!animateFrames.empty()) animate.frames = vdbtrace::parseFrameRange(animateFrames);
            if (!animateResolution.empty()) {
                vdbtrace::parseResolution(animateResolution, animate.width, animate.height);
            }
            animate.maxMemoryBytes = bake::memoryLimit(maxMemoryGiB);
            animate.machine = machineDescription();
            animate.model = [&model](scenes::RenderSettings& r) { model.apply(r); };
            animate.log = [](const std::string& line) {
                tool::info() << "vdbtrace animate-compare: " << line << '\n';
            };
            if (!animateNoPlot) {
                animate.plot = [](const fs::path& dir) {
                    return tool::runPlotScript(tool::plotScript("plot_animation.py"), dir) &&
                           fs::exists(dir / "flicker_frames.png");
                };
            }
            vdbtrace::runAnimationCompare(animate);
            return 0;
        }
        if (*compareCmd) {
            compare.settings = vdbtrace::CompareSettings::forQuick(quick);
            if (truthSamples > 0) compare.settings.truthSamples = truthSamples;
            if (compareRepeat > 0) compare.settings.repeat = compareRepeat;
            compare.settings.budget = !noBudget;
            compare.maxMemoryBytes = bake::memoryLimit(maxMemoryGiB);
            compare.machine = machineDescription();
            compare.model = [&model](scenes::RenderSettings& r) { model.apply(r); };
            compare.log = [](const std::string& line) {
                tool::info() << "vdbtrace compare: " << line << '\n';
            };
            compare.warn = [](const std::string& line) {
                std::cerr << "vdbtrace compare: " << line << '\n';
            };
            if (!noPlot) compare.plot = plotCompare;
            if (!resolution.empty()) {
                vdbtrace::parseResolution(resolution, compare.width, compare.height);
            }
            vdbtrace::runCompare(compare);
            return 0;
        }
        int benchWidth = 0, benchHeight = 0;
        if (!benchResolution.empty()) {
            vdbtrace::parseResolution(benchResolution, benchWidth, benchHeight);
        }
        if (!growAxis.empty()) {
            if (growDir.empty()) throw InputError("--grow needs --grow-dir DIR for its outputs");
            if (!benchJson.empty() || scaling) {
                throw InputError(std::string(scaling ? "--scaling" : "--json") +
                                 " does not apply to --grow (growth.json is written into "
                                 "--grow-dir)");
            }
            return benchGrowth(sceneFile, growAxis, growSteps, growFactor, growDir, model,
                               benchGeometrySamples, benchPrimitive, benchRepeats, !growNoPlot,
                               maxMemoryGiB, benchWidth, benchHeight, benchLawCacheMiB);
        }
        if (scaling && benchLawCacheMiB > 0.0) {
            throw InputError("--law-cache does not apply to --scaling (it times the law's "
                             "profiles of every bough, all kept)");
        }
        return bench(sceneFile, scaling, model, benchGeometrySamples, benchPrimitive,
                     benchRepeats, benchJson, benchWidth, benchHeight, benchLawCacheMiB);
    });
}
