#include "pine/support/tool_main.h"

#include "pine/support/input_error.h"
#include "pine/support/progress.h"

#include <malloc.h>
#include <sys/resource.h>
#include <tbb/global_control.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <functional>
#include <iostream>
#include <limits>
#include <memory>
#include <new>
#include <sstream>
#include <string>
#include <vector>

namespace pine::tool {
namespace {

bool gQuiet = false;

// Where informational lines go under --quiet.
class NullBuffer : public std::streambuf {
protected:
    int overflow(int c) override { return traits_type::not_eof(c); }
};

// What an error says, on one line: a library's message may span several.
std::string oneLine(std::string text)
{
    while (!text.empty() && (text.back() == '\n' || text.back() == ' ')) text.pop_back();
    for (char& c : text) {
        if (c == '\n') c = ' ';
    }
    return printable(text);
}

}  // namespace

int run(const char* name, CLI::App& app, int argc, char** argv,
        const std::function<int()>& body)
{
    int threads = 0;
    app.add_option("--threads", threads, "Worker threads (default: all cores)")
        ->check(wholeNumberAtLeast(0));
    app.add_flag("--quiet,-q", gQuiet, "Only warnings and errors on stderr (no progress)");
    app.set_version_flag("--version", std::string(name) + " " + PINE_TOOL_VERSION);
    for (CLI::App* sub : app.get_subcommands({})) {
        sub->fallthrough();  // --threads and --version also after the subcommand
    }
    try {
        app.parse(argc, argv);
    } catch (const CLI::ParseError& e) {
        if (e.get_exit_code() == 0) return app.exit(e);  // --help
        // CLI11 checks what is required before what is left over, so that a misspelt option
        // would be reported as the option it failed to be ("--out is required"): name it.
        // (ExtrasError joins them last first.)
        std::vector<std::string> unknown = app.remaining(true);
        std::reverse(unknown.begin(), unknown.end());
        const std::string why =
            unknown.empty() ? std::string(e.what()) : std::string(CLI::ExtrasError(unknown).what());
        errorLine(std::string(name) + ": " + oneLine(why) + " (see --help)");
        return 2;
    }
    std::unique_ptr<tbb::global_control> limit;
    if (threads > 0) {
        limit = std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism,
                                                      std::size_t(threads));
    }
    try {
        return body();
    } catch (const InputError& e) {
        errorLine(std::string(name) + ": " + e.what());
        return 2;
    } catch (const std::bad_alloc&) {
        errorLine(std::string(name) +
                  ": out of memory: the scene or the settings ask for more than this machine "
                  "has (lower the resolution, the samples, the trees or the voxel size)");
        return 2;
    } catch (const std::exception& e) {
        errorLine(std::string(name) + ": " + e.what());
        return 1;
    }
}

void errorLine(const std::string& text)
{
    Progress::endOpenLine();
    const std::string line = oneLine(text) + '\n';
    std::cerr.flush();
    std::fwrite(line.data(), 1, line.size(), stderr);
    std::fflush(stderr);
}

bool quiet() { return gQuiet; }

void setQuiet(bool quiet)
{
    gQuiet = quiet;
}

std::ostream& info()
{
    static NullBuffer nothing;
    static std::ostream discard(&nothing);
    return gQuiet ? discard : std::cerr;
}

namespace {

std::string shown(double v)
{
    std::ostringstream s;
    s << v;
    return s.str();
}

bool spacedAbout(const std::string& text)
{
    const auto space = [](unsigned char c) { return std::isspace(c) != 0; };
    return !text.empty() && (space(text.front()) || space(text.back()));
}

// Why `text` is not a number `wanted` (one the test `within` accepts), or empty. Spaces about
// it are refused either side: strtod skips leading ones, so ' 3' was taken where '3 ' was not
// (CLI11 converts the text as given: a validator under check() cannot trim it).
std::string whyNotANumber(const std::string& text, const std::string& wanted,
                          const std::function<bool(double)>& within)
{
    const std::string refused = "must be a number " + wanted + ", got '" + text + "'";
    if (spacedAbout(text)) return refused + ", with spaces about it";
    errno = 0;
    char* end = nullptr;
    const double v = std::strtod(text.c_str(), &end);
    if (text.empty() || end != text.c_str() + text.size()) return refused;
    // strtod's range error: past the largest double, or below the smallest normal one (5e-324
    // is a number > 0 to the user; to the tool it is 0 or a denormal).
    if (errno == ERANGE) {
        return refused + (std::abs(v) > 1.0 ? ", which overflows a double"
                                            : ", which is below the smallest normal double (" +
                                                  shown(std::numeric_limits<double>::min()) + ")");
    }
    return std::isfinite(v) && within(v) ? std::string() : refused;
}

}  // namespace

CLI::Validator positiveNumber()
{
    return CLI::Validator(
        [](std::string& text) {
            return whyNotANumber(text, "> 0", [](double v) { return v > 0.0; });
        },
        "> 0");
}

CLI::Validator wholeNumberIn(long least, long most)
{
    const std::string wanted =
        most == std::numeric_limits<long>::max()
            ? ">= " + std::to_string(least)
            : "from " + std::to_string(least) + " to " + std::to_string(most);
    return CLI::Validator(
        [=](std::string& text) -> std::string {
            const std::string refused = "must be a whole number " + wanted + ", got '" + text + "'";
            // stol skips leading spaces and stops at trailing ones: refused both ways, as
            // whyNotANumber refuses them.
            if (spacedAbout(text)) return refused + ", with spaces about it";
            try {
                std::size_t used = 0;
                const long v = std::stol(text, &used, 0);  // as CLI11 reads it: 010 is 8
                if (used == text.size() && v >= least && v <= most) return {};
            } catch (const std::exception&) {
            }
            return refused;
        },
        most == std::numeric_limits<long>::max()
            ? ">= " + std::to_string(least)
            : "in [" + std::to_string(least) + ", " + std::to_string(most) + "]");
}

CLI::Validator wholeNumberAtLeast(long least)
{
    return wholeNumberIn(least, std::numeric_limits<long>::max());
}

CLI::Validator numberIn(double least, double most)
{
    const std::string wanted =
        std::isinf(most) ? ">= " + shown(least) : "from " + shown(least) + " to " + shown(most);
    return CLI::Validator(
        [=](std::string& text) {
            return whyNotANumber(text, wanted, [=](double v) { return v >= least && v <= most; });
        },
        std::isinf(most) ? ">= " + shown(least) : "in [" + shown(least) + ", " + shown(most) + "]");
}

double peakMemoryMiB()
{
    rusage usage{};
    getrusage(RUSAGE_SELF, &usage);
    return double(usage.ru_maxrss) / 1024.0;  // Linux reports KiB
}

bool resetPeakMemory()
{
    malloc_trim(0);
    std::ofstream refs("/proc/self/clear_refs");
    refs << "5";  // proc(5): "reset the peak resident set size"
    refs.flush();
    return bool(refs);
}

double peakMemoryMiBSinceReset()
{
    std::ifstream status("/proc/self/status");
    for (std::string line; std::getline(status, line);) {
        if (line.rfind("VmHWM:", 0) == 0) return std::stod(line.substr(6)) / 1024.0;  // kB
    }
    return peakMemoryMiB();
}

}  // namespace pine::tool
