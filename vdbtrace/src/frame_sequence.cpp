#include "pine/vdbtrace/frame_sequence.h"

#include "pine/support/input_error.h"

#include <cstdio>

namespace pine::vdbtrace {

FrameRange parseFrameRange(const std::string& text)
{
    FrameRange r;
    char tail = 0;
    const int read = std::sscanf(text.c_str(), "%d-%d%c", &r.first, &r.last, &tail);
    if (read == 1 && text.find('-') == std::string::npos) r.last = r.first;
    const bool ok = (read == 2 || (read == 1 && r.last == r.first)) && r.first >= 0 &&
                    r.last >= r.first && r.last <= 9999999;
    if (!ok) {
        throw InputError("--frames '" + text + "': expected A-B (0 <= A <= B) or one frame A");
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
