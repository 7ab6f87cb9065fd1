// The error a user's input causes (a malformed scene, a missing or damaged file, an output that
// cannot be written): tools print its one line and exit with status 2 (tool_main.h). Each
// component's own error (SceneError, BakeError, ImageError) is one.
#pragma once

#include <stdexcept>
#include <string>
#include <string_view>

namespace pine {

class InputError : public std::runtime_error {
public:
    using std::runtime_error::runtime_error;
};

/// `text` as an error line may show it: each control byte as \xNN (a NUL would end the
/// message there, a newline split its line, an escape sequence drive the terminal), and with
/// `asciiOnly` each byte of a multi-byte character too (one byte of it alone is not text). A
/// backslash stays as it is: the text "\\x0a" and a newline read the same.
inline std::string printable(std::string_view text, bool asciiOnly = false)
{
    static constexpr char kHex[] = "0123456789abcdef";
    std::string out;
    out.reserve(text.size());
    for (const char c : text) {
        const auto byte = static_cast<unsigned char>(c);
        if (byte >= 0x20 && byte != 0x7f && (byte < 0x80 || !asciiOnly)) {
            out += c;
            continue;
        }
        out += "\\x";
        out += kHex[byte >> 4];
        out += kHex[byte & 15];
    }
    return out;
}

/// A JSON library's message without its "[json.exception.parse_error.101] " tags (each of them,
/// where one message wraps another), for an error line that says what is wrong in its own words.
inline std::string withoutLibraryTags(std::string_view what)
{
    std::string out;
    for (;;) {
        const auto tag = what.find("[json.exception.");
        const auto end = tag == std::string_view::npos ? tag : what.find("] ", tag);
        if (end == std::string_view::npos) break;
        out += what.substr(0, tag);
        what.remove_prefix(end + 2);
    }
    out += what;
    return out;
}

}  // namespace pine
