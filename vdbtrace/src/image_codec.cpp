// Loads the image module (image_codec.h) on first use.
#include "image_codec.h"

#include <dlfcn.h>

#include <mutex>
#include <system_error>

namespace pine::vdbtrace::codec {
namespace {

namespace fs = std::filesystem;

// Where the module may lie, in order: beside the executable (the build's bin/, where every
// tool and test program is), then where `cmake --install` puts it (PINE_INSTALL_MODULE_DIR,
// relative to the installed executables' folder).
std::vector<fs::path> candidates()
{
    std::error_code error;
    const fs::path executable = fs::read_symlink("/proc/self/exe", error);
    if (error) return {};
    const fs::path folder = executable.parent_path();
    return {folder / kModuleFile, folder / PINE_INSTALL_MODULE_DIR / kModuleFile};
}

struct Loaded {
    const Codec* codec = nullptr;
    std::string error;
};

Loaded load()
{
    using Entry = const Codec* (*)();
    std::string tried;
    for (const fs::path& path : candidates()) {
        std::error_code error;
        if (!fs::exists(path, error)) {
            tried += (tried.empty() ? "" : ", ") + path.lexically_normal().string();
            continue;
        }
        // Never closed: the codec lives as long as the process.
        void* module = dlopen(path.c_str(), RTLD_NOW | RTLD_LOCAL);
        if (!module) {
            return {nullptr, "cannot load the image module '" + path.string() +
                                 "': " + dlerror()};
        }
        const auto entry = reinterpret_cast<Entry>(dlsym(module, kModuleEntry));
        if (!entry) {
            return {nullptr, "the image module '" + path.string() + "' has no entry point " +
                                 kModuleEntry};
        }
        return {entry(), {}};
    }
    return {nullptr, std::string("the image module ") + kModuleFile + " is missing (" +
                         (tried.empty() ? "the executable's folder is unknown"
                                        : "looked for " + tried) +
                         "): rebuild or reinstall"};
}

}  // namespace

const Codec& imageCodec()
{
    static Loaded loaded;
    static std::once_flag once;
    std::call_once(once, [] { loaded = load(); });
    if (!loaded.codec) throw ImageError(loaded.error);
    return *loaded.codec;
}

}  // namespace pine::vdbtrace::codec
