#!/usr/bin/env bash
# Fuzzes every libFuzzer harness (tests/fuzz/fuzz_*.cpp: each reader, the model-file loader, paired
# frames) for N seconds each (default 60), starting from its committed corpus. The fuzzers are the
# ASan build's replay_<name> binaries (clang, ASan+UBSan, libFuzzer's driver behind `--fuzz`): the
# build scripts/test.sh makes, configured and built here if needed. New crashing inputs land in
# build-asan/crashes/. Without clang++ this is a skip, or a failure where SIMSR_REQUIRE_PEERS is set.
#   bash scripts/fuzz.sh [SECONDS]        (SIMSR_FUZZ_SEED=N picks the mutation seed; default 1, so
#                                         a short run in CI explores the same inputs every time)
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
cd "$root"
seconds=${1:-60}
if ! command -v clang++ >/dev/null; then
  if [[ ${SIMSR_REQUIRE_PEERS:-0} != 0 && -n ${SIMSR_REQUIRE_PEERS:-} ]]; then
    echo "simsr: clang++ not found and SIMSR_REQUIRE_PEERS is set: fuzzing cannot run (apt-get install clang libclang-rt-dev)" >&2; exit 1
  fi
  echo "simsr: clang++ not found, fuzzing skipped (apt-get install clang libclang-rt-dev)"; exit 0
fi
build=${SIMSR_ASAN_BUILD_DIR:-build-asan}
[[ -f $build/CMakeCache.txt ]] || cmake -S . -B "$build" -G Ninja -DCMAKE_CXX_COMPILER=clang++ -DCMAKE_BUILD_TYPE=Debug \
  -DSIMSR_SANITIZE=asan -DSIMSR_BUILD_BENCHMARKS=OFF -DSIMSR_BUILD_EXAMPLES=OFF >/dev/null
shopt -s nullglob
targets=""
for f in tests/fuzz/fuzz_*.cpp; do n=$(basename "$f" .cpp); targets+=" replay_${n#fuzz_}"; done
[[ -n $targets ]] || { echo "simsr: no fuzz harnesses"; exit 0; }
cmake --build "$build" -j "$(nproc)" --target $targets
mkdir -p "$build/crashes"
status=0
# One fuzzer per core at a time (each is single-threaded): the same seconds each, half the wall
# clock on CI's two cores.
fuzz_one() {
  local t=$1 name work largest max_len runs
  name=${t#replay_}
  work=$(mktemp -d)
  cp -r "tests/fuzz/corpus/$name/." "$work/" 2>/dev/null || true
  # inputs up to 8 KiB, or twice the largest seed (a model file's seeds are ~40 KB): a seed cut to
  # max_len would only exercise the truncated-file paths
  largest=$(find "$work" -type f -printf '%s\n' | sort -n | tail -1)
  max_len=$((2 * ${largest:-0} > 8192 ? 2 * ${largest:-0} : 8192))
  if "$build/tests/fuzz/$t" --fuzz "$work" -max_total_time="$seconds" -seed="${SIMSR_FUZZ_SEED:-1}" -max_len="$max_len" -timeout=5 -rss_limit_mb=2048 \
       -artifact_prefix="$build/crashes/$name-" -print_final_stats=1 >"$build/$t.log" 2>&1; then
    runs=$(grep -m1 'stat::number_of_executed_units' "$build/$t.log" | awk '{print $2}')
    echo "simsr: fuzz $name: ${seconds} s, ${runs:-?} inputs, no crash"
    rm -rf "$work"
  else
    echo "simsr: fuzz $name FOUND A CRASH (see $build/$t.log, inputs in $build/crashes/)"; tail -30 "$build/$t.log"
    rm -rf "$work"
    return 1
  fi
}
jobs_max=$(nproc)
rm -f "$build"/fuzz_failed_*
for t in $targets; do
  while (($(jobs -rp | wc -l) >= jobs_max)); do wait -n || true; done
  { fuzz_one "$t" || touch "$build/fuzz_failed_${t#replay_}"; } &
done
wait
if compgen -G "$build/fuzz_failed_*" >/dev/null; then status=1; fi
exit $status
