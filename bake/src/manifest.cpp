#include "manifest.h"

#include "pine/support/atomic_file.h"

#include "pine/bake/tree_grids.h"

#include <nlohmann/json.hpp>

#include <cstdio>
#include <fstream>
#include <sstream>

namespace pine::bake::detail {

namespace fs = std::filesystem;

void Fnv1a64::update(std::string_view bytes)
{
    for (const char c : bytes) {
        mHash ^= std::uint64_t(static_cast<unsigned char>(c));
        mHash *= 1099511628211ull;
    }
}

std::string Fnv1a64::hex(std::uint64_t hash)
{
    char text[17];
    std::snprintf(text, sizeof text, "%016llx", static_cast<unsigned long long>(hash));
    return text;
}

FileDigest digestFile(const fs::path& file)
{
    std::ifstream in(file, std::ios::binary);
    if (!in) throw BakeError("cannot read '" + file.string() + "'");
    Fnv1a64 hash;
    FileDigest digest;
    std::string chunk(1 << 20, '\0');
    while (in) {
        in.read(chunk.data(), std::streamsize(chunk.size()));
        const auto got = std::size_t(in.gcount());
        hash.update(std::string_view(chunk.data(), got));
        digest.bytes += got;
    }
    if (in.bad()) throw BakeError("cannot read '" + file.string() + "'");
    digest.fnv1a64 = hash.value();
    return digest;
}

fs::path manifestPath(const fs::path& file) { return fs::path(file.string() + ".json"); }

void writeManifest(const fs::path& file, const FileDigest& digest)
{
    const nlohmann::json j = {{"file", file.filename().string()},
                              {"bytes", digest.bytes},
                              {"fnv1a64", Fnv1a64::hex(digest.fnv1a64)}};
    try {
        io::writeTextAtomically(manifestPath(file), j.dump(2) + "\n");
    } catch (const InputError& e) {
        throw BakeError(e.what());
    }
}

std::string readVerified(const fs::path& file)
{
    const auto refuse = [&](const std::string& why) {
        return BakeError("'" + file.string() +
                         "' does not match its manifest (written by bake?): " + why);
    };
    const fs::path manifest = manifestPath(file);
    std::error_code error;
    if (!fs::is_regular_file(manifest, error)) {
        throw refuse("no manifest '" + manifest.filename().string() + "' beside it");
    }
    std::string expectedHash;
    std::uintmax_t expectedBytes = 0;
    try {
        std::ifstream in(manifest);
        const nlohmann::json j = nlohmann::json::parse(in);
        (void)j.at("file").get<std::string>();
        expectedBytes = j.at("bytes").get<std::uintmax_t>();
        expectedHash = j.at("fnv1a64").get<std::string>();
    } catch (const nlohmann::json::exception& e) {
        throw refuse("unreadable manifest: " + std::string(e.what()));
    }
    // The name is for people; size and checksum tie the manifest to the bytes, so a file renamed
    // with its manifest is still accepted.
    const std::uintmax_t bytes = fs::file_size(file, error);
    if (error) throw refuse("cannot read it: " + error.message());
    if (bytes != expectedBytes) {
        throw refuse(std::to_string(bytes) + " bytes, the manifest says " +
                     std::to_string(expectedBytes));
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
    if (Fnv1a64::hex(hash.value()) != expectedHash) {
        throw refuse("checksum " + Fnv1a64::hex(hash.value()) + ", the manifest says " +
                     expectedHash);
    }
    return content;
}

}  // namespace pine::bake::detail
