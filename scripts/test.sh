#!/usr/bin/env bash
# The README test command (and CI's, .ci/run). Installs every missing Debian package first
# (scripts/deps.sh test: the peers numpy, scipy, meshio, torch, gmsh, tetgen; clang, its sanitizer
# runtimes and LLVM's OpenMP with Archer), so it exports SIMSR_REQUIRE_PEERS=1: after that, a peer,
# the ../shared/data folder or clang that is still missing is a real failure here, never a skip.
#
#   1. build/       g++, a test build (SIMSR_TEST_BUILD: -O1 everywhere): the nn suite and
#                   interp's, pipeline's and scenario's files the sanitizer builds leave out (the
#                   libgomp allocation checks; the demo, animate and ablation runs; the SoftDECA
#                   template from the kit),
#                   test_threads, the tool and examples, the peers (gmsh,
#                   meshio, numpy, scipy, torch), the Python module and its pytest suite (tests/python),
#                   install + consumer project, compile-fail checks,
#                   cuda-compile, and each benchmark compiled (clang syntax only, a ctest each: none
#                   is built or run here; -DSIMSR_BUILD_BENCHMARKS=ON builds them)
#   2. build-asan/  clang, SIMSR_SANITIZE=asan: every area's suite (pipeline's own parts) and the corpus replays under
#                   ASan+UBSan (-fsanitize=address,undefined,float-cast-overflow, UBSan's address
#                   checks left to ASan, no recovery); the
#                   suites other than interp, nn, pipeline and scenario run here and under TSan only
#                   (tests/CMakeLists.txt says why)
#   3. build-tsan/  clang, SIMSR_SANITIZE=tsan: the suites' files that run parallel code, under TSan, with
#                   LLVM's libomp and its Archer tool (so OpenMP's synchronisation is understood)
#   4. scripts/fuzz.sh: every libFuzzer harness (build-asan's replay binaries) for
#                   SIMSR_FUZZ_SECONDS (default 3) seconds each
#
# ctest must report no skipped or not-run test. The one exception, named here:
#   cuda_compile where nvcc is absent: the CUDA toolkit is no Debian package deps.sh can install
#   (a fresh machine has none; this one has /usr/local/cuda/bin/nvcc), and without nvcc there is
#   nothing to compile the .cu check with. Where nvcc exists, the check runs and must pass.
#
#   bash scripts/test.sh                          full run
#   SIMSR_FUZZ_SECONDS=0 bash scripts/test.sh     no live fuzzing (the corpus replays still run)
#   SIMSR_JOBS=N                                  parallel jobs (default: nproc)
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
cd "$root"
bash scripts/deps.sh test
export SIMSR_REQUIRE_PEERS=1

build=${SIMSR_BUILD_DIR:-build}
asan=${SIMSR_ASAN_BUILD_DIR:-build-asan}
tsan=${SIMSR_TSAN_BUILD_DIR:-build-tsan}
jobs=${SIMSR_JOBS:-$(nproc)}
start=$(date +%s)
step_start=$start
step() {  # prints the time of the step that just ended
  local now
  now=$(date +%s)
  echo "simsr: $1 took $((now - step_start)) s"
  step_start=$now
}

command -v clang++ >/dev/null || { echo "simsr: clang++ not found (scripts/deps.sh test installs clang)" >&2; exit 1; }

# ctest in $1 (more arguments go to ctest); fails on a failed test and on any skipped or not-run
# test except the exception above.
run_ctest() {
  local dir=$1 log status=0
  shift
  log="$dir/ctest.log"
  (cd "$dir" && ctest --output-on-failure -j "$jobs" --timeout 1500 "$@") 2>&1 | tee "$log" || status=$?
  local skipped t bad=0
  skipped=$(sed -n '/The following tests did not run:/,/^$/p' "$log" | sed -n 's/^[[:space:]]*[0-9]* - \(.*\) ([^)]*)$/\1/p')
  for t in $skipped; do
    if [[ $t == cuda_compile ]] && grep -q '^SIMSR_NVCC:FILEPATH=.*NOTFOUND' "$dir/CMakeCache.txt"; then
      echo "simsr: cuda_compile skipped: nvcc not found (the named exception: no CUDA toolkit on this machine)"
      continue
    fi
    echo "simsr: test '$t' did not run (skipped): with SIMSR_REQUIRE_PEERS=1 that is a failure" >&2
    bad=1
  done
  if ! grep -q "tests passed" "$log"; then
    echo "simsr: ctest in $dir printed no result" >&2
    bad=1
  fi
  ((status == 0 && bad == 0))
}

# 1. the normal build
cmake -S . -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Release -DSIMSR_TEST_BUILD=ON -DSIMSR_NATIVE=OFF -DSIMSR_BUILD_BENCHMARKS=OFF -DSIMSR_CHECK_BENCHMARKS=ON -DSIMSR_WITH_CHOLMOD=ON -DSIMSR_WITH_CGAL=ON -DSIMSR_WITH_PYTHON=ON -DSIMSR_WITH_MPI=ON
cmake --build "$build" -j "$jobs"
step "build ($build)"
run_ctest "$build"
step "ctest ($build)"

# 2-3. the sanitizer builds: only the test suites (no tool, examples or benchmarks), -O1 -g1 with
# assertions on (Debug: no NDEBUG, so Eigen checks its indices too), clang
for kind in asan tsan; do
  dir=$asan
  [[ $kind == tsan ]] && dir=$tsan
  cmake -S . -B "$dir" -G Ninja -DCMAKE_CXX_COMPILER=clang++ -DCMAKE_BUILD_TYPE=Debug -DSIMSR_SANITIZE=$kind \
    -DSIMSR_BUILD_BENCHMARKS=OFF -DSIMSR_BUILD_EXAMPLES=OFF -DSIMSR_WITH_CHOLMOD=ON >/dev/null
  cmake --build "$dir" -j "$jobs"
  step "build ($dir)"
  run_ctest "$dir"
  step "ctest ($dir)"
done

fuzz_seconds=${SIMSR_FUZZ_SECONDS:-3}
if ((fuzz_seconds > 0)); then
  bash scripts/fuzz.sh "$fuzz_seconds"
  step "fuzzing"
fi
echo "simsr: all tests passed in $(($(date +%s) - start)) s"
