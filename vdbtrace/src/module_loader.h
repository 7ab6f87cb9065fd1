// The tool's optional parts live in modules loaded on first use (libpine_image_codec.so:
// OpenImageIO; libpine_mpi_ranks.so: Open MPI), so that a command that needs neither does not
// load their hundreds of shared libraries before main().
#pragma once

#include <string>

namespace pine::vdbtrace {

/// The entry point `entry` (extern "C") of the module `file`, looked for beside the executable
/// (the build's bin/), then in ../lib/pine from it (`cmake --install`); never unloaded. Null,
/// with `error` saying where it looked and why it failed (one line, naming `what`: "the image
/// module"), if it cannot be loaded.
void* loadModuleEntry(const char* file, const char* entry, const std::string& what,
                      std::string& error);

}  // namespace pine::vdbtrace
