// A step run on bytes we cannot trust, in a child process: OpenVDB 10.0.1 crashes or allocates
// without bound on some damaged files (DESIGN.md), and a manifest that matches a file says only
// that the bytes are those someone wrote, not that OpenVDB survives them. A signal, a runaway
// allocation or a hang in the child becomes an answer, never the caller's death.
#pragma once

#include <functional>
#include <string>

namespace pine::io {

struct IsolationLimits {
    double memoryBytes = 0.0;  ///< address space the step may add to the caller's; 0: no limit
    double seconds = 60.0;     ///< wall-clock time before the child is killed
};

struct IsolatedOutcome {
    enum class Kind { Returned, Threw, OutOfMemory, Crashed, TimedOut };
    Kind kind = Kind::Returned;
    /// Threw: what(); OutOfMemory: "needs more than 1.5 GiB of memory"; Crashed: "crashed
    /// (Segmentation fault)" or "exited with status 3"; TimedOut: "took longer than 60 s".
    std::string why;
    bool returned() const { return kind == Kind::Returned; }
};

/// Runs `step` in a forked child within `limits` and says how it ended. Nothing the step
/// builds reaches the caller: run it again here once it has returned on the same input. The
/// child holds only the calling thread, so a step must not need a lock another thread might
/// hold (call it before parallel work). Throws std::system_error if no child can be started.
IsolatedOutcome runIsolated(const std::function<void()>& step, const IsolationLimits& limits);

}  // namespace pine::io
