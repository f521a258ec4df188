#!/usr/bin/env bash
# Builds simsr and runs every test: the doctest suites, the sanitized io suite, fuzz-corpus
# replays, the install/consumer check, cuda-compile (where nvcc exists), then a short libFuzzer
# run of every reader (clang). Installs missing Debian packages first (root).
#   bash scripts/test.sh            full run
#   SIMSR_FUZZ_SECONDS=0 bash scripts/test.sh    skip the live fuzzing
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
cd "$root"
bash scripts/deps.sh test

build=${SIMSR_BUILD_DIR:-build}
jobs=${SIMSR_JOBS:-$(nproc)}
start=$(date +%s)
cmake -S . -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Release
cmake --build "$build" -j "$jobs"
echo "simsr: build took $(( $(date +%s) - start )) s"
(cd "$build" && ctest --output-on-failure -j "$jobs" --timeout 900)

fuzz_seconds=${SIMSR_FUZZ_SECONDS:-5}
if (( fuzz_seconds > 0 )); then
  bash scripts/fuzz.sh "$fuzz_seconds"
fi
echo "simsr: all tests passed in $(( $(date +%s) - start )) s"
