// bake: voxelize a scene's trees into OpenVDB grids (one .vdb and its manifest per tree).
#include "pine/bake/extinction_law.h"
#include "pine/bake/resource_estimate.h"
#include "pine/bake/tree_boughs.h"
#include "pine/bake/tree_grids.h"
#include "pine/bake/tree_proxy.h"
#include "pine/scenes/scene.h"
#include "pine/scenes/tree.h"
#include "pine/support/atomic_file.h"
#include "pine/support/folder_lock.h"
#include "pine/support/progress.h"
#include "pine/support/tool_main.h"

#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>
#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <functional>
#include <iostream>
#include <memory>
#include <optional>
#include <set>
#include <vector>

namespace {

using namespace pine;
namespace fs = std::filesystem;

struct Totals {
    std::atomic<std::size_t> trees{0};
    std::atomic<std::uint64_t> voxels{0}, bytes{0};
};

/// Where and how the files are laid out (--units, --frame).
struct Output {
    bake::LengthUnit unit = bake::LengthUnit::Metre;
    bool treeFrame = true;
};

/// Runs `work` in the turn of `file`'s folder (io::FolderLock, as the grids are written),
/// isolated so that the thread waits for the lock without taking other tasks.
void inFolderTurn(const fs::path& file, const std::function<void()>& work)
{
    tbb::this_task_arena::isolate([&] {
        const io::FolderLock turn(io::FolderLock::of(file));
        work();
    });
}

/// Writes `text` to `file` atomically (call it in the folder's turn): the temporaries a killed bake
/// left are removed, a live one's never are.
void writeTextReplacingStale(const fs::path& file, const std::string& text)
{
    io::removeStaleTemporaries(file);
    io::writeTextAtomically(file, text);
}

void writeInTurn(const fs::path& file, const std::string& text)
{
    inFolderTurn(file, [&] { writeTextReplacingStale(file, text); });
}

/// The mesh of the trunk and branches beside a tree's grids.
fs::path meshBeside(const fs::path& grids)
{
    fs::path mesh = grids;
    return mesh.replace_extension(".obj");
}

/// Grows tree `index` of the scene, bakes it and writes its grids to `out` and its branch mesh
/// beside them; returns its entry of the instance list.
bake::ProxyInstance bakeTree(const scenes::Scene& scene, const fs::path& sceneFile,
                             std::size_t index, const bake::BakeSettings& settings,
                             const Output& output, const fs::path& out, Totals& totals)
{
    const scenes::TreePlacement& placement = scene.trees[index];
    const scenes::Tree tree = scenes::growTree(scene.species.at(placement.species), placement);
    const std::vector<bake::BoughSpec> boughs = bake::treeBoughs(tree);
    const bake::TreeGrids grids = bake::bakeBoughs(boughs, settings);
    bake::FileLayout layout{output.unit, std::nullopt};
    if (output.treeFrame) layout.treeFrame = bake::treeFrame(placement);
    writeInTurn(meshBeside(out), bake::branchMeshObj(tree, layout));
    bake::writeTreeGrids(grids, out,
                         {sceneFile.string(), int(index), placement.seed, bake::treeDigest(boughs)},
                         layout);
    totals.trees += 1;
    totals.voxels += grids.density->activeVoxelCount();
    totals.bytes +=
        std::uint64_t(fs::file_size(out)) + std::uint64_t(fs::file_size(meshBeside(out)));
    return {int(index),         out.filename().string(), meshBeside(out).filename().string(),
            placement.species, placement.seed,          layout.treeFrame};
}

void summarize(const Totals& totals, std::chrono::steady_clock::time_point start)
{
    const double seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    const std::size_t trees = totals.trees.load();
    if (tool::quiet()) return;
    std::fprintf(stderr, "bake: %zu %s, %llu voxels, %llu bytes, %.2f s, peak %.0f MiB\n",
                 trees, trees == 1 ? "tree" : "trees",
                 static_cast<unsigned long long>(totals.voxels.load()),
                 static_cast<unsigned long long>(totals.bytes.load()), seconds,
                 tool::peakMemoryMiB());
}

// The scene's extinction law (render.extinction_law) unless the command line named one.
bake::BakeSettings forScene(bake::BakeSettings settings, const std::string& law,
                            const scenes::Scene& scene)
{
    settings.extinctionLaw = law.empty() ? scene.render.model.extinctionLaw : law;
    bake::checkVoxelSize(settings.voxelSize_cm);
    return settings;
}

int bakeOne(const fs::path& sceneFile, int tree, const bake::BakeSettings& common,
            const std::string& law, const Output& output, const fs::path& out,
            double maxMemoryGiB)
{
    const auto start = std::chrono::steady_clock::now();
    if (out.extension() != ".vdb") {
        throw InputError("--out '" + out.string() + "': the grids' name must end in .vdb (the " +
                         "branch mesh goes beside it as .obj)");
    }
    io::checkWritable(out);  // before the work, not after it
    io::checkOutputsApart({out, out.string() + ".json", meshBeside(out)}, {sceneFile});
    const scenes::Scene scene = scenes::loadScene(sceneFile);
    const bake::BakeSettings settings = forScene(common, law, scene);
    if (tree < 0 || std::size_t(tree) >= scene.trees.size()) {
        std::cerr << "bake: " << sceneFile.string() << ": no tree " << tree << " (the scene has "
                  << scene.trees.size() << ")\n";
        return 2;
    }
    bake::checkMemory(bake::estimateBake(scene, {std::size_t(tree)}, settings.voxelSize_cm),
                      bake::memoryLimit(maxMemoryGiB), sceneFile.string());
    Totals totals;
    (void)bakeTree(scene, sceneFile, std::size_t(tree), settings, output, out, totals);
    summarize(totals, start);
    return 0;
}

fs::path treeFile(const fs::path& dir, std::size_t index)
{
    char name[32];
    std::snprintf(name, sizeof name, "tree_%03zu.vdb", index);
    return dir / name;
}

/// A folder's instance list as a previous `bake scene` left it, read leniently: nothing from a
/// list that is missing, unreadable or not one (a render of the folder refuses it itself).
std::optional<nlohmann::json> previousList(const fs::path& listFile)
{
    std::ifstream in(listFile);
    if (!in) return std::nullopt;
    nlohmann::json list = nlohmann::json::parse(in, nullptr, /*allow_exceptions=*/false);
    if (!list.is_object()) return std::nullopt;
    const auto format = list.find("format");
    if (format == list.end() || *format != "pine-instances") return std::nullopt;
    return list;
}

/// The files an instance list names: each placement's grids, their manifest and its mesh.
/// Names that are not bare file names (a hand-edited "../x.vdb") are skipped, since only the
/// folder's own files are meant.
std::set<std::string> filesListed(const nlohmann::json& list)
{
    std::set<std::string> names;
    const auto instances = list.find("instances");
    if (instances == list.end() || !instances->is_array()) return names;
    const auto add = [&](const nlohmann::json& entry, const char* key, const char* suffix) {
        const auto name = entry.find(key);
        if (name == entry.end() || !name->is_string()) return;
        const std::string bare = name->get<std::string>();
        if (bare.empty() || bare == "." || bare == ".." || fs::path(bare).filename() != bare) {
            return;
        }
        names.insert(bare + suffix);
    };
    for (const nlohmann::json& entry : *instances) {
        if (!entry.is_object()) continue;
        add(entry, "grids", "");
        add(entry, "grids", ".json");  // the grids' manifest
        add(entry, "mesh", "");
    }
    return names;
}

/// Writes the new instance list `list` to `listFile` and removes from its folder the files
/// the list it replaces named and this one does not: a scene of fewer trees baked over a
/// larger one would otherwise leave tree_NNN files that nothing lists. Both in the folder's
/// turn (io::FolderLock), so that the list replaced is the one read. Never the list itself,
/// an input or anything but a regular file; a file that cannot be removed is warned of, the
/// bake being done. Returns how many were removed.
std::size_t writeListInTurn(const fs::path& listFile, const nlohmann::json& list,
                            const fs::path& sceneFile)
{
    std::size_t removed = 0;
    inFolderTurn(listFile, [&] {
        const std::optional<nlohmann::json> before = previousList(listFile);
        writeTextReplacingStale(listFile, list.dump(1) + "\n");
        if (!before) return;
        const std::set<std::string> now = filesListed(list);
        const fs::path dir = io::folderOf(listFile);
        for (const std::string& name : filesListed(*before)) {
            const fs::path file = dir / name;
            std::error_code error;
            if (now.count(name) != 0 || name == listFile.filename() ||
                !fs::is_regular_file(fs::symlink_status(file, error)) ||
                io::sameFile(file, sceneFile)) {
                continue;
            }
            if (fs::remove(file, error)) {
                ++removed;
            } else if (error) {
                std::cerr << "bake: warning: cannot remove '" << file.string()
                          << "', left from the folder's previous bake: " << error.message() << "\n";
            }
        }
    });
    return removed;
}

int bakeScene(const fs::path& sceneFile, const bake::BakeSettings& common, const std::string& law,
              const Output& output, const fs::path& dir, double maxMemoryGiB)
{
    const auto start = std::chrono::steady_clock::now();
    const scenes::Scene scene = scenes::loadScene(sceneFile);
    const bake::BakeSettings settings = forScene(common, law, scene);
    const std::size_t n = scene.trees.size();
    std::vector<std::size_t> all(n);
    for (std::size_t i = 0; i < n; ++i) all[i] = i;
    bake::checkMemory(
        bake::estimateBake(scene, all, settings.voxelSize_cm,
                           std::size_t(tbb::this_task_arena::max_concurrency())),
        bake::memoryLimit(maxMemoryGiB), sceneFile.string());
    const fs::path listFile = dir / "instances.json";
    for (std::size_t i = 0; i < n; ++i) {  // the names differ; the scene may be among them
        io::checkOutputsApart({treeFile(dir, i), treeFile(dir, i).string() + ".json",
                               meshBeside(treeFile(dir, i)), listFile},
                              {sceneFile});
    }
    // The folder made only once nothing above refuses the run.
    io::checkWritableFolder(dir);
    io::checkWritable(treeFile(dir, 0));
    Totals totals;
    std::vector<bake::ProxyInstance> instances(n);
    tool::Progress progress("bake:");
    // Trees in parallel, one task each; bakeBoughs also splits a tree's boughs among threads.
    tbb::parallel_for(std::size_t(0), n, [&](std::size_t i) {
        instances[i] = bakeTree(scene, sceneFile, i, settings, output, treeFile(dir, i), totals);
        progress.count(totals.trees.load(), n, "trees");
    });
    progress.finish();
    // Last: a list names only files already in place. A bake killed before it leaves the
    // previous list, which still names what this one would have removed.
    const std::size_t removed = writeListInTurn(
        listFile, bake::instanceList(sceneFile.string(), output.unit, instances), sceneFile);
    if (removed > 0) {
        tool::info() << "bake: removed " << removed << (removed == 1 ? " file" : " files")
                     << " of the previous bake in '" << dir.string()
                     << "' that this scene does not have\n";
    }
    summarize(totals, start);
    return 0;
}

/// A .vdb file to verify, and why it is suspect before it is read: a folder's file that the
/// folder's instances.json does not name (left by another bake, or put there by hand).
struct FileToVerify {
    fs::path path;
    std::string unlisted;
};

/// The .vdb files among `paths`, a folder standing for the .vdb files in it (sorted).
std::vector<FileToVerify> vdbFiles(const std::vector<fs::path>& paths)
{
    std::vector<FileToVerify> files;
    for (const fs::path& path : paths) {
        std::error_code error;
        if (!fs::is_directory(path, error)) {
            files.push_back({path, {}});
            continue;
        }
        std::vector<fs::path> inside;
        for (fs::directory_iterator it(path, error), end; !error && it != end;
             it.increment(error)) {
            if (it->path().extension() == ".vdb") inside.push_back(it->path());
        }
        if (error) throw InputError("cannot list '" + path.string() + "': " + error.message());
        std::sort(inside.begin(), inside.end());
        const fs::path listFile = path / "instances.json";
        const std::optional<nlohmann::json> list = previousList(listFile);
        const std::set<std::string> listed = list ? filesListed(*list) : std::set<std::string>();
        for (const fs::path& file : inside) {
            const bool unlisted = list && listed.count(file.filename().string()) == 0;
            files.push_back({file, unlisted
                                       ? "not in " + listFile.string() + ", left by another bake?"
                                       : std::string()});
        }
    }
    return files;
}

/// Reads every file as a render would (manifest, then OpenVDB in a child process): one line
/// each; status 2 if any is refused, else 3 if any was read without a manifest or lies in a
/// folder given whose instances.json does not name it (unverified; a file given by name is
/// not checked against its folder's list).
int verify(const std::vector<fs::path>& paths, double maxMemoryGiB)
{
    const std::vector<FileToVerify> files = vdbFiles(paths);
    if (files.empty()) throw InputError("no .vdb files in what was given");
    int refused = 0, unverified = 0;
    for (const FileToVerify& file : files) {
        try {
            const bake::ReadGrids read =
                bake::readTreeGrids(file.path, bake::memoryLimit(maxMemoryGiB));
            const bake::TreeGrids& grids = read.grids;
            std::string why = read.unverified;
            if (!file.unlisted.empty()) why += (why.empty() ? "" : "; ") + file.unlisted;
            std::cout << file.path.string() << ": " << (why.empty() ? "ok" : "unverified") << ", "
                      << grids.density->activeVoxelCount() << " voxels of " << grids.voxelSize_cm
                      << " cm, extinction law " << grids.extinctionLaw;
            if (!why.empty()) {
                std::cout << " (" << why << ")";
                ++unverified;
            }
            std::cout << "\n";
        } catch (const InputError& e) {
            std::cout << file.path.string() << ": refused: " << e.what() << "\n";
            ++refused;
        }
    }
    tool::info() << "bake: " << files.size() - std::size_t(refused) << " of " << files.size()
                 << " files read whole";
    if (unverified > 0) tool::info() << ", " << unverified << " of them unverified";
    tool::info() << '\n';
    // A render reads an unverified file; a check says it could not vouch for it.
    return refused > 0 ? 2 : unverified > 0 ? 3 : 0;
}

}  // namespace

int main(int argc, char** argv)
{
    CLI::App app{"bake: voxelize the boughs of a scene's trees into OpenVDB grids (density, "
                 "layer gradient and opacity, needle direction and albedo)"};
    app.require_subcommand(1);

    fs::path sceneFile, out, outDir;
    int tree = 0;
    double maxMemoryGiB = 0.0;  // 0: bake::defaultMemoryLimit()
    bake::BakeSettings settings;
    std::string law, units = "m", frame = "tree";
    const CLI::Validator positive = tool::positiveNumber();
    const auto addCommon = [&](CLI::App* cmd) {
        cmd->add_option("scene", sceneFile, "Scene file (JSON)")->required();
        cmd->add_option("--voxel-size", settings.voxelSize_cm, "Voxel size in cm")
            ->required()
            ->check(positive);
        cmd->add_option("--extinction-law", law,
                        "How the field stops light, written into the file (default: the "
                        "scene's render.extinction_law, fibre unless it says otherwise)")
            ->check(CLI::IsMember(bake::extinctionLawNames()));
        cmd->add_option("--max-memory", maxMemoryGiB,
                        "Refuse, before any work, a bake estimated to need more memory than "
                        "this, in GiB (default: 80% of this machine's, " +
                            bake::formatBytes(bake::defaultMemoryLimit()) + ")")
            ->check(positive);
        cmd->add_option("--levels", settings.pyramidLevels,
                        "Density levels at h, 2h, 4h, ... (1: no pyramid)")
            ->default_val(settings.pyramidLevels)
            ->check(tool::wholeNumberIn(1, 16));
        cmd->add_option("--units", units,
                        "Length unit of the files (transform, extinction per unit length, mesh)")
            ->default_val(units)
            ->check(CLI::IsMember({"m", "cm"}));
        cmd->add_option("--frame", frame,
                        "tree: each tree in its own frame, origin at its base (placements in "
                        "instances.json); world: the scene's frame")
            ->default_val(frame)
            ->check(CLI::IsMember({"tree", "world"}));
    };
    auto* treeCmd = app.add_subcommand("tree", "Bake one tree of a scene into one .vdb");
    addCommon(treeCmd);
    treeCmd->add_option("--tree", tree, "Index of the tree in the scene (from 0)")->required();
    treeCmd->add_option("--out", out, "Output .vdb; its manifest goes to OUT.json, the branch "
                                      "mesh beside it as .obj")
        ->required();

    auto* sceneCmd = app.add_subcommand(
        "scene", "Bake every tree: DIR/tree_000.vdb (+ .obj mesh), ..., DIR/instances.json");
    addCommon(sceneCmd);
    sceneCmd->add_option("--out-dir", outDir, "Output folder (created if missing)")->required();

    std::vector<fs::path> verifyPaths;
    auto* verifyCmd = app.add_subcommand(
        "verify",
        "Check baked files as a render reads them (manifest, then OpenVDB isolated); "
        "exit status 2 if any is refused, 3 if any has no manifest or lies in a folder given "
        "whose instances.json does not name it");
    verifyCmd->add_option("paths", verifyPaths, ".vdb files, or folders of them")->required();
    verifyCmd->add_option("--max-memory", maxMemoryGiB,
                          "Memory OpenVDB may use to read one file, in GiB (default: 80% of "
                          "this machine's)")
        ->check(positive);

    return tool::run("bake", app, argc, argv, [&] {
        const Output output{bake::lengthUnit(units), frame == "tree"};
        if (*treeCmd) return bakeOne(sceneFile, tree, settings, law, output, out, maxMemoryGiB);
        if (*verifyCmd) return verify(verifyPaths, maxMemoryGiB);
        return bakeScene(sceneFile, settings, law, output, outDir, maxMemoryGiB);
    });
}
