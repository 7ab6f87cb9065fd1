// Long work's progress on stderr, as a person or a log expects it: a bar rewritten in place on
// a terminal; plain lines otherwise, one per tenth of the work, so that a log holds neither
// fifty updates on one line nor thousands of lines.
#pragma once

#include <cstddef>
#include <mutex>
#include <string>

namespace pine::tool {

class Progress {
public:
    /// `what` begins each line ("vdbtrace: rendering").
    explicit Progress(std::string what);
    ~Progress() { finish(); }
    Progress(const Progress&) = delete;
    Progress& operator=(const Progress&) = delete;

    /// The fraction done, in [0, 1]. Thread-safe; a fraction that arrives late (another
    /// thread's, smaller) never moves the line back.
    void update(double fraction);
    /// `done` of `total` UNITs ("12/80 trees"). Thread-safe, as update.
    void count(std::size_t done, std::size_t total, const std::string& unit);
    /// Ends the line on a terminal; nothing is shown after it.
    void finish();

    /// Ends a terminal line left open by any Progress, so that an error gets its own line.
    static void endOpenLine();

private:
    void show(double fraction, const std::string& text);

    std::string mWhat;
    std::mutex mMutex;
    double mShown = -1.0;
    int mTenth = -1;
    bool mFinished = false;
    const bool mTerminal;
};

}  // namespace pine::tool
