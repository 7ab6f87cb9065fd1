#include "pine/vdbtrace/frame_sequence.h"

#include "pine/scenes/camera.h"
#include "pine/support/input_error.h"
#include "pine/vdbtrace/integer_list.h"

#include <cstdio>
#include <span>
#include <string>

namespace pine::vdbtrace {

FrameRange parseFrameRange(const std::string& text)
{
    // Digits, then optionally '-' and digits: nothing else (no sign, space or tail).
    const std::size_t numbers = text.find('-') == std::string::npos ? 1 : 2;
    int range[2];
    bool ok = parseIntegers(text, '-', std::span<int>(range, numbers), /*negative=*/false);
    const FrameRange r{range[0], range[numbers - 1]};
    ok = ok && r.last >= r.first && r.last <= 9999999;
    if (!ok) {
        throw InputError("--frames '" + text + "': expected A-B (0 <= A <= B) or one frame A");
    }
    if (r.count() > scenes::CameraPath::kMaxFrames) {
        throw InputError("--frames '" + text + "': " + std::to_string(r.count()) +
                         " frames, more than " + std::to_string(scenes::CameraPath::kMaxFrames));
    }
    return r;
}

std::filesystem::path frameFile(const std::filesystem::path& out, int frame,
                                const std::string& suffix)
{
    char number[16];
    std::snprintf(number, sizeof number, ".%04d", frame);
    std::filesystem::path p = out;
    p.replace_extension();
    return p.string() + number + suffix;
}

}  // namespace pine::vdbtrace
