#include "pine/support/isolated_process.h"

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <new>
#include <system_error>

namespace pine::io {

namespace {

std::string gibibytes(double bytes)
{
    char text[32];
    std::snprintf(text, sizeof text, "%.3g GiB", bytes / (1024.0 * 1024.0 * 1024.0));
    return text;
}

// The child's address space may grow by `bytes` beyond what it shares with the caller.
// AddressSanitizer reserves terabytes of shadow as it goes and enforces its own limits, so
// there the limit is left to it.
void limitAddressSpace(double bytes)
{
#if !defined(__SANITIZE_ADDRESS__)
    long pages = 0;
    if (std::FILE* statm = std::fopen("/proc/self/statm", "r")) {
        if (std::fscanf(statm, "%ld", &pages) != 1) pages = 0;
        std::fclose(statm);
    }
    const double now = double(pages) * double(::sysconf(_SC_PAGESIZE));
    const rlimit limit{rlim_t(now + bytes), rlim_t(now + bytes)};
    ::setrlimit(RLIMIT_AS, &limit);
#else
    (void)bytes;
#endif
}

void writeAll(int fd, const std::string& text)
{
    for (std::size_t done = 0; done < text.size();) {
        const ssize_t n = ::write(fd, text.data() + done, text.size() - done);
        if (n < 0 && errno == EINTR) continue;
        if (n <= 0) return;
        done += std::size_t(n);
    }
}

// The child's reply: one byte saying how the step ended, then its words. An exit without the
// byte (a library calling exit(0), a sanitizer's report) is a crash.
constexpr char kReturned = 'R', kThrew = 'T', kOutOfMemory = 'M';

[[noreturn]] void runChild(const std::function<void()>& step, const IsolationLimits& limits,
                           int reply)
{
    const rlimit noCore{0, 0};  // a crash here is an answer, not a core file
    ::setrlimit(RLIMIT_CORE, &noCore);
    if (limits.memoryBytes > 0.0) limitAddressSpace(limits.memoryBytes);
    char status = kReturned;
    std::string why;
    try {
        step();
    } catch (const std::bad_alloc&) {
        status = kOutOfMemory;
        why = limits.memoryBytes > 0.0 ? "needs more than " + gibibytes(limits.memoryBytes) +
                                             " of memory"
                                       : "ran out of memory";
    } catch (const std::exception& e) {
        status = kThrew;
        why = e.what();
    } catch (...) {
        status = kThrew;
        why = "an unknown exception";
    }
    writeAll(reply, status + why);
    // No destructors, atexit handlers or buffered output of the caller's run twice.
    ::_exit(0);
}

}  // namespace

IsolatedOutcome runIsolated(const std::function<void()>& step, const IsolationLimits& limits)
{
    int fds[2];
    if (::pipe2(fds, O_CLOEXEC) != 0) {
        throw std::system_error(errno, std::generic_category(), "cannot start a child process");
    }
    std::fflush(nullptr);
    const pid_t pid = ::fork();
    if (pid < 0) {
        const int why = errno;
        ::close(fds[0]);
        ::close(fds[1]);
        throw std::system_error(why, std::generic_category(), "cannot start a child process");
    }
    if (pid == 0) {
        ::close(fds[0]);
        runChild(step, limits, fds[1]);
    }
    ::close(fds[1]);

    using Clock = std::chrono::steady_clock;
    const auto deadline =
        Clock::now() + std::chrono::duration_cast<Clock::duration>(
                           std::chrono::duration<double>(limits.seconds));
    std::string message;
    bool timedOut = false;
    for (;;) {  // the reply, until the child closes its end by exiting
        const auto left =
            std::chrono::duration_cast<std::chrono::milliseconds>(deadline - Clock::now());
        if (left.count() <= 0) {
            timedOut = true;
            break;
        }
        pollfd p{fds[0], POLLIN, 0};
        const int ready = ::poll(&p, 1, int(std::min<long long>(left.count(), 1 << 30)));
        if (ready < 0 && errno == EINTR) continue;
        if (ready == 0) {
            timedOut = true;
            break;
        }
        char buffer[512];
        const ssize_t n = ::read(fds[0], buffer, sizeof buffer);
        if (n < 0 && errno == EINTR) continue;
        if (n <= 0) break;
        message.append(buffer, std::size_t(n));
    }
    ::close(fds[0]);
    // The child has closed its end (or its time is up): its exit, within the same deadline.
    int status = 0;
    bool reaped = false;
    for (;;) {
        if (!timedOut && Clock::now() >= deadline) timedOut = true;
        if (timedOut) ::kill(pid, SIGKILL);
        const pid_t got = ::waitpid(pid, &status, timedOut ? 0 : WNOHANG);
        if (got == pid) {
            reaped = true;
            break;
        }
        if (got < 0 && errno != EINTR) break;  // not ours to wait for: no answer
        if (got == 0) ::usleep(1000);
    }

    using Kind = IsolatedOutcome::Kind;
    if (timedOut) {
        char text[48];
        std::snprintf(text, sizeof text, "took longer than %g s", limits.seconds);
        return {Kind::TimedOut, text};
    }
    if (!reaped) return {Kind::Crashed, "ended unseen (waitpid failed)"};
    if (WIFSIGNALED(status)) {
        return {Kind::Crashed, std::string("crashed (") + ::strsignal(WTERMSIG(status)) + ")"};
    }
    const int code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    const char said = message.empty() ? '\0' : message[0];
    const std::string why = message.empty() ? "" : message.substr(1);
    if (code != 0 || said == '\0') {
        return {Kind::Crashed, "exited with status " + std::to_string(code) +
                                   (said == '\0' ? " before it answered" : "")};
    }
    if (said == kReturned) return {Kind::Returned, ""};
    if (said == kThrew) return {Kind::Threw, why};
    if (said == kOutOfMemory) return {Kind::OutOfMemory, why};
    return {Kind::Crashed, "answered what no step says"};
}

}  // namespace pine::io
