// Loads the image module (image_codec.h) on first use.
#include "image_codec.h"

#include "module_loader.h"

#include <mutex>

namespace pine::vdbtrace::codec {
namespace {

struct Loaded {
    const Codec* codec = nullptr;
    std::string error;
};

Loaded load()
{
    using Entry = const Codec* (*)();
    Loaded loaded;
    const auto entry = reinterpret_cast<Entry>(
        loadModuleEntry(kModuleFile, kModuleEntry, "the image module", loaded.error));
    if (entry) loaded.codec = entry();
    return loaded;
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
