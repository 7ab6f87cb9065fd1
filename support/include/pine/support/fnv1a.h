// FNV-1a, 64 bits: a checksum of bytes, not cryptographic; it detects damage and change, not
// forgery (baked files' manifests, a frame's record of the job that rendered it).
#pragma once

#include <cstdint>
#include <cstdio>
#include <istream>
#include <string>
#include <string_view>

namespace pine::io {

class Fnv1a64 {
public:
    void update(std::string_view bytes)
    {
        for (const char c : bytes) {
            mHash ^= std::uint64_t(static_cast<unsigned char>(c));
            mHash *= 1099511628211ull;
        }
    }
    /// Adds what `in` holds, read in chunks up to its end; returns the bytes read (check
    /// in.bad() after: a read error ends the stream too).
    std::uintmax_t update(std::istream& in)
    {
        std::string chunk(1 << 20, '\0');
        std::uintmax_t bytes = 0;
        while (in) {
            in.read(chunk.data(), std::streamsize(chunk.size()));
            const auto got = std::size_t(in.gcount());
            update(std::string_view(chunk.data(), got));
            bytes += got;
        }
        return bytes;
    }
    std::uint64_t value() const { return mHash; }
    /// 16 lower-case hex digits.
    static std::string hex(std::uint64_t hash)
    {
        char text[17];
        std::snprintf(text, sizeof text, "%016llx", static_cast<unsigned long long>(hash));
        return text;
    }

private:
    std::uint64_t mHash = 14695981039346656037ull;
};

}  // namespace pine::io
