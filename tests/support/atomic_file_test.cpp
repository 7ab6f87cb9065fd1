// The one atomic writer and writability probe every component and tool uses.
#include "pine/support/atomic_file.h"

#include "temp_dir.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <fstream>
#include <iterator>
#include <sstream>
#include <vector>

namespace pine::io {
namespace {

namespace fs = std::filesystem;

std::vector<std::string> listing(const fs::path& dir)
{
    std::vector<std::string> names;
    for (const auto& e : fs::directory_iterator(dir)) names.push_back(e.path().filename().string());
    std::sort(names.begin(), names.end());
    return names;
}

std::string readFile(const fs::path& p)
{
    std::ifstream in(p, std::ios::binary);
    return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

TEST(AtomicFile, AFailedWriteLeavesTheOldFileAndNoTemporary)
{
    const test::TempDir dir;
    const fs::path file = dir.write("report.md", "old");
    try {
        writeAtomically(file, [](const fs::path& tmp) {
            std::ofstream(tmp) << "half";
            throw std::runtime_error("disk full");
        });
        ADD_FAILURE() << "no InputError";
    } catch (const InputError& e) {
        EXPECT_EQ(std::string(e.what()), "cannot write '" + file.string() + "': disk full");
    }
    EXPECT_EQ(readFile(file), "old");
    EXPECT_EQ(listing(dir.path()), std::vector<std::string>{"report.md"});
    writeTextAtomically(file, "new");
    EXPECT_EQ(readFile(file), "new");
    EXPECT_EQ(listing(dir.path()), std::vector<std::string>{"report.md"});
}

TEST(AtomicFile, CheckWritableRejectsMissingFolderAndAcceptsAWritableOne)
{
    const test::TempDir dir;
    try {
        checkWritable(dir.path() / "missing" / "frame.exr");
        ADD_FAILURE() << "no InputError for a missing folder";
    } catch (const InputError& error) {
        EXPECT_NE(std::string(error.what()).find((dir.path() / "missing").string()),
                  std::string::npos)
            << error.what();
    }
    dir.write("plain.txt", "not a folder");
    EXPECT_THROW(checkWritable(dir.path() / "plain.txt" / "frame.exr"), InputError);
    EXPECT_THROW(checkWritable(dir.path()), InputError) << "a folder is no file";
    EXPECT_THROW(checkWritable(""), InputError);
    EXPECT_NO_THROW(checkWritable(dir.path() / "frame.exr"));
    EXPECT_EQ(listing(dir.path()), std::vector<std::string>{"plain.txt"}) << "the probe is removed";
}

TEST(AtomicFile, WhyUnreadableTellsAMissingFileFromOneThatIsNoFile)
{
    // A device or a folder is not "missing" (bake verify /dev/zero said so), nor a loop of
    // links (the system's reason, not "no such file").
    const test::TempDir dir;
    dir.write("plain.txt", "text");
    EXPECT_EQ(whyUnreadable(dir.path() / "plain.txt"), "");
    EXPECT_EQ(whyUnreadable(dir.path() / "missing.json"), "no such file");
    EXPECT_EQ(whyUnreadable(dir.path()), "not a regular file");
    EXPECT_EQ(whyUnreadable("/dev/null"), "not a regular file");
    fs::create_symlink(dir.path() / "loop", dir.path() / "loop");
    EXPECT_EQ(whyUnreadable(dir.path() / "loop").rfind("cannot reach it: ", 0), 0u)
        << whyUnreadable(dir.path() / "loop");
    fs::create_symlink(dir.path() / "plain.txt", dir.path() / "link");
    EXPECT_EQ(whyUnreadable(dir.path() / "link"), "");
}

TEST(AtomicFile, CheckWritableFolderCreatesItOrSaysWhyNot)
{
    const test::TempDir dir;
    EXPECT_NO_THROW(checkWritableFolder(dir.path() / "a" / "b"));
    EXPECT_TRUE(fs::is_directory(dir.path() / "a" / "b"));
    EXPECT_TRUE(listing(dir.path() / "a" / "b").empty());
    // The probe a run killed between making and removing it left, the next check removes
    // (fuzz.kill_and_concurrency found one in a baked folder after its rerun).
    dir.write("a/b/.probe.tmp-0123456789abcdef", "");
    EXPECT_NO_THROW(checkWritableFolder(dir.path() / "a" / "b"));
    EXPECT_TRUE(listing(dir.path() / "a" / "b").empty());
    dir.write("plain.txt", "not a folder");
    EXPECT_THROW(checkWritableFolder(dir.path() / "plain.txt" / "c"), InputError);
    EXPECT_THROW(checkWritableFolder("/proc/no-such-dir"), InputError);
}

TEST(AtomicFile, AFolderThatRefusesNewFilesIsNamedWithTheSystemsReason)
{
    // /proc exists and takes no new file (ENOENT, whoever runs the test, root included).
    try {
        checkWritable("/proc/frame.exr");
        ADD_FAILURE() << "no InputError for a file in /proc";
    } catch (const InputError& error) {
        EXPECT_EQ(std::string(error.what()),
                  "cannot write '/proc/frame.exr': cannot create a file in folder '/proc' (" +
                      std::string(std::strerror(ENOENT)) + ")");
    }
}

TEST(AtomicFile, ANameNearTheLongestAllowedIsWrittenNotRefused)
{
    // The temporary adds 22 bytes to the name: it must still fit in NAME_MAX (255).
    const test::TempDir dir;
    const fs::path file = dir.path() / (std::string(250, 'n') + ".exr");
    EXPECT_LE(temporaryBeside(file).filename().string().size(), 255u);
    EXPECT_EQ(temporaryBeside(file).parent_path(), file.parent_path());
    writeTextAtomically(file, "long");
    EXPECT_EQ(readFile(file), "long");
    EXPECT_EQ(listing(dir.path()).size(), 1u);
}

TEST(AtomicFile, ADeviceIsNotAnOutput)
{
    // A rename onto /dev/null would replace the device node with a regular file.
    try {
        checkWritable("/dev/null");
        ADD_FAILURE() << "no InputError";
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("not a regular file"), std::string::npos) << e.what();
    }
}

TEST(AtomicFile, OutputsApartFromInputsAndFromEachOther)
{
    const test::TempDir dir;
    const fs::path scene = dir.write("scene.json", "{}");
    fs::create_directories(dir.path() / "sub");
    const fs::path out = dir.path() / "out.exr";
    EXPECT_NO_THROW(checkOutputsApart({out, dir.path() / "out.png", {}}, {scene}));
    // The same file under other names: "..", a hard link, a symbolic link.
    const fs::path viaDots = dir.path() / "sub" / ".." / "scene.json";
    const fs::path hard = dir.path() / "hard.json";
    const fs::path soft = dir.path() / "soft.json";
    fs::create_hard_link(scene, hard);
    fs::create_symlink(scene, soft);
    for (const fs::path& alias : {scene, viaDots, hard, soft}) {
        try {
            checkOutputsApart({out, alias}, {scene});
            ADD_FAILURE() << alias << " accepted";
        } catch (const InputError& e) {
            EXPECT_NE(std::string(e.what()).find("also an input"), std::string::npos) << e.what();
        }
    }
    // Two outputs, one file (neither exists yet).
    try {
        checkOutputsApart({out, dir.path() / "sub" / ".." / "out.exr"}, {});
        ADD_FAILURE() << "two names of one output accepted";
    } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find("the same file"), std::string::npos) << e.what();
    }
    EXPECT_EQ(readFile(scene), "{}");
}

TEST(AtomicFile, WhatMustComeFirstRunsBeforeTheRenameAndCanStopIt)
{
    const test::TempDir dir;
    const fs::path file = dir.write("grid.vdb", "old");
    bool ran = false;
    writeAtomically(
        file, [](const fs::path& tmp) { std::ofstream(tmp) << "new"; },
        [&] {
            ran = true;
            EXPECT_EQ(readFile(file), "old");  // not renamed yet
        });
    EXPECT_TRUE(ran);
    EXPECT_EQ(readFile(file), "new");
    EXPECT_THROW(writeAtomically(
                     file, [](const fs::path& tmp) { std::ofstream(tmp) << "newer"; },
                     [] { throw std::runtime_error("manifest: disk full"); }),
                 InputError);
    EXPECT_EQ(readFile(file), "new");
    EXPECT_EQ(listing(dir.path()), std::vector<std::string>{"grid.vdb"});
    // A killed write's temporary, and a file that only looks like one, beside it.
    std::ofstream(dir.path() / ".grid.vdb.tmp-0123456789abcdef") << "half";
    std::ofstream(dir.path() / ".grid.vdb.tmp-mine") << "keep";
    EXPECT_EQ(removeStaleTemporaries(file), 1);
    EXPECT_EQ(listing(dir.path()),
              (std::vector<std::string>{".grid.vdb.tmp-mine", "grid.vdb"}));
}

}  // namespace
}  // namespace pine::io
