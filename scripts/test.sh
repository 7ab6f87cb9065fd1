#!/usr/bin/env bash
# Every test, from a fresh Debian 12 machine: install what is missing, build (Release), run the
# GoogleTest suites and the tool checks through ctest.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh --test
cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release -DPINE_BUILD_BENCHMARKS=ON
cmake --build build
ctest --test-dir build --output-on-failure -j "$(nproc)"
