// The "species" section: an L-system and the needle parameters of its boughs. Keys, units,
// defaults and valid ranges: docs/scene-format.md, "species".
#include "scene_sections.h"

#include "pine/analytic/cone_shader.h"

#include "pine/scenes/lsystem.h"

#include <cctype>
#include <cmath>
#include <numbers>

namespace pine::scenes::detail {
namespace {

constexpr double kRadPerDeg = std::numbers::pi / 180.0;

// Spaces are allowed in a file for readability; the turtle never sees them.
std::string readProgram(const Json& value, const Where& where)
{
    std::string program;
    int depth = 0;
    for (char c : readString(value, where)) {
        if (std::isspace(static_cast<unsigned char>(c))) continue;
        if (!isLSystemSymbol(c)) {
            where.fail("unknown symbol '" + printable(std::string(1, c), /*asciiOnly=*/true) +
                       "' (the turtle reads F [ ] + - & ^ / \\ !; other letters are "
                       "non-terminals)");
        }
        if (c == '[') ++depth;
        if (c == ']' && --depth < 0) where.fail("']' without its '['");
        program += c;
    }
    // Each string balanced on its own keeps every rewriting of them balanced.
    if (depth != 0) where.fail("'[' without its ']'");
    return program;
}

void readLSystem(ObjectReader& r, Species& s)
{
    s.axiom = readProgram(r.required("axiom"), r.where().key("axiom"));
    if (const Json* rules = r.optional("rules")) {
        ObjectReader rr(*rules, r.where().key("rules"));
        for (const auto& [symbol, successor] : rules->items()) {
            if (symbol == "comment") continue;
            const Where where = rr.where().key(symbol);
            if (symbol.size() != 1 || !std::isalpha(static_cast<unsigned char>(symbol[0]))) {
                where.fail("a rule rewrites one letter");
            }
            s.rules[symbol[0]] = readProgram(*rr.optional(symbol), where);
        }
        rr.finish();
    }
    if (const Json* iterations = r.optional("iterations")) {
        s.iterations =
            static_cast<int>(readInteger(*iterations, r.where().key("iterations"), 0, 30));
    }
    if (expandedLength(s.axiom, s.rules, s.iterations) > kMaxLSystemLength) {
        r.where().key("iterations").fail("the L-system grows past " +
                                         std::to_string(kMaxLSystemLength) + " symbols");
    }
    const auto maxSegments = std::size_t(readInteger(
        r.optional("max_segments") ? *r.optional("max_segments") : Json(kDefaultMaxSegments),
        r.where().key("max_segments"), 1, (long long)kMaxLSystemLength));
    if (const std::size_t segments =
            expandedCount(s.axiom, s.rules, s.iterations, "F", maxSegments);
        segments > maxSegments) {
        r.where().key("iterations").fail(
            "the L-system grows more than " + std::to_string(maxSegments) +
            " segments (F), lsystem.max_segments; raise it knowingly: render time grows "
            "faster than the segments where boughs crowd");
    }
    s.branchAngle_rad =
        kRadPerDeg * r.number("branch_angle_deg", Range::closed(0, 180), s.branchAngle_rad /
                                                                             kRadPerDeg);
    s.divergence_rad = kRadPerDeg * r.number("divergence_deg", Range::closed(-360, 360),
                                             s.divergence_rad / kRadPerDeg);
    s.segment_cm = r.number("segment", Range::above(0), s.segment_cm);
    s.trunkRadius_cm = r.number("trunk_radius", Range::above(0), s.trunkRadius_cm);
    s.lengthDecay = r.number("length_decay", Range::leftOpen(0, 10), s.lengthDecay);
    s.radiusDecay = r.number("radius_decay", Range::leftOpen(0, 10), s.radiusDecay);
    s.branchRadiusRatio =
        r.number("branch_radius_ratio", Range::leftOpen(0, 10), s.branchRadiusRatio);
    s.jitter_rad = kRadPerDeg * r.number("jitter_deg", Range::closed(0, 90),
                                         s.jitter_rad / kRadPerDeg);
    r.finish();
}

// One end of a bough (section 3.1); keys absent take `fallback`'s values.
// Section 3.3: A = 2 N r / (pi R) is the fraction of the cone covered by needles; above 1 the
// needles of one cone overlap and no shader level describes them. N as every method draws it,
// in whole needles (bake::boughGeometry).
double layerCoverage(const NeedleParameters& p)
{
    return analytic::layerCoverage(
        analytic::ConeGeometry{p.aperture_rad, p.length_cm, p.radius_cm, wholeNeedles(p.perCone)});
}

NeedleParameters readNeedles(const Json& value, const Where& where,
                             const NeedleParameters& fallback)
{
    ObjectReader r(value, where);
    NeedleParameters p;
    p.aperture_rad = kRadPerDeg * r.number("aperture_deg", Range::leftOpen(0, 90),
                                           fallback.aperture_rad / kRadPerDeg);
    p.length_cm = r.number("length", Range::above(0), fallback.length_cm);
    p.radius_cm = r.number("radius", Range::above(0), fallback.radius_cm);
    p.perCone = r.number("per_cone", Range::atLeast(1), fallback.perCone);
    p.coneSpacing_cm = r.number("cone_spacing", Range::above(0), fallback.coneSpacing_cm);
    r.finish();
    if (p.radius_cm >= p.length_cm) {
        where.key("radius").fail("must be less than the needle length (" +
                                 formatNumber(p.length_cm) + " cm)");
    }
    // A line across a bough crosses about 2 l / dh layers; the multiscale levels walk them one
    // by one (cone_crossings.h), so a spacing far below any fir's is refused before any work.
    constexpr double kMaxLayersAcross = 20000.0;
    if (2.0 * p.length_cm / p.coneSpacing_cm > kMaxLayersAcross) {
        where.key("cone_spacing")
            .fail("must be at least 2 x the needle length / " +
                  formatNumber(kMaxLayersAcross) + " (" +
                  formatNumber(2.0 * p.length_cm / kMaxLayersAcross) +
                  " cm): a line through a bough would cross more layers than that");
    }
    if (const double A = layerCoverage(p); A > 1.0) {
        where.fail("needles overlap on their cone: A = 2 N r / (pi l sin(phi)) = " +
                   formatNumber(A) + " > 1");
    }
    return p;
}

// Between base and tip each parameter varies linearly, so A can exceed 1 where it does at
// neither end (r grows as l shrinks): checked at fine steps along the branch.
void checkNeedlesAlong(const NeedleParameters& base, const NeedleParameters& tip,
                       const Where& where)
{
    constexpr int kSteps = 64;
    for (int k = 1; k < kSteps; ++k) {
        const double t = double(k) / kSteps;
        if (const double A = layerCoverage(lerp(base, tip, t)); A > 1.0) {
            where.fail("needles overlap on their cone " + formatNumber(t) +
                       " of the way from base to tip: A = 2 N r / (pi l sin(phi)) = " +
                       formatNumber(A) + " > 1");
        }
    }
}

}  // namespace

Species readSpecies(const Json& value, const Where& where)
{
    ObjectReader r(value, where);
    Species s;
    {
        ObjectReader l(r.required("lsystem"), where.key("lsystem"));
        readLSystem(l, s);
    }
    if (const Json* needles = r.optional("needles")) {
        ObjectReader n(*needles, where.key("needles"));
        if (const Json* base = n.optional("base")) {
            s.needlesAtBase = readNeedles(*base, n.where().key("base"), s.needlesAtBase);
        }
        // The tip defaults to the base: parameters constant along the branch.
        s.needlesAtTip = s.needlesAtBase;
        if (const Json* tip = n.optional("tip")) {
            s.needlesAtTip = readNeedles(*tip, n.where().key("tip"), s.needlesAtBase);
        }
        n.finish();
        checkNeedlesAlong(s.needlesAtBase, s.needlesAtTip, n.where());
    } else {
        s.needlesAtTip = s.needlesAtBase;
    }
    s.barkAlbedo = r.number("bark_albedo", Range::closed(0, 1), s.barkAlbedo);
    s.needleAlbedo = r.number("needle_albedo", Range::closed(0, 1), s.needleAlbedo);
    s.needleSpecular = r.number("needle_specular", Range::atLeast(0), s.needleSpecular);
    // The cone shader's specular peak scales as sqrt(2 pi / (n - 1)): n must exceed 1.
    s.specularExponent = r.number("specular_exponent", Range::above(1), s.specularExponent);
    r.finish();
    return s;
}

}  // namespace pine::scenes::detail
