#include "module_loader.h"

#include <dlfcn.h>

#include <filesystem>
#include <system_error>
#include <vector>

namespace pine::vdbtrace {
namespace {

namespace fs = std::filesystem;

// Where a module may lie, in order: beside the executable (the build's bin/, where every tool
// and test program is), then where `cmake --install` puts it (PINE_INSTALL_MODULE_DIR,
// relative to the installed executables' folder).
std::vector<fs::path> candidates(const char* file)
{
    std::error_code error;
    const fs::path executable = fs::read_symlink("/proc/self/exe", error);
    if (error) return {};
    const fs::path folder = executable.parent_path();
    return {folder / file, folder / PINE_INSTALL_MODULE_DIR / file};
}

}  // namespace

void* loadModuleEntry(const char* file, const char* entry, const std::string& what,
                      std::string& error)
{
    std::string tried;
    for (const fs::path& path : candidates(file)) {
        std::error_code missing;
        if (!fs::exists(path, missing)) {
            tried += (tried.empty() ? "" : ", ") + path.lexically_normal().string();
            continue;
        }
        void* module = dlopen(path.c_str(), RTLD_NOW | RTLD_LOCAL);
        if (!module) {
            error = "cannot load " + what + " '" + path.string() + "': " + dlerror();
            return nullptr;
        }
        void* symbol = dlsym(module, entry);
        if (!symbol) error = what + " '" + path.string() + "' has no entry point " + entry;
        return symbol;
    }
    error = what + " " + file + " is missing (" +
            (tried.empty() ? "the executable's folder is unknown" : "looked for " + tried) +
            "): rebuild or reinstall";
    return nullptr;
}

}  // namespace pine::vdbtrace
