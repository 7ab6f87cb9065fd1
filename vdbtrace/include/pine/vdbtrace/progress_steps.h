// Parallel work's progress in steps: units finished on any thread, each step of the fraction
// done told once, by the thread that finished it, never back. The tiles of a render and the
// reference's light grids tell their progress so.
#pragma once

#include <atomic>
#include <cstddef>

namespace pine::vdbtrace {

class ProgressSteps {
public:
    /// `total` units, told in `steps` steps.
    ProgressSteps(std::size_t total, int steps) : mTotal(total), mSteps(steps) {}

    /// One more unit finished: true, with the fraction done, where it reaches a step no other
    /// unit has told.
    bool finished(double& fraction)
    {
        const std::size_t done = ++mDone;
        const int step = mTotal ? int(done * std::size_t(mSteps) / mTotal) : mSteps;
        int last = mTold.load();
        while (step > last && !mTold.compare_exchange_weak(last, step)) {
        }
        if (!(step > last)) return false;
        fraction = mTotal ? double(done) / double(mTotal) : 1.0;
        return true;
    }

private:
    std::size_t mTotal;
    int mSteps;
    std::atomic<std::size_t> mDone{0};
    std::atomic<int> mTold{0};
};

}  // namespace pine::vdbtrace
