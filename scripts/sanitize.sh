#!/usr/bin/env bash
# The fuzz and fault-injection suite (ctest label "fuzz") once more, on the tools built with
# AddressSanitizer and UndefinedBehaviorSanitizer (Debug, -O1 so that it runs in minutes): a
# memory error or undefined behaviour the suite provokes aborts the tool, which the suite counts
# as a crash. Run by .ci/run after scripts/test.sh; `bash scripts/sanitize.sh` alone needs the
# dependencies installed (scripts/install-deps.sh).
set -euo pipefail
cd "$(dirname "$0")/.."
build=${PINE_SANITIZE_BUILD:-build-sanitize}
flags="-O1 -fsanitize=address,undefined -fno-omit-frame-pointer -fno-sanitize-recover=undefined"
cmake -S . -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Debug -DPINE_BUILD_BENCHMARKS=OFF \
    "-DCMAKE_CXX_FLAGS=$flags" "-DCMAKE_EXE_LINKER_FLAGS=-fsanitize=address,undefined"
cmake --build "$build" --target vdbtrace bake analytic
# Leaks are not what this run looks for (libraries keep their caches to the end); every other
# finding stops the tool with a report on stderr.
export ASAN_OPTIONS=detect_leaks=0:abort_on_error=0:halt_on_error=1
export UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
export PINE_SANITIZED=1
ctest --test-dir "$build" --output-on-failure -L fuzz -j "$(nproc)"
