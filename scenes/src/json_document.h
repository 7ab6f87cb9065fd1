// Scene text to a JSON document, with errors located by file, line and column (private).
#pragma once

#include <nlohmann/json.hpp>

#include <cstddef>
#include <string>

namespace pine::scenes::detail {

using Json = nlohmann::json;

/// Line and column (both 1-based) of the character at 0-based `index` in `text`.
struct TextPosition {
    std::size_t line = 1, column = 1;
};
TextPosition positionOf(const std::string& text, std::size_t index);

/// Parses `text`; throws SceneError "FILE:LINE:COL: problem" on malformed JSON, and
/// "FILE:LINE:COL: key.path: problem" on a number no double holds (1e999) or a duplicate key,
/// which nlohmann would otherwise turn into a bare parse error or silently drop.
Json parseJsonDocument(const std::string& text, const std::string& file);

}  // namespace pine::scenes::detail
