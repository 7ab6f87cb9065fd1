#include "manifest.h"

#include "pine/support/atomic_file.h"
#include "pine/support/input_error.h"

#include "pine/bake/tree_grids.h"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <vector>

namespace pine::bake::detail {

namespace fs = std::filesystem;

FileDigest digestFile(const fs::path& file)
{
    std::ifstream in(file, std::ios::binary);
    if (!in) throw BakeError("cannot read '" + file.string() + "'");
    Fnv1a64 hash;
    FileDigest digest;
    digest.bytes = hash.update(in);
    if (in.bad()) throw BakeError("cannot read '" + file.string() + "'");
    digest.fnv1a64 = hash.value();
    return digest;
}

fs::path manifestPath(const fs::path& file) { return fs::path(file.string() + ".json"); }

namespace {

nlohmann::json toJson(const FileDigest& digest)
{
    return {{"bytes", digest.bytes}, {"fnv1a64", Fnv1a64::hex(digest.fnv1a64)}};
}

/// A digest as recorded: bytes and the checksum's hex digits. Throws nlohmann::json::exception.
struct Recorded {
    std::uintmax_t bytes = 0;
    std::string fnv1a64;
};
Recorded recorded(const nlohmann::json& j)
{
    const nlohmann::json& bytes = j.at("bytes");
    if (!bytes.is_number_unsigned()) {  // a double cast to an integer is undefined behaviour
        throw nlohmann::json::type_error::create(302, "bytes must be a whole number", &bytes);
    }
    return {bytes.get<std::uintmax_t>(), j.at("fnv1a64").get<std::string>()};
}

}  // namespace

void writeManifest(const fs::path& file, const FileDigest& digest,
                   const std::optional<FileDigest>& previous)
{
    nlohmann::json j = toJson(digest);
    j["file"] = file.filename().string();
    if (previous) j["previous"] = toJson(*previous);
    try {
        io::writeTextAtomically(manifestPath(file), j.dump(2) + "\n");
    } catch (const InputError& e) {
        throw BakeError(e.what());
    }
}

std::optional<FileDigest> acceptedDigest(const fs::path& file)
{
    std::error_code error;
    if (!fs::exists(file, error)) return std::nullopt;
    try {
        FileDigest digest;
        (void)readVerified(file, &digest);
        return digest;
    } catch (const BakeError&) {
        return std::nullopt;
    }
}

namespace {

// A file to read whole: a folder or a device (/dev/zero) is named as such, not as missing.
void requireRegularFile(const fs::path& file)
{
    if (const std::string why = io::whyUnreadable(file); !why.empty()) {
        throw BakeError("'" + file.string() + "': " + why);
    }
}

}  // namespace

std::string readVerified(const fs::path& file, FileDigest* digest)
{
    const auto refuse = [&](const std::string& why) {
        return BakeError("'" + file.string() +
                         "' does not match its manifest (damaged, or changed since bake wrote "
                         "it): " + why);
    };
    const fs::path manifest = manifestPath(file);
    requireRegularFile(file);
    std::error_code error;
    if (!fs::is_regular_file(manifest, error)) {
        throw refuse("no manifest '" + manifest.filename().string() + "' beside it");
    }
    std::vector<Recorded> accepted;  // this file's digest, then the one it replaces if recorded
    try {
        std::ifstream in(manifest);
        const nlohmann::json j = nlohmann::json::parse(in);
        (void)j.at("file").get<std::string>();
        accepted.push_back(recorded(j));
        if (j.contains("previous")) accepted.push_back(recorded(j.at("previous")));
    } catch (const nlohmann::json::exception& e) {
        throw refuse("unreadable manifest: " + withoutLibraryTags(e.what()));
    }
    // The name is for people; size and checksum tie the manifest to the bytes, so a file renamed
    // with its manifest is still accepted.
    const std::uintmax_t bytes = fs::file_size(file, error);
    if (error) throw refuse("cannot read it: " + error.message());
    if (std::none_of(accepted.begin(), accepted.end(),
                     [&](const Recorded& r) { return r.bytes == bytes; })) {
        throw refuse(std::to_string(bytes) + " bytes, the manifest says " +
                     std::to_string(accepted.front().bytes));
    }
    // Read once, check, and hand OpenVDB these very bytes: the file cannot change in between.
    std::string content(bytes, '\0');
    {
        std::ifstream in(file, std::ios::binary);
        in.read(content.data(), std::streamsize(bytes));
        if (!in || std::uintmax_t(in.gcount()) != bytes) throw refuse("cannot read it whole");
    }
    Fnv1a64 hash;
    hash.update(content);
    const std::string hex = Fnv1a64::hex(hash.value());
    if (std::none_of(accepted.begin(), accepted.end(), [&](const Recorded& r) {
            return r.bytes == bytes && r.fnv1a64 == hex;
        })) {
        throw refuse("checksum " + hex + ", the manifest says " + accepted.front().fnv1a64);
    }
    if (digest) *digest = {bytes, hash.value()};
    return content;
}

std::string readWhole(const fs::path& file)
{
    requireRegularFile(file);
    std::error_code error;
    const std::uintmax_t bytes = fs::file_size(file, error);
    if (error) throw BakeError("cannot read '" + file.string() + "': " + error.message());
    std::string content(bytes, '\0');
    std::ifstream in(file, std::ios::binary);
    in.read(content.data(), std::streamsize(bytes));
    if (!in || std::uintmax_t(in.gcount()) != bytes) {
        throw BakeError("cannot read '" + file.string() + "' whole");
    }
    return content;
}

}  // namespace pine::bake::detail
