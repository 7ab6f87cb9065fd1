#include "pine/support/atomic_file.h"

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <new>
#include <random>

namespace pine::io {

namespace fs = std::filesystem;

fs::path temporaryBeside(const fs::path& file)
{
    static thread_local std::mt19937_64 rng{std::random_device{}()};
    char hex[17];
    std::snprintf(hex, sizeof hex, "%016llx", static_cast<unsigned long long>(rng()));
    const fs::path folder = file.has_parent_path() ? file.parent_path() : fs::path(".");
    std::string name = ".";  // built in steps: GCC 12's -Wrestrict misfires on "." + string
    name += file.filename().string();
    name += ".tmp-";
    name += hex;
    return folder / name;
}

void writeAtomically(const fs::path& file, const std::function<void(const fs::path&)>& write)
{
    const fs::path tmp = temporaryBeside(file);
    std::error_code ignored;
    const auto refuse = [&](const std::string& why) {
        fs::remove(tmp, ignored);
        return InputError("cannot write '" + file.string() + "': " + why);
    };
    try {
        write(tmp);
    } catch (const std::bad_alloc&) {  // not the output's fault: not the user's error
        fs::remove(tmp, ignored);
        throw;
    } catch (const std::exception& e) {
        throw refuse(e.what());
    } catch (...) {
        fs::remove(tmp, ignored);
        throw;
    }
    std::error_code error;
    fs::rename(tmp, file, error);
    if (error) throw refuse(error.message());
}

void writeTextAtomically(const fs::path& file, const std::string& text)
{
    writeAtomically(file, [&](const fs::path& tmp) {
        std::ofstream out(tmp, std::ios::binary);
        out << text;
        out.close();
        if (!out) throw std::runtime_error(std::strerror(errno));
    });
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
    if (!f) return "folder '" + folder.string() + "' is not writable: " + std::strerror(errno);
    std::fclose(f);
    fs::remove(probe, error);
    return "";
}

}  // namespace

void checkWritable(const fs::path& file)
{
    const auto refuse = [&](const std::string& why) {
        return InputError("cannot write '" + file.string() + "': " + why);
    };
    if (file.empty() || !file.has_filename()) throw refuse("no file name");
    std::error_code error;
    if (fs::is_directory(file, error)) throw refuse("it is a folder");
    const fs::path folder = file.has_parent_path() ? file.parent_path() : fs::path(".");
    if (const std::string why = probeFolder(folder, file); !why.empty()) throw refuse(why);
}

void checkWritableFolder(const fs::path& folder)
{
    std::error_code error;
    fs::create_directories(folder, error);
    if (const std::string why = probeFolder(folder, folder / "probe"); !why.empty()) {
        throw InputError("cannot write into '" + folder.string() + "': " +
                         (error ? "cannot create it: " + error.message() : why));
    }
}

}  // namespace pine::io
