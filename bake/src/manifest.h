// The manifest beside each baked file (`PATH.json`): its name, size and FNV-1a 64 checksum, so
// that a reader refuses a damaged or foreign file before OpenVDB parses it (a damaged .vdb can
// crash OpenVDB 10.0.1: DESIGN.md). Private to bake/.
#pragma once

#include "pine/support/fnv1a.h"

#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>

namespace pine::bake::detail {

using io::Fnv1a64;

struct FileDigest {
    std::uintmax_t bytes = 0;
    std::uint64_t fnv1a64 = 0;
};

/// Size and checksum of a file, read in chunks. Throws BakeError.
FileDigest digestFile(const std::filesystem::path& file);

std::filesystem::path manifestPath(const std::filesystem::path& file);

/// Writes `file`'s manifest atomically (temporary file, then rename). With `previous`, the
/// manifest also accepts the file it is about to replace: put in place before the new file,
/// it keeps the pair whole if the writer is killed between the two renames. Throws BakeError.
void writeManifest(const std::filesystem::path& file, const FileDigest& digest,
                   const std::optional<FileDigest>& previous = std::nullopt);

/// The digest of `file` if it exists and its manifest accepts it (readVerified).
std::optional<FileDigest> acceptedDigest(const std::filesystem::path& file);

/// The bytes of `file`, once its manifest is found and its size and checksum match it (or
/// match the previous file it records). Throws BakeError "'FILE' does not match its manifest
/// (written by bake?): WHY". Fills `digest`, if given, with what was checked.
std::string readVerified(const std::filesystem::path& file, FileDigest* digest = nullptr);

/// The bytes of `file`, unchecked (a file without a manifest). Throws BakeError.
std::string readWhole(const std::filesystem::path& file);

}  // namespace pine::bake::detail
