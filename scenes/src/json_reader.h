// Reading a scene's JSON with every key accounted for (private to pine_scenes).
//
// pbrt-v4's ReportUnused() style: a key that nobody reads is an error naming its path, never
// silence, so a typo ("fov_dge") cannot fall back to a default unnoticed.
#pragma once

#include "json_document.h"

#include "pine/scenes/scene.h"

#include <limits>
#include <set>
#include <string>

namespace pine::scenes::detail {

/// Where a value sits: the file (for messages) and its key path ("trees[3].seed").
struct Where {
    const std::string* file;
    std::string path;

    Where key(const std::string& k) const { return {file, path.empty() ? k : path + "." + k}; }
    Where index(std::size_t i) const { return {file, path + "[" + std::to_string(i) + "]"}; }
    /// Throws SceneError "FILE: path: problem".
    [[noreturn]] void fail(const std::string& problem) const;
};

/// An interval of allowed values, open or closed at each end.
struct Range {
    double lo = -std::numeric_limits<double>::infinity();
    double hi = std::numeric_limits<double>::infinity();
    bool loOpen = false, hiOpen = false;

    static Range any() { return {}; }
    static Range atLeast(double lo) { return {lo, Range{}.hi, false, false}; }
    static Range above(double lo) { return {lo, Range{}.hi, true, false}; }
    static Range closed(double lo, double hi) { return {lo, hi, false, false}; }
    static Range leftOpen(double lo, double hi) { return {lo, hi, true, false}; }
    static Range open(double lo, double hi) { return {lo, hi, true, true}; }

    bool contains(double x) const;
    std::string describe() const;  ///< "must be in (0, 180)", "must be >= 0", ...
};

/// A number in the printed form used by messages (shortest that reads back, roughly).
std::string formatNumber(double x);

// Values, checked: each throws SceneError naming `where` when the value is unusable.
double readNumber(const Json& v, const Where& where, const Range& range);
long long readInteger(const Json& v, const Where& where, long long lo, long long hi);
std::string readString(const Json& v, const Where& where);
Vec2 readVec2(const Json& v, const Where& where);
Vec3 readVec3(const Json& v, const Where& where);
/// Three numbers, not all zero; returned unit length.
Vec3 readDirection(const Json& v, const Where& where);
/// Three numbers in `range` each (a colour, an albedo).
Vec3 readColour(const Json& v, const Where& where, const Range& range);

/// One JSON object, remembering which of its keys were read.
class ObjectReader {
public:
    ObjectReader(const Json& object, Where where);

    const Where& where() const { return mWhere; }
    bool has(const std::string& key) const { return mJson.contains(key); }

    /// The value under `key`, which must be present; marks it read.
    const Json& required(const std::string& key);
    /// The value under `key` or nullptr; marks it read.
    const Json* optional(const std::string& key);

    double number(const std::string& key, const Range& range);
    double number(const std::string& key, const Range& range, double fallback);
    std::string string(const std::string& key);
    std::string string(const std::string& key, const std::string& fallback);
    Vec3 vec3(const std::string& key);
    Vec3 colour(const std::string& key, const Range& range, const Vec3& fallback);

    /// Every key not read so far is an error ("camera.fov_dge: unknown key"); call it last.
    void finish() const;

private:
    const Json& mJson;
    Where mWhere;
    std::set<std::string> mRead;
};

}  // namespace pine::scenes::detail
