// Whole numbers a command line gives joined by one character ("640x480", "0,0,8,8", "3-7"),
// read strictly: sscanf's %d read 4294967328 as 32, and a stray sign or space as a number.
#pragma once

#include <charconv>
#include <span>
#include <string_view>
#include <system_error>

namespace pine::vdbtrace {

/// The whole of `text` as values.size() integers joined by `separator`, each a decimal an int
/// holds, a sign allowed only as a leading '-' and only if `negative`: false otherwise.
inline bool parseIntegers(std::string_view text, char separator, std::span<int> values,
                          bool negative = true)
{
    const char* at = text.data();
    const char* const end = text.data() + text.size();
    for (std::size_t k = 0; k < values.size(); ++k) {
        if (k > 0 && (at == end || *at++ != separator)) return false;
        if (!negative && at != end && *at == '-') return false;
        const auto [next, error] = std::from_chars(at, end, values[k]);
        if (error != std::errc() || next == at) return false;
        at = next;
    }
    return at == end;
}

}  // namespace pine::vdbtrace
