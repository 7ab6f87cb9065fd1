// Parsing with locations. nlohmann's DOM keeps no source positions and reports a number overflow
// without its key; a SAX parser that follows the key path as it goes fixes both (the same idea
// as KeyTrackingParser in analytic/tool/eval_case.cpp, extended from the last key to the path).
#include "json_document.h"

#include "pine/scenes/scene.h"
#include "pine/support/input_error.h"

#include <algorithm>
#include <set>
#include <string_view>
#include <vector>

namespace pine::scenes::detail {
namespace {

class PathTrackingParser : public nlohmann::detail::json_sax_dom_parser<Json> {
public:
    explicit PathTrackingParser(Json& result) : json_sax_dom_parser(result, false) {}

    // Scalars: record the value, then step the enclosing array on.
    bool null() { return json_sax_dom_parser::null() && advance(); }
    bool boolean(bool v) { return json_sax_dom_parser::boolean(v) && advance(); }
    bool number_integer(number_integer_t v)
    {
        return json_sax_dom_parser::number_integer(v) && advance();
    }
    bool number_unsigned(number_unsigned_t v)
    {
        return json_sax_dom_parser::number_unsigned(v) && advance();
    }
    bool number_float(number_float_t v, const string_t& s)
    {
        return json_sax_dom_parser::number_float(v, s) && advance();
    }
    bool string(string_t& v) { return json_sax_dom_parser::string(v) && advance(); }
    bool binary(binary_t& v) { return json_sax_dom_parser::binary(v) && advance(); }

    bool start_object(std::size_t n)
    {
        mFrames.push_back(Frame{false, 0, {}, {}});
        return json_sax_dom_parser::start_object(n);
    }
    bool key(string_t& k)
    {
        Frame& f = mFrames.back();
        f.key = k;
        if (!f.keys.insert(k).second) {
            // nlohmann keeps the last of two equal keys: one of them is a mistake.
            mProblem = "duplicate key";
            return false;
        }
        return json_sax_dom_parser::key(k);
    }
    bool end_object()
    {
        mFrames.pop_back();
        return json_sax_dom_parser::end_object() && advance();
    }
    bool start_array(std::size_t n)
    {
        mFrames.push_back(Frame{true, 0, {}, {}});
        return json_sax_dom_parser::start_array(n);
    }
    bool end_array()
    {
        mFrames.pop_back();
        return json_sax_dom_parser::end_array() && advance();
    }

    bool parse_error(std::size_t position, const std::string& token,
                     const nlohmann::detail::exception& e)
    {
        mPosition = position;
        if (e.id == 406) {  // out_of_range.406: a number JSON can write but no double holds
            mProblem = "must be finite (number out of range: " + token + ")";
            mTokenLength = token.size();
        } else {
            mProblem = e.what();
            mFramesValid = false;  // the path is of no use for a syntax error
        }
        return json_sax_dom_parser::parse_error(position, token, e);
    }

    /// Path of the value being read when parsing stopped: "trees[3].height".
    std::string path() const
    {
        std::string p;
        for (const Frame& f : mFrames) {
            if (f.array) {
                // Appended piecewise: GCC 12 warns falsely (-Wrestrict) on "[" + to_string().
                p += '[';
                p += std::to_string(f.index);
                p += ']';
            } else {
                if (!p.empty()) p += '.';
                p += f.key;
            }
        }
        return p;
    }
    const std::string& problem() const { return mProblem; }
    bool hasPath() const { return mFramesValid; }
    std::size_t position() const { return mPosition; }
    std::size_t tokenLength() const { return mTokenLength; }

private:
    struct Frame {
        bool array;
        std::size_t index;  // arrays: the element being read
        std::string key;    // objects: the key being read
        std::set<std::string> keys;
    };

    bool advance()
    {
        if (!mFrames.empty() && mFrames.back().array) ++mFrames.back().index;
        return true;
    }

    std::vector<Frame> mFrames;
    std::string mProblem;
    std::size_t mPosition = 0, mTokenLength = 0;
    bool mFramesValid = true;
};

// nlohmann's message: "[json.exception.parse_error.101] parse error at line 3, column 5: syntax
// error while parsing ..."; keep what follows the position, since we give our own.
std::string withoutPrefix(const std::string& what)
{
    const std::string_view marker = ": ";
    const auto column = what.find("column ");
    if (column != std::string::npos) {
        const auto colon = what.find(marker, column);
        if (colon != std::string::npos) return what.substr(colon + marker.size());
    }
    return withoutLibraryTags(what);
}

std::string located(const std::string& file, const std::string& text, std::size_t index)
{
    const TextPosition p = positionOf(text, index);
    return file + ":" + std::to_string(p.line) + ":" + std::to_string(p.column);
}

}  // namespace

TextPosition positionOf(const std::string& text, std::size_t index)
{
    TextPosition p;
    const std::size_t end = std::min(index, text.size());
    for (std::size_t i = 0; i < end; ++i) {
        if (text[i] == '\n') {
            ++p.line;
            p.column = 1;
        } else {
            ++p.column;
        }
    }
    return p;
}

Json parseJsonDocument(const std::string& text, const std::string& file)
{
    Json result;
    PathTrackingParser parser(result);
    bool ok = false;
    try {
        ok = Json::sax_parse(text, &parser);
    } catch (const nlohmann::json::exception& e) {
        // Only the size checks of start_object/start_array throw here.
        throw SceneError(file + ": " + std::string(e.what()));
    }
    if (ok) return result;

    if (parser.position() == 0) {
        // Stopped by a callback (a duplicate key): no byte position, the path says where.
        throw SceneError(file + ": " + parser.path() + ": " + parser.problem());
    }
    // nlohmann's position counts the characters read, so the last one read is at position - 1.
    const std::size_t last = parser.position() - 1;
    if (parser.hasPath()) {
        // A number overflow: point at the number's first character.
        const std::size_t length = parser.tokenLength();
        const std::size_t start = last + 1 >= length ? last + 1 - length : 0;
        throw SceneError(located(file, text, start) + ": " + parser.path() + ": " +
                         parser.problem());
    }
    throw SceneError(located(file, text, last) + ": " + withoutPrefix(parser.problem()));
}

}  // namespace pine::scenes::detail
