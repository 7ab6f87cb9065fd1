#include "pine/support/progress.h"

#include "pine/support/tool_main.h"

#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <string>

namespace pine::tool {

namespace {
std::atomic<bool> gLineOpen{false};  // a terminal line without its newline yet
}  // namespace

Progress::Progress(std::string what)
    : mWhat(std::move(what)), mTerminal(::isatty(::fileno(stderr)) != 0)
{
}

void Progress::update(double fraction)
{
    fraction = fraction >= 0.0 ? std::min(fraction, 1.0) : 0.0;  // NaN too
    char text[8];
    std::snprintf(text, sizeof text, "%3d%%", int(std::lround(100.0 * fraction)));
    show(fraction, text);
}

void Progress::count(std::size_t done, std::size_t total, const std::string& unit)
{
    show(total ? double(done) / double(total) : 1.0,
         std::to_string(done) + "/" + std::to_string(total) + " " + unit);
}

void Progress::show(double fraction, const std::string& text)
{
    if (!(fraction >= 0.0)) fraction = 0.0;  // NaN too
    fraction = std::min(fraction, 1.0);
    const std::lock_guard<std::mutex> lock(mMutex);
    if (mFinished || fraction <= mShown || quiet()) return;
    mShown = fraction;
    if (mTerminal) {
        constexpr int kBar = 24;
        const int filled = int(std::floor(kBar * fraction));
        const std::string bar = std::string(std::size_t(filled), '#') +
                                std::string(std::size_t(kBar - filled), '.');
        std::fprintf(stderr, "\r%s [%s] %s", mWhat.c_str(), bar.c_str(), text.c_str());
        gLineOpen = true;
    } else {
        const int tenth = int(std::floor(10.0 * fraction));
        if (tenth <= mTenth) return;
        mTenth = tenth;
        std::fprintf(stderr, "%s %s\n", mWhat.c_str(), text.c_str());
    }
    std::fflush(stderr);
}

void Progress::finish()
{
    const std::lock_guard<std::mutex> lock(mMutex);
    if (mFinished) return;
    mFinished = true;
    if (mTerminal && mShown >= 0.0) endOpenLine();
}

void Progress::endOpenLine()
{
    if (gLineOpen.exchange(false)) {
        std::fputc('\n', stderr);
        std::fflush(stderr);
    }
}

}  // namespace pine::tool
