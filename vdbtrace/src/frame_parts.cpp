#include "pine/vdbtrace/frame_parts.h"

#include <algorithm>
#include <cstring>
#include <map>
#include <stdexcept>
#include <string>
#include <type_traits>

namespace pine::vdbtrace {
namespace {

constexpr std::uint32_t kMagic = 0x70696e65;  // "pine"

class Writer {
public:
    template <class T>
    void put(const T& value)
    {
        static_assert(std::is_trivially_copyable_v<T>);
        append(&value, sizeof(T));
    }
    template <class T>
    void putArray(const std::vector<T>& values)
    {
        put<std::uint64_t>(values.size());
        append(values.data(), values.size() * sizeof(T));
    }
    void putText(const std::string& text)
    {
        put<std::uint64_t>(text.size());
        append(text.data(), text.size());
    }
    Bytes bytes;

private:
    void append(const void* data, std::size_t size)
    {
        if (size == 0) return;
        const std::size_t at = bytes.size();
        bytes.resize(at + size);
        std::memcpy(bytes.data() + at, data, size);
    }
};

class Reader {
public:
    explicit Reader(const Bytes& bytes) : mBytes(bytes) {}
    template <class T>
    T get()
    {
        T value;
        std::memcpy(&value, take(sizeof(T)), sizeof(T));
        return value;
    }
    template <class T>
    std::vector<T> getArray()
    {
        const auto n = get<std::uint64_t>();
        if (n > mBytes.size() / sizeof(T)) throw std::runtime_error("packed render: bad length");
        std::vector<T> values(n);
        if (n > 0) std::memcpy(values.data(), take(n * sizeof(T)), n * sizeof(T));
        return values;
    }
    std::string getText()
    {
        const auto n = get<std::uint64_t>();
        if (n > mBytes.size()) throw std::runtime_error("packed render: bad length");
        const auto* p = reinterpret_cast<const char*>(take(n));
        return std::string(p, p + n);
    }
    bool done() const { return mAt == mBytes.size(); }

private:
    const unsigned char* take(std::size_t n)
    {
        if (n > mBytes.size() - mAt) throw std::runtime_error("packed render: truncated");
        const unsigned char* p = mBytes.data() + mAt;
        mAt += n;
        return p;
    }
    const Bytes& mBytes;
    std::size_t mAt = 0;
};

}  // namespace

Bytes packRender(const RenderResult& r)
{
    Writer w;
    w.put(kMagic);
    const Image& im = r.image;
    for (const int v :
         {im.width, im.height, im.originX, im.originY, im.frameWidth, im.frameHeight}) {
        w.put(v);
    }
    w.putArray(im.rgba);
    w.put<std::uint64_t>(im.aovs.size());
    for (const auto& [name, plane] : im.aovs) {
        w.putText(name);
        w.putArray(plane);
    }
    static_assert(std::is_trivially_copyable_v<RenderStats>);
    w.put(r.stats);
    w.put(r.seconds);
    w.put(r.prepSeconds);
    w.putArray(r.treeFoliage);
    return std::move(w.bytes);
}

RenderResult unpackRender(const Bytes& bytes)
{
    Reader in(bytes);
    if (in.get<std::uint32_t>() != kMagic) throw std::runtime_error("not a packed render");
    RenderResult r;
    Image& im = r.image;
    for (int* v :
         {&im.width, &im.height, &im.originX, &im.originY, &im.frameWidth, &im.frameHeight}) {
        *v = in.get<int>();
    }
    const std::size_t pixels = std::size_t(std::max(im.width, 0)) * std::max(im.height, 0);
    im.rgba = in.getArray<float>();
    if (im.rgba.size() != 4 * pixels) throw std::runtime_error("packed render: bad RGBA size");
    const auto aovs = in.get<std::uint64_t>();
    for (std::uint64_t k = 0; k < aovs; ++k) {
        std::string name = in.getText();
        std::vector<float> plane = in.getArray<float>();
        if (plane.size() != pixels) throw std::runtime_error("packed render: bad AOV size");
        im.aovs[std::move(name)] = std::move(plane);
    }
    r.stats = in.get<RenderStats>();
    r.seconds = in.get<double>();
    r.prepSeconds = in.get<double>();
    r.treeFoliage = in.getArray<TreeFoliageSum>();
    if (!in.done()) throw std::runtime_error("packed render: trailing bytes");
    return r;
}

std::vector<PixelWindow> rowBands(const PixelWindow& window, int count, int tileRows)
{
    tileRows = std::max(1, tileRows);
    const int rows = window.y1 - window.y0;
    const int tiles = (rows + tileRows - 1) / tileRows;
    count = std::clamp(count, 1, std::max(1, tiles));
    std::vector<PixelWindow> bands;
    for (int b = 0; b < count; ++b) {
        // Tile rows [b T / n, (b + 1) T / n): as even as whole tiles allow.
        const int y0 = window.y0 + tileRows * (b * tiles / count);
        const int y1 = std::min(window.y1, window.y0 + tileRows * ((b + 1) * tiles / count));
        if (y1 > y0) bands.push_back({window.x0, y0, window.x1, y1});
    }
    return bands;
}

RenderResult joinBands(std::vector<RenderResult> renders, const std::vector<PixelWindow>& bands,
                       const PixelWindow& window)
{
    if (renders.size() != bands.size() || renders.empty()) {
        throw std::invalid_argument("joinBands: one render per band");
    }
    RenderResult out;
    const int width = window.x1 - window.x0, height = window.y1 - window.y0;
    out.image = Image(width, height);
    const Image& first = renders.front().image;
    out.image.frameWidth = first.frameWidth;
    out.image.frameHeight = first.frameHeight;
    out.image.originX = window.x0;
    out.image.originY = window.y0;
    // The whole frame is no crop (render_driver.cpp writes a whole frame so).
    if (window.x0 == 0 && window.y0 == 0 && window.x1 == first.frameWidth &&
        window.y1 == first.frameHeight) {
        out.image.frameWidth = out.image.frameHeight = 0;
    }
    std::map<int, TreeFoliageSum> trees;
    for (std::size_t b = 0; b < bands.size(); ++b) {
        const Image& part = renders[b].image;
        const PixelWindow& band = bands[b];
        if (part.width != band.x1 - band.x0 || part.height != band.y1 - band.y0) {
            throw std::invalid_argument("joinBands: band " + std::to_string(b) + " is " +
                                        std::to_string(part.width) + " x " +
                                        std::to_string(part.height) + ", not its band's size");
        }
        const std::size_t row = std::size_t(width);
        for (int y = 0; y < part.height; ++y) {
            const std::size_t to = std::size_t(band.y0 - window.y0 + y) * row;
            const std::size_t from = std::size_t(y) * row;
            std::copy_n(&part.rgba[4 * from], 4 * row, &out.image.rgba[4 * to]);
            for (const auto& [name, plane] : part.aovs) {
                std::copy_n(&plane[from], row, &out.image.aov(name)[to]);
            }
        }
        out.stats += renders[b].stats;
        out.seconds = std::max(out.seconds, renders[b].seconds);
        out.prepSeconds = std::max(out.prepSeconds, renders[b].prepSeconds);
        for (const TreeFoliageSum& t : renders[b].treeFoliage) {
            TreeFoliageSum& sum = trees[t.tree];
            sum.tree = t.tree;
            sum.coverage_px += t.coverage_px;
            sum.luminance += t.luminance;
        }
    }
    for (const auto& [tree, sum] : trees) out.treeFoliage.push_back(sum);
    return out;
}

}  // namespace pine::vdbtrace
