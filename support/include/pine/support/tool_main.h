// The prologue and epilogue every executable shares (analytic, bake, vdbtrace): what a user
// sees on --help, a bad option, --threads and an error is the same in all of them.
#pragma once

#include <CLI/CLI.hpp>

#include <functional>
#include <ostream>
#include <string>

namespace pine::tool {

/// Adds --threads and --quiet to `app`, parses argv (--help prints and returns 0; a parse error prints one
/// line "NAME: WHY (see --help)" and returns 2), limits TBB to the threads asked for, runs
/// `body` and returns its status; what it throws becomes one line "NAME: WHAT" on stderr and
/// status 2 for an InputError (the user's input or output) and for running out of memory
/// (std::bad_alloc: what was asked of the machine), 1 for anything else.
int run(const char* name, CLI::App& app, int argc, char** argv,
        const std::function<int()>& body);

/// True under --quiet (which run adds to every tool).
bool quiet();
/// As --quiet would: a process whose progress another one tells (an MPI rank's).
void setQuiet(bool quiet);
/// Where informational lines go: stderr, or nowhere under --quiet. Warnings and errors go to
/// std::cerr whatever the flag.
std::ostream& info();

/// Ends an open progress line and writes `text` as one line on stderr in a single write, so
/// that no other process's output (mpirun's, another rank's) lands inside it; line breaks in
/// `text` become spaces.
void errorLine(const std::string& text);

/// A finite number > 0 (CLI::PositiveNumber lets nan and inf through and prints DBL_MAX).
CLI::Validator positiveNumber();
/// A whole number >= least, named in its message (CLI::NonNegativeNumber's prints DBL_MAX).
CLI::Validator wholeNumberAtLeast(long least);
/// A whole number from `least` to `most`, without spaces about it (CLI::Range, through
/// strtoll, took ' 3' and refused '3 ').
CLI::Validator wholeNumberIn(long least, long most);
/// A finite number from `least` to `most` (+infinity: no bound above): CLI::Range lets nan
/// through, which the options then read as their default.
CLI::Validator numberIn(double least, double most);

/// The process's peak resident memory so far, in MiB (for the tools' summary lines).
double peakMemoryMiB();
/// Starts a new peak of resident memory (memory the allocator keeps is given back first), so
/// that peakMemoryMiBSinceReset() measures one step of a longer run. False where Linux does
/// not let it (/proc/self/clear_refs): the peak is then the process's.
bool resetPeakMemory();
/// The peak resident memory since the last resetPeakMemory() (VmHWM), in MiB.
double peakMemoryMiBSinceReset();

}  // namespace pine::tool
