#include "json_reader.h"

#include "pine/analytic/direction.h"

#include <glm/geometric.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

namespace pine::scenes::detail {
namespace {

// Levenshtein distance, to name the likely typo when a required key is missing.
std::size_t editDistance(const std::string& a, const std::string& b)
{
    std::vector<std::size_t> row(b.size() + 1);
    for (std::size_t j = 0; j <= b.size(); ++j) row[j] = j;
    for (std::size_t i = 1; i <= a.size(); ++i) {
        std::size_t diagonal = row[0];
        row[0] = i;
        for (std::size_t j = 1; j <= b.size(); ++j) {
            const std::size_t up = row[j];
            row[j] = std::min({row[j] + 1, row[j - 1] + 1,
                               diagonal + (a[i - 1] == b[j - 1] ? 0 : 1)});
            diagonal = up;
        }
    }
    return row[b.size()];
}

const char* typeName(const Json& v)
{
    return v.type_name();
}

}  // namespace

void Where::fail(const std::string& problem) const
{
    throw SceneError(*file + ": " + (path.empty() ? std::string("(top level)") : path) + ": " +
                     problem);
}

bool Range::contains(double x) const
{
    const bool aboveLo = loOpen ? x > lo : x >= lo;
    const bool belowHi = hiOpen ? x < hi : x <= hi;
    return aboveLo && belowHi;
}

std::string Range::describe() const
{
    const bool noLo = std::isinf(lo), noHi = std::isinf(hi);
    if (noLo && noHi) return "must be finite";
    if (noHi) return std::string("must be ") + (loOpen ? "> " : ">= ") + formatNumber(lo);
    if (noLo) return std::string("must be ") + (hiOpen ? "< " : "<= ") + formatNumber(hi);
    return std::string("must be in ") + (loOpen ? "(" : "[") + formatNumber(lo) + ", " +
           formatNumber(hi) + (hiOpen ? ")" : "]");
}

std::string formatNumber(double x)
{
    char buffer[32];
    std::snprintf(buffer, sizeof buffer, "%.10g", x);
    return buffer;
}

double readNumber(const Json& v, const Where& where, const Range& range)
{
    if (!v.is_number()) where.fail(std::string("must be a number, not ") + typeName(v));
    const double x = v.get<double>();
    if (!std::isfinite(x)) where.fail("must be finite");
    if (!range.contains(x)) where.fail(range.describe() + " (is " + formatNumber(x) + ")");
    return x;
}

long long readInteger(const Json& v, const Where& where, long long lo, long long hi)
{
    const std::string range =
        "must be in [" + std::to_string(lo) + ", " + std::to_string(hi) + "]";
    if (v.is_number_float()) {
        // 640.0 is an integer written as a float: take it; 4.5 is not.
        const double x = v.get<double>();
        if (!std::isfinite(x)) where.fail("must be finite");
        if (x != std::floor(x)) where.fail("must be an integer (is " + formatNumber(x) + ")");
        if (x < static_cast<double>(lo) || x > static_cast<double>(hi)) {
            where.fail(range + " (is " + formatNumber(x) + ")");
        }
        return static_cast<long long>(x);
    }
    if (!v.is_number_integer()) where.fail(std::string("must be an integer, not ") + typeName(v));
    // Unsigned values above the signed range are out of any range we accept.
    const auto max = static_cast<unsigned long long>(hi);
    if (v.is_number_unsigned() && v.get<unsigned long long>() > max) {
        where.fail(range + " (is " + std::to_string(v.get<unsigned long long>()) + ")");
    }
    const long long x = v.get<long long>();
    if (x < lo || x > hi) where.fail(range + " (is " + std::to_string(x) + ")");
    return x;
}

std::string readString(const Json& v, const Where& where)
{
    if (!v.is_string()) where.fail(std::string("must be a string, not ") + typeName(v));
    return v.get<std::string>();
}

namespace {
template <int N>
glm::vec<N, double> readVector(const Json& v, const Where& where)
{
    const std::string shape = "must be an array of " + std::to_string(N) + " numbers";
    if (!v.is_array() || v.size() != N) where.fail(shape);
    glm::vec<N, double> out;
    for (int i = 0; i < N; ++i) {
        if (!v[i].is_number()) where.fail(shape);
        out[i] = v[i].get<double>();
        if (!std::isfinite(out[i])) where.index(i).fail("must be finite");
    }
    return out;
}
}  // namespace

Vec2 readVec2(const Json& v, const Where& where) { return readVector<2>(v, where); }
Vec3 readVec3(const Json& v, const Where& where) { return readVector<3>(v, where); }

Vec3 readDirection(const Json& v, const Where& where)
{
    // Only a true zero vector has no direction: 1e-200 and 1e200 are directions.
    const auto unit = analytic::normalizeGiven(readVec3(v, where));
    if (!unit) where.fail("must not be a zero vector");
    return *unit;
}

Vec3 readColour(const Json& v, const Where& where, const Range& range)
{
    const Vec3 c = readVec3(v, where);
    for (int i = 0; i < 3; ++i) {
        if (!range.contains(c[i])) {
            where.index(i).fail(range.describe() + " (is " + formatNumber(c[i]) + ")");
        }
    }
    return c;
}

ObjectReader::ObjectReader(const Json& object, Where where)
    : mJson(object), mWhere(std::move(where))
{
    if (!mJson.is_object()) mWhere.fail(std::string("must be an object, not ") + typeName(mJson));
    // "comment" is allowed anywhere, for notes in a format without comments.
    if (const auto it = mJson.find("comment"); it != mJson.end()) {
        readString(*it, mWhere.key("comment"));
        mRead.insert("comment");
    }
}

const Json& ObjectReader::required(const std::string& key)
{
    if (const Json* v = optional(key)) return *v;
    // Name a likely misspelling among the keys nobody has read.
    for (const auto& [other, value] : mJson.items()) {
        if (!mRead.count(other) && editDistance(other, key) <= 2) {
            mWhere.key(key).fail("missing (is \"" + other + "\" a typo?)");
        }
    }
    mWhere.key(key).fail("missing");
}

const Json* ObjectReader::optional(const std::string& key)
{
    const auto it = mJson.find(key);
    if (it == mJson.end()) return nullptr;
    mRead.insert(key);
    return &*it;
}

double ObjectReader::number(const std::string& key, const Range& range)
{
    return readNumber(required(key), mWhere.key(key), range);
}

double ObjectReader::number(const std::string& key, const Range& range, double fallback)
{
    const Json* v = optional(key);
    return v ? readNumber(*v, mWhere.key(key), range) : fallback;
}

std::string ObjectReader::string(const std::string& key)
{
    return readString(required(key), mWhere.key(key));
}

std::string ObjectReader::string(const std::string& key, const std::string& fallback)
{
    const Json* v = optional(key);
    return v ? readString(*v, mWhere.key(key)) : fallback;
}

Vec3 ObjectReader::vec3(const std::string& key)
{
    return readVec3(required(key), mWhere.key(key));
}

Vec3 ObjectReader::colour(const std::string& key, const Range& range, const Vec3& fallback)
{
    const Json* v = optional(key);
    return v ? readColour(*v, mWhere.key(key), range) : fallback;
}

void ObjectReader::finish() const
{
    for (const auto& [key, value] : mJson.items()) {
        if (!mRead.count(key)) mWhere.key(key).fail("unknown key (nothing reads it)");
    }
}

}  // namespace pine::scenes::detail
