// An animation's frames on disk: which frames a command names, and the file of each
// (NAME.####.exr beside --out NAME.exr, as compositors and players number an image sequence).
#pragma once

#include <filesystem>
#include <string>
#include <vector>

namespace pine::vdbtrace {

struct FrameRange {
    int first = 0, last = -1;  ///< inclusive
    int count() const { return last >= first ? last - first + 1 : 0; }
};

/// "A-B" (A <= B) or "A", frame numbers >= 0. Throws InputError naming the text.
FrameRange parseFrameRange(const std::string& text);

/// `out` ("dir/forest.exr") numbered: "dir/forest.0012.exr", four digits at least; `suffix`
/// replaces the extension (".png" for the frame's preview).
std::filesystem::path frameFile(const std::filesystem::path& out, int frame,
                                const std::string& suffix = ".exr");

/// Frame numbers of `range` for which `complete(frame)` is false, in order: what is left to
/// render of an interrupted job.
template <class Complete>
std::vector<int> framesLeft(const FrameRange& range, Complete&& complete)
{
    std::vector<int> left;
    for (int f = range.first; f <= range.last; ++f) {
        if (!complete(f)) left.push_back(f);
    }
    return left;
}

}  // namespace pine::vdbtrace
