// The process's CPU clock: how the tools and reports time work on a shared, noisy machine
// (CPU seconds of all threads, not wall seconds).
#pragma once

namespace pine::io {

/// CPU seconds the process has used so far, all threads (user and system).
double processCpuSeconds();

}  // namespace pine::io
