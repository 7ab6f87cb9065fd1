#include "pine/vdbtrace/frame_sequence.h"

#include "pine/scenes/camera.h"
#include "pine/support/input_error.h"

#include <charconv>
#include <cstdio>
#include <string>
#include <system_error>

namespace pine::vdbtrace {

FrameRange parseFrameRange(const std::string& text)
{
    // Digits, then optionally '-' and digits: nothing else (no sign, space or tail).
    const auto number = [](const char*& at, const char* end, int& value) {
        if (at == end || *at < '0' || *at > '9') return false;
        const auto [next, error] = std::from_chars(at, end, value);
        at = next;
        return error == std::errc();
    };
    FrameRange r;
    const char* at = text.data();
    const char* end = at + text.size();
    bool ok = number(at, end, r.first);
    r.last = r.first;
    if (ok && at != end) ok = *at++ == '-' && number(at, end, r.last);
    ok = ok && at == end && r.last >= r.first && r.last <= 9999999;
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
