#include "pine/vdbtrace/light_columns.h"

#include "pine/analytic/direction.h"

#include <array>
#include <atomic>
#include <limits>
#include <numeric>

namespace pine::vdbtrace {

std::unique_ptr<LightColumns> LightColumns::build(std::size_t count,
                                                  const std::function<Primitive(std::size_t)>& at,
                                                  const std::vector<std::uint32_t>& order,
                                                  const Vec3& towardsLight, std::size_t maxBytes)
{
    constexpr std::uint32_t kRankMask = (1u << 30) - 1;  // an Entry's rank's bits
    if (count == 0 || order.size() != count || count > kRankMask) return nullptr;
    // Each primitive takes one entry at least: too many are refused before anything is made
    // (a landscape's 6.8 million would hold 250 MB while finding out).
    if (count * (sizeof(Entry) + sizeof(Shadow) + sizeof(std::uint32_t)) > maxBytes) {
        return nullptr;
    }
    std::unique_ptr<LightColumns> out(new LightColumns);
    LightColumns& c = *out;
    static std::atomic<std::uint64_t> generations{0};
    c.mGeneration = ++generations;
    c.mTowardsLight = towardsLight;
    c.mAcross[0] = analytic::anyPerpendicular(towardsLight);
    c.mAcross[1] = glm::cross(towardsLight, c.mAcross[0]);
    c.mShadows.resize(count);
    c.mIndexOf.resize(count);
    std::vector<float> depths(count);
    std::vector<double> radii(count);
    constexpr double kInf = std::numeric_limits<double>::infinity();
    double lo[2] = {kInf, kInf}, hi[2] = {-kInf, -kInf};
    for (std::size_t rank = 0; rank < count; ++rank) {
        const std::uint32_t index = order[rank];
        const Primitive p = at(index);
        Shadow& s = c.mShadows[rank];
        for (int k = 0; k < 2; ++k) {
            const double a = c.across(p.base, k), b = c.across(p.end, k);
            s.a[k] = float(a);
            s.b[k] = float(b);
            lo[k] = std::min(lo[k], std::min(a, b) - p.radius_cm);
            hi[k] = std::max(hi[k], std::max(a, b) + p.radius_cm);
        }
        // The floats' rounding of a and b (6e-8 of each) in the radius, so that a query's
        // distance from them errs on the near side.
        s.radius = roundedUp(p.radius_cm + 1e-6 * (std::abs(s.a[0]) + std::abs(s.a[1]) +
                                                   std::abs(s.b[0]) + std::abs(s.b[1]) + 1.0));
        depths[rank] = roundedDown(std::min(c.depth(p.base), c.depth(p.end)) - p.radius_cm);
        radii[rank] = p.radius_cm;
        c.mIndexOf[rank] = index;
    }
    // Cells about six times a typical primitive's radius (a bough's cones' reach): a shadow
    // tube as wide as a pixel's footprint reads one to four cells. Measured on the dense
    // forest (1280 firs), against the bough law's bands as a yardstick, the columns' build
    // and queries cost 0.97, 0.78, 0.83 and 0.88 of them at 3, 6, 9 and 12 radii, and take
    // 96, 57, 48 and 44 MB: small cells cost entries (a primitive in many), large ones
    // candidates that miss.
    std::nth_element(radii.begin(), radii.begin() + long(count / 2), radii.end());
    c.mCell_cm = std::max(6.0 * radii[count / 2], 1e-3);
    const auto cellsAlong = [&](int k) {
        return std::max(1.0, std::ceil((hi[k] - lo[k]) / c.mCell_cm));
    };
    // Never more cells than primitives: a wide scene of few primitives gets wider cells.
    while (cellsAlong(0) * cellsAlong(1) > double(std::max<std::size_t>(count, 1024))) {
        c.mCell_cm *= 2.0;
    }
    for (int k = 0; k < 2; ++k) {
        c.mOrigin[k] = lo[k];
        c.mCells[k] = int(cellsAlong(k));
    }

    // Each primitive goes into every cell its projected axis, grown by its radius (which holds
    // the floats' rounding), may cross: its box across the light. Each entry says whether its
    // cell is the primitive's first along each direction, so that a query reads it once.
    const auto cellRange = [&](const Shadow& s, int k, int& from, int& to) {
        const double a = std::min(s.a[k], s.b[k]) - double(s.radius);
        const double b = std::max(s.a[k], s.b[k]) + double(s.radius);
        from = std::min(c.mCells[k] - 1,
                        std::max(0, int(std::floor((a - c.mOrigin[k]) / c.mCell_cm))));
        to = std::max(from,
                      std::min(c.mCells[k] - 1, int(std::floor((b - c.mOrigin[k]) / c.mCell_cm))));
    };
    const std::size_t cells = std::size_t(c.mCells[0]) * std::size_t(c.mCells[1]);
    std::vector<std::uint32_t> perCell(cells + 1, 0);
    std::size_t entries = 0;
    for (int pass = 0; pass < 2; ++pass) {
        for (std::size_t rank = 0; rank < count; ++rank) {
            int from[2], to[2];
            for (int k = 0; k < 2; ++k) cellRange(c.mShadows[rank], k, from[k], to[k]);
            for (int j = from[1]; j <= to[1]; ++j) {
                for (int i = from[0]; i <= to[0]; ++i) {
                    const std::size_t cell = std::size_t(j) * std::size_t(c.mCells[0]) + i;
                    if (pass == 0) {
                        ++perCell[cell + 1];
                        ++entries;
                    } else {
                        c.mEntries[c.mFirst[cell] + perCell[cell]++] =
                            Entry{depths[rank], std::uint32_t(rank) & kRankMask, i == from[0],
                                  j == from[1]};
                    }
                }
            }
        }
        if (pass == 0) {
            const std::size_t bytes = entries * sizeof(Entry) + count * sizeof(Shadow) +
                                      count * sizeof(std::uint32_t) +
                                      (cells + 1) * sizeof(std::uint32_t);
            if (bytes > maxBytes || entries >= std::size_t(UINT32_MAX)) return nullptr;
            std::partial_sum(perCell.begin(), perCell.end(), perCell.begin());
            c.mFirst.assign(perCell.begin(), perCell.end());
            c.mEntries.resize(entries);
            std::fill(perCell.begin(), perCell.end(), 0u);
        }
    }
    // Each cell nearest the light first, so that a query stops at the point's depth.
    for (std::size_t cell = 0; cell < cells; ++cell) {
        std::sort(c.mEntries.begin() + c.mFirst[cell], c.mEntries.begin() + c.mFirst[cell + 1],
                  [](const Entry& a, const Entry& b) {
                      return a.depth != b.depth ? a.depth < b.depth : a.rank < b.rank;
                  });
    }
    return out;
}

void LightColumns::gather(const double p[2], double reach_cm, double deepest,
                          Neighbourhood& out) const
{
    out.candidates.clear();
    // Held for later queries only where it is all finite: an infinite point or reach (whose
    // scan reads nothing) would hold every point.
    const bool finite = std::isfinite(p[0]) && std::isfinite(p[1]) && std::isfinite(reach_cm) &&
                        std::isfinite(deepest);
    out.generation = finite ? mGeneration : 0;
    out.at[0] = p[0];
    out.at[1] = p[1];
    out.reach_cm = reach_cm;
    out.deepest = deepest;
    int from[2], to[2];
    for (int k = 0; k < 2; ++k) {
        const double lo = (p[k] - reach_cm - mOrigin[k]) / mCell_cm;
        const double hi = (p[k] + reach_cm - mOrigin[k]) / mCell_cm;
        if (!(hi >= 0.0) || !(lo < double(mCells[k]))) return;
        // Clamped before they become ints: a reach of 2^31 cells or more reads them all.
        from[k] = int(std::max(0.0, std::floor(lo)));
        to[k] = int(std::min(double(mCells[k] - 1), std::floor(hi)));
    }
    for (int j = from[1]; j <= to[1]; ++j) {
        for (int i = from[0]; i <= to[0]; ++i) {
            const std::size_t cell = std::size_t(j) * std::size_t(mCells[0]) + std::size_t(i);
            for (std::uint32_t e = mFirst[cell]; e < mFirst[cell + 1]; ++e) {
                const Entry& entry = mEntries[e];
                if (double(entry.depth) > deepest) break;
                // Once: from the first of the query's cells that the primitive is binned in,
                // along each direction its own first or the query's first, whichever is
                // later (tested first: a primitive lies in several cells).
                if (!(entry.firstAlong0 || i == from[0]) || !(entry.firstAlong1 || j == from[1])) {
                    continue;
                }
                const Shadow& s = mShadows[entry.rank];
                const Candidate c{
                    {s.a[0], s.a[1]}, {s.b[0], s.b[1]}, s.radius, entry.depth, entry.rank};
                if (within(c, p, reach_cm)) out.candidates.push_back(c);
            }
        }
    }
    std::sort(out.candidates.begin(), out.candidates.end(),
              [](const Candidate& a, const Candidate& b) { return a.rank < b.rank; });
}

const LightColumns::Neighbourhood& LightColumns::around(const double p[2], double reach_cm,
                                                        double deepest) const
{
    // Deeper than the query by this: 39% of the dense forest's shadow cones start at the same
    // point as the one before (a bough within the levels' blend, render.level_blend, is shaded
    // by both levels from its chord's middle), most of them no deeper than this past it.
    // Neighbours a little wider would hold a few more, for more than they save (a gather over
    // 1 cm more reads about twice the cells).
    constexpr double kDeeper_cm = 1.0;
    // One per light (a few), so that a scene's lights do not evict each other's.
    thread_local std::array<Neighbourhood, 4> recent;
    Neighbourhood& n = recent[mGeneration % recent.size()];
    // Every primitive within reach_cm of p lies within reach_cm + |p - at| of `at` (the
    // triangle inequality, with a hair for its rounding): n holds all that p's query yields.
    // Gathered a hair wider than asked, so that a cone from the same point reached by another
    // sum (a few ulps away) is held too.
    const double hair = 1e-3 * slack(p);
    const double off = std::hypot(p[0] - n.at[0], p[1] - n.at[1]);
    if (n.generation == mGeneration && deepest <= n.deepest &&
        off + reach_cm + hair <= n.reach_cm) {
        return n;
    }
    gather(p, reach_cm + 2.0 * hair, deepest + kDeeper_cm, n);
    return n;
}

std::size_t LightColumns::bytes() const
{
    return sizeof(*this) + mFirst.capacity() * sizeof(std::uint32_t) +
           mEntries.capacity() * sizeof(Entry) + mShadows.capacity() * sizeof(Shadow) +
           mIndexOf.capacity() * sizeof(std::uint32_t);
}

}  // namespace pine::vdbtrace
