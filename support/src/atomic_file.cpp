#include "pine/support/atomic_file.h"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <csignal>
#include <cstdlib>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <new>
#include <random>

namespace pine::io {

namespace fs = std::filesystem;

namespace {

// ".NAME.tmp-": what every temporary of `file` begins with, NAME shortened to fit NAME_MAX.
std::string temporaryPrefix(const fs::path& file)
{
    constexpr std::size_t kNameMax = 255, kAdded = 1 + 5 + 16;
    std::string base = file.filename().string();
    if (base.size() > kNameMax - kAdded) base.resize(kNameMax - kAdded);
    std::string name = ".";  // built in steps: GCC 12's -Wrestrict misfires on "." + string
    name += base;
    name += ".tmp-";
    return name;
}

// The user's error about an output: "cannot write 'FILE': WHY".
InputError cannotWrite(const fs::path& file, const std::string& why)
{
    return InputError("cannot write '" + file.string() + "': " + why);
}

}  // namespace

fs::path folderOf(const fs::path& file)
{
    return file.has_parent_path() ? file.parent_path() : fs::path(".");
}

int removeStaleTemporaries(const fs::path& file)
{
    const fs::path folder = folderOf(file);
    const std::string prefix = temporaryPrefix(file);
    std::error_code error;
    int removed = 0;
    for (fs::directory_iterator it(folder, error), end; !error && it != end; it.increment(error)) {
        const std::string name = it->path().filename().string();
        std::error_code kind;
        if (name.size() == prefix.size() + 16 && name.compare(0, prefix.size(), prefix) == 0 &&
            it->is_regular_file(kind)) {
            std::error_code ignored;
            if (fs::remove(it->path(), ignored)) ++removed;
        }
    }
    return removed;
}

fs::path temporaryBeside(const fs::path& file)
{
    static thread_local std::mt19937_64 rng{std::random_device{}()};
    char hex[17];
    std::snprintf(hex, sizeof hex, "%016llx", static_cast<unsigned long long>(rng()));
    const fs::path folder = folderOf(file);
    // ".NAME.tmp-HEX" within NAME_MAX (255 bytes on Linux): NAME shortened if need be.
    return folder / (temporaryPrefix(file) + hex);
}

void writeAtomically(const fs::path& file, const std::function<void(const fs::path&)>& write,
                     const std::function<void()>& beforeRename)
{
    const fs::path tmp = temporaryBeside(file);
    std::error_code ignored;
    const auto refuse = [&](const std::string& why) {
        fs::remove(tmp, ignored);
        return cannotWrite(file, why);
    };
    // What a step throws becomes the user's error about this file, the temporary removed;
    // running out of memory (not the output's fault), non-standard exceptions and what
    // beforeRename's own writes say of their files (InputError) pass as they are.
    const auto step = [&](auto&& run, bool passInputErrors) {
        try {
            run();
        } catch (const InputError& e) {
            if (!passInputErrors) throw refuse(e.what());
            fs::remove(tmp, ignored);
            throw;
        } catch (const std::bad_alloc&) {
            fs::remove(tmp, ignored);
            throw;
        } catch (const std::exception& e) {
            throw refuse(e.what());
        } catch (...) {
            fs::remove(tmp, ignored);
            throw;
        }
    };
    step([&] { write(tmp); }, false);
    // The bytes on the disk before the name: a full disk fails here, not after the rename.
    const int fd = ::open(tmp.c_str(), O_RDONLY);
    if (fd < 0 || ::fsync(fd) != 0) {
        const int why = errno;
        if (fd >= 0) ::close(fd);
        throw refuse(std::strerror(why));
    }
    ::close(fd);
    if (beforeRename) step(beforeRename, true);
    // Fault injection (tests/fuzz/kill_test.py): a kill at the one moment random kills miss.
    if (const char* name = std::getenv("PINE_KILL_BEFORE_RENAME");
        name && file.filename() == name) {
        ::raise(SIGKILL);
    }
    std::error_code error;
    fs::rename(tmp, file, error);
    if (error) throw refuse(error.message());
}

void writeBytes(const fs::path& file, std::string_view bytes)
{
    std::ofstream out(file, std::ios::binary);
    out.write(bytes.data(), std::streamsize(bytes.size()));
    out.close();
    if (!out) throw std::runtime_error(std::strerror(errno));
}

void writeTextAtomically(const fs::path& file, const std::string& text)
{
    writeAtomically(file, [&](const fs::path& tmp) { writeBytes(tmp, text); });
}

namespace {

// Creates and removes a file in `folder`: permission bits do not tell the whole story
// (read-only mounts, ACLs, root), so it is tried. Returns why not, or "".
std::string probeFolder(const fs::path& folder, const fs::path& beside)
{
    std::error_code error;
    if (!fs::is_directory(folder, error)) return "folder '" + folder.string() + "' is missing";
    const fs::path probe = temporaryBeside(beside);
    std::FILE* f = std::fopen(probe.c_str(), "wx");
    // The system's own reason: a folder that exists can refuse a new file for reasons other
    // than its permissions (a read-only mount; /proc answers ENOENT).
    if (!f) {
        return "cannot create a file in folder '" + folder.string() + "' (" + std::strerror(errno) +
               ")";
    }
    std::fclose(f);
    fs::remove(probe, error);
    return "";
}

}  // namespace

std::string whyUnreadable(const fs::path& file)
{
    std::error_code error;
    const fs::file_status status = fs::status(file, error);
    if (status.type() == fs::file_type::not_found) return "no such file";
    if (error) return "cannot reach it: " + error.message();
    if (!fs::is_regular_file(status)) return "not a regular file";
    return {};
}

void checkWritableName(const fs::path& file)
{
    const auto refuse = [&](const std::string& why) { return cannotWrite(file, why); };
    if (file.empty() || !file.has_filename()) throw refuse("no file name");
    std::error_code error;
    if (fs::is_directory(file, error)) throw refuse("it is a folder");
    const fs::file_status status = fs::status(file, error);
    if (fs::exists(status) && !fs::is_regular_file(status)) {
        throw refuse("it is not a regular file (a device, a pipe or a socket)");
    }
}

void checkWritable(const fs::path& file)
{
    checkWritableName(file);
    const fs::path folder = folderOf(file);
    if (const std::string why = probeFolder(folder, file); !why.empty()) {
        throw cannotWrite(file, why);
    }
}

bool sameFile(const fs::path& a, const fs::path& b)
{
    std::error_code ea, eb;
    if (fs::exists(a, ea) && fs::exists(b, eb)) {
        std::error_code error;
        const bool same = fs::equivalent(a, b, error);
        if (!error) return same;
    }
    // Resolved where the folders allow it, else lexically: a failure is never "the same".
    const auto resolved = [](const fs::path& p) {
        std::error_code error;
        const fs::path absolute = fs::absolute(p, error);
        if (error) return p.lexically_normal();
        const fs::path canonical = fs::weakly_canonical(absolute, error);
        return error ? absolute.lexically_normal() : canonical;
    };
    return resolved(a) == resolved(b);
}

void checkOutputsApart(const std::vector<fs::path>& outputs, const std::vector<fs::path>& inputs)
{
    for (std::size_t i = 0; i < outputs.size(); ++i) {
        if (outputs[i].empty()) continue;
        for (const fs::path& in : inputs) {
            if (!in.empty() && sameFile(outputs[i], in)) {
                throw cannotWrite(outputs[i],
                                  "it is also an input of this run ('" + in.string() + "')");
            }
        }
        for (std::size_t j = 0; j < i; ++j) {
            if (!outputs[j].empty() && sameFile(outputs[i], outputs[j])) {
                throw InputError("cannot write '" + outputs[i].string() + "' and '" +
                                 outputs[j].string() + "': they are the same file");
            }
        }
    }
}

void checkFolderSparesInputs(const fs::path& folder,
                             const std::function<bool(const std::string&)>& writes,
                             const std::vector<fs::path>& inputs)
{
    for (const fs::path& in : inputs) {
        if (in.empty()) continue;
        std::error_code error;
        const fs::path target = fs::canonical(in, error);
        for (const fs::path& file : {in, error ? in : target}) {
            const fs::path parent = folderOf(file);
            const std::string name = file.filename().string();
            if (writes(name) && sameFile(parent, folder)) {
                throw InputError("cannot write into '" + folder.string() + "': this run writes '" +
                                 name + "' there, and '" + in.string() +
                                 "' is an input of this run");
            }
        }
    }
}

void checkWritableFolder(const fs::path& folder)
{
    std::error_code error;
    fs::create_directories(folder, error);
    if (const std::string why = probeFolder(folder, folder / "probe"); !why.empty()) {
        throw InputError("cannot write into '" + folder.string() + "': " +
                         (error ? "cannot create it: " + error.message() : why));
    }
    // The probes of runs killed between making one and removing it (a probe of a run now,
    // removed under it, only fails to remove it itself).
    removeStaleTemporaries(folder / "probe");
}

}  // namespace pine::io
