// FNV-1a, 64 bits: a checksum of bytes, not cryptographic; it detects damage and change, not
// forgery (baked files' manifests, a frame's record of the job that rendered it).
#pragma once

#include <cstdint>
#include <cstdio>
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
