// A step run in a child process: each way it can end comes back as an answer, and the caller
// goes on (the caller here is this test: a crash or a runaway allocation in the step would
// otherwise end it).
#include "pine/support/isolated_process.h"

#include <gtest/gtest.h>

#include <unistd.h>

#include <cstdlib>
#include <stdexcept>
#include <vector>

namespace pine::io {
namespace {

using Kind = IsolatedOutcome::Kind;

TEST(IsolatedProcess, AStepThatReturnsReturned)
{
    int touched = 0;
    const IsolatedOutcome outcome = runIsolated([&] { touched = 1; }, {});
    EXPECT_TRUE(outcome.returned()) << outcome.why;
    EXPECT_EQ(touched, 0);  // the child's memory, not ours
}

TEST(IsolatedProcess, WhatTheStepThrowsComesBackAsItWas)
{
    const IsolatedOutcome outcome =
        runIsolated([] { throw std::runtime_error("grid 'density' is missing"); }, {});
    EXPECT_EQ(outcome.kind, Kind::Threw);
    EXPECT_EQ(outcome.why, "grid 'density' is missing");
}

TEST(IsolatedProcess, ACrashIsAnAnswer)
{
    const IsolatedOutcome outcome = runIsolated([] { std::abort(); }, {});
    EXPECT_EQ(outcome.kind, Kind::Crashed);
    EXPECT_NE(outcome.why.find("crashed (Aborted)"), std::string::npos) << outcome.why;
}

TEST(IsolatedProcess, AnExitWithoutAReplyIsACrash)
{
    const IsolatedOutcome outcome = runIsolated([] { ::_exit(7); }, {});
    EXPECT_EQ(outcome.kind, Kind::Crashed);
    EXPECT_EQ(outcome.why, "exited with status 7 before it answered");
    // A library that exits with status 0 in the middle of the step has not returned.
    const IsolatedOutcome quiet = runIsolated([] { ::_exit(0); }, {});
    EXPECT_EQ(quiet.kind, Kind::Crashed);
    EXPECT_EQ(quiet.why, "exited with status 0 before it answered");
}

#if !defined(__SANITIZE_ADDRESS__)
TEST(IsolatedProcess, MemoryBeyondTheLimitIsRefused)
{
    // 64 MiB allowed, 1 GiB asked for (touched, so an overcommitting kernel cannot pretend).
    const IsolatedOutcome outcome = runIsolated(
        [] {
            std::vector<char> big(std::size_t(1) << 30, 1);
            if (big[12345] != 1) throw std::logic_error("unreachable");
        },
        {64.0 * 1024 * 1024, 60.0});
    EXPECT_EQ(outcome.kind, Kind::OutOfMemory);
    EXPECT_EQ(outcome.why, "needs more than 0.0625 GiB of memory");
    // The same step within a limit it fits in returns.
    EXPECT_TRUE(runIsolated([] { std::vector<char>(1 << 20, 1); }, {64.0 * 1024 * 1024, 60.0})
                    .returned());
}
#endif

TEST(IsolatedProcess, AHangIsKilledAtItsDeadline)
{
    const IsolatedOutcome outcome = runIsolated([] { ::pause(); }, {0.0, 0.3});
    EXPECT_EQ(outcome.kind, Kind::TimedOut);
    EXPECT_EQ(outcome.why, "took longer than 0.3 s");
    // Its end of the pipe closed, the child still hangs: the same deadline holds.
    const IsolatedOutcome closed = runIsolated(
        [] {
            for (int fd = 3; fd < 1024; ++fd) ::close(fd);
            ::pause();
        },
        {0.0, 0.3});
    EXPECT_EQ(closed.kind, Kind::TimedOut);
}

}  // namespace
}  // namespace pine::io
