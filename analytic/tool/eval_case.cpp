#include "eval_case.h"

#include "pine/analytic/bough_shader.h"
#include "pine/analytic/cone_shader.h"
#include "pine/analytic/needle_shader.h"
#include "pine/support/input_error.h"

#include <glm/geometric.hpp>

#include <cmath>
#include <istream>
#include <ostream>
#include <set>
#include <string>
#include <vector>

namespace pine::analytic::tool {
namespace {

using nlohmann::json;

// Reads keys from one case and remembers which were read, so that a key nobody reads is an
// error rather than silence (a typo like "apperture" would otherwise fall back to nothing).
class CaseReader {
public:
    explicit CaseReader(const json& j) : mJson(j)
    {
        if (!j.is_object()) throw CaseError("", "expected a JSON object");
    }

    bool has(const std::string& key) const { return mJson.contains(key); }

    std::string text(const std::string& key)
    {
        const json& v = need(key);
        if (!v.is_string()) throw CaseError(key, "must be a string");
        return v.get<std::string>();
    }

    /// A finite number, at least `min` (or above it when `strict`).
    double number(const std::string& key, double min, bool strict = false)
    {
        const json& v = need(key);
        if (!v.is_number()) throw CaseError(key, "must be a number");
        const double x = v.get<double>();
        if (!std::isfinite(x)) throw CaseError(key, "must be finite");
        if (strict ? !(x > min) : !(x >= min)) {
            throw CaseError(key, std::string("must be ") + (strict ? "> " : ">= ") +
                                     std::to_string(min));
        }
        return x;
    }

    /// A direction: three finite numbers, not all zero; returned normalized.
    Vec3 direction(const std::string& key)
    {
        const json& v = need(key);
        if (!v.is_array() || v.size() != 3) throw CaseError(key, "must be an array of 3 numbers");
        Vec3 d;
        for (int i = 0; i < 3; ++i) {
            if (!v[i].is_number()) throw CaseError(key, "must be an array of 3 numbers");
            d[i] = v[i].get<double>();
            if (!std::isfinite(d[i])) throw CaseError(key, "must be finite");
        }
        const auto unit = normalizeGiven(d);
        if (!unit) throw CaseError(key, "must not be a zero vector");
        return *unit;
    }

    void rejectUnread() const
    {
        for (const auto& [key, value] : mJson.items()) {
            if (!mRead.count(key)) throw CaseError(key, "unknown key for this level");
        }
    }

private:
    const json& need(const std::string& key)
    {
        if (!mJson.contains(key)) throw CaseError(key, "missing");
        mRead.insert(key);
        return mJson.at(key);
    }

    const json& mJson;
    std::set<std::string> mRead;
};

// JSON has no infinity: a layer rate for a ray along the branch is written as "inf".
json finiteOrInf(double x) { return std::isinf(x) ? json("inf") : json(x); }

ConeGeometry readCone(CaseReader& r)
{
    ConeGeometry cone;
    cone.needleRadius_cm = r.number("radius", 0.0);
    cone.needleLength_cm = r.number("length", 0.0);
    cone.aperture_rad = r.number("aperture", 0.0);
    if (cone.aperture_rad > 0.5 * kPi) throw CaseError("aperture", "must be <= pi/2");
    cone.needlesPerCone = r.number("needles_per_cone", 0.0);
    return cone;
}

json evaluateNeedle(CaseReader& r, const Vec3& axis, const Vec3& L, const Vec3& V)
{
    const double n = r.number("exponent", 0.0, true);
    json out = {{"diffuse", needleDiffuse(axis, L, V)},
                {"specular", needleSpecular(axis, L, V, n)}};
    if (r.has("radius") || r.has("length")) {
        const double area =
            needleProjectedArea(axis, V, r.number("radius", 0.0), r.number("length", 0.0));
        out["projected_area"] = area;
        if (r.has("footprint_area")) {
            out["alpha"] = needleOpacity(area, r.number("footprint_area", 0.0));
        }
    }
    return out;
}

json evaluateCone(CaseReader& r, const Vec3& axis, const Vec3& L, const Vec3& V)
{
    const ConeGeometry cone = readCone(r);
    const double n = r.number("exponent", 1.0, true);
    const double R = boughRadius(cone);
    const double footprint =
        r.has("footprint_area") ? r.number("footprint_area", 0.0) : kPi * R * R;
    const ConeSums sums = coneSums(cone, coneIntegrals(cone.aperture_rad, axis, L, V, n), n);
    const ConeShading s = shadeCone(sums, footprint);
    return {{"A", layerOpacity(cone)},           {"R", R},
            {"footprint_area", footprint},       {"area_front", sums.front.area},
            {"area_rear", sums.rear.area},       {"alpha_front", s.alphaFront},
            {"alpha_rear", s.alphaRear},         {"diffuse_front", s.diffuseFront},
            {"diffuse_rear", s.diffuseRear},     {"specular_front", s.specularFront},
            {"specular_rear", s.specularRear}};
}

json evaluateBough(CaseReader& r, const Vec3& axis, const Vec3& L, const Vec3& V)
{
    BoughGeometry bough;
    bough.cone = readCone(r);
    bough.coneSpacing_cm = r.number("cone_spacing", 0.0, true);
    const double n = r.number("exponent", 1.0, true);
    const ConeSums sums =
        coneSums(bough.cone, coneIntegrals(bough.cone.aperture_rad, axis, L, V, n), n);
    const double cylFront = meanReflectance(sums.front).diffuse;
    const double cylRear = meanReflectance(sums.rear).diffuse;
    const BoughView view = boughView(bough.cone.aperture_rad, axis, L, V);
    const BoughLinearLaw law = boughLinearLaw(bough, view);
    const BoughExact exact = boughExact(bough, view);
    return {{"A", layerOpacity(bough.cone)},
            {"R", boughRadius(bough.cone)},
            {"a", law.a},
            {"k_V", finiteOrInf(view.kV)},
            {"k_V_bar", finiteOrInf(view.kVbar)},
            {"k_L", finiteOrInf(view.kL)},
            {"k_L_bar", finiteOrInf(view.kLbar)},
            {"cos_lv", view.cosLV},
            {"alpha_front", law.alphaView.front},
            {"alpha_rear", law.alphaView.rear},
            {"alpha_linear_unclamped", finiteOrInf(law.alphaUnclamped)},
            {"alpha_front_exact", exact.alpha.front},
            {"alpha_rear_exact", exact.alpha.rear},
            {"alpha_exact", exact.total()},
            {"I_cyl_front", cylFront},
            {"I_cyl_rear", cylRear},
            {"I_front", cylFront * law.transfer.front},
            {"I_rear", cylRear * law.transfer.rear},
            {"I_front_exact", cylFront * exact.transfer.front},
            {"I_rear_exact", cylRear * exact.transfer.rear}};
}

// Builds the JSON of one line while remembering the last key read, so that a number JSON
// cannot hold (1e999 overflows a double) is reported against its key, not as a bare parse error,
// and refusing a key an object already has (the JSON would keep the last, silently).
class KeyTrackingParser : public nlohmann::detail::json_sax_dom_parser<json> {
public:
    explicit KeyTrackingParser(json& result) : json_sax_dom_parser(result, false) {}
    bool start_object(std::size_t n)
    {
        mKeys.emplace_back();
        return json_sax_dom_parser::start_object(n);
    }
    bool end_object()
    {
        mKeys.pop_back();
        return json_sax_dom_parser::end_object();
    }
    bool key(json::string_t& k)
    {
        mLastKey = k;
        if (!mKeys.back().insert(k).second) {
            mDuplicate = true;
            return false;
        }
        return json_sax_dom_parser::key(k);
    }
    bool parse_error(std::size_t position, const std::string& token,
                     const nlohmann::detail::exception& e)
    {
        mOverflow = e.id == 406;  // out_of_range.406: number overflow
        mMessage = e.what();
        return json_sax_dom_parser::parse_error(position, token, e);
    }
    bool overflow() const { return mOverflow; }
    bool duplicate() const { return mDuplicate; }
    const std::string& lastKey() const { return mLastKey; }
    const std::string& message() const { return mMessage; }

private:
    std::string mLastKey, mMessage;
    bool mOverflow = false, mDuplicate = false;
    std::vector<std::set<std::string>> mKeys;  ///< of each object open
};

json parseLine(const std::string& line)
{
    json result;
    KeyTrackingParser parser(result);
    if (!json::sax_parse(line, &parser)) {
        if (parser.overflow()) throw CaseError(parser.lastKey(), "must be finite");
        if (parser.duplicate()) throw CaseError(parser.lastKey(), "given twice");
        throw CaseError("", "not JSON (" + withoutLibraryTags(parser.message()) + ")");
    }
    return result;
}

}  // namespace

json evaluateCase(const json& input)
{
    CaseReader r(input);
    const std::string level = r.text("level");
    const Vec3 axis = r.direction("axis"), L = r.direction("L"), V = r.direction("V");
    json out;
    if (level == "needle") {
        out = evaluateNeedle(r, axis, L, V);
    } else if (level == "cone") {
        out = evaluateCone(r, axis, L, V);
    } else if (level == "bough") {
        out = evaluateBough(r, axis, L, V);
    } else {
        throw CaseError("level", "must be \"needle\", \"cone\" or \"bough\"");
    }
    r.rejectUnread();
    // Valid but enormous inputs (a radius of 1e308) can overflow a result: refused, never a
    // NaN or an infinity written as null (the layer rates' "inf" is a string, not checked).
    for (const auto& [key, value] : out.items()) {
        if (value.is_number() && !std::isfinite(value.get<double>())) {
            throw CaseError("", "output '" + key + "' overflows double precision: the inputs " +
                                    "are too large or too small for it");
        }
    }
    out["level"] = level;
    return out;
}

int runEval(std::istream& in, std::ostream& out, std::ostream& err)
{
    std::string line;
    for (long number = 1; std::getline(in, line); ++number) {
        if (line.find_first_not_of(" \t\r") == std::string::npos) continue;
        try {
            const json input = parseLine(line);
            out << evaluateCase(input).dump() << '\n';
        } catch (const json::exception& e) {
            err << "analytic eval: line " << number << ": not JSON ("
                << withoutLibraryTags(e.what()) << ")\n";
            return 2;
        } catch (const CaseError& e) {
            err << "analytic eval: line " << number << ": ";
            if (!e.key().empty()) err << "key '" << e.key() << "': ";
            err << e.what() << '\n';
            return 2;
        }
    }
    out.flush();
    return out.good() ? 0 : 1;
}

}  // namespace pine::analytic::tool
