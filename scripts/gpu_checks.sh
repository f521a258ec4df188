#!/usr/bin/env bash
# The GPU checks of issue #17 item 5, on a machine with an NVIDIA GPU: the cuda tests, CUDA's
# memory checker over the library's, and the GPU benchmark with its host baselines in the same run.
#   bash scripts/gpu_checks.sh BIN [OUT]
# BIN holds exec_cuda_test, library_cuda_test and bench_cuda: tests/cuda/project built with nvcc,
#   cmake -S tests/cuda/project -B BIN -G Ninja -DSIMSR_SOURCE_DIR=$PWD -DCMAKE_BUILD_TYPE=Release \
#         -DCMAKE_CUDA_ARCHITECTURES=90 -DCMAKE_CUDA_COMPILER=/usr/local/cuda/bin/nvcc && ninja -C BIN
# (README, "Execution policies"). OUT (default gpu_checks) receives the logs and the benchmark's
# JSON. Stops at the first failing check.
set -euo pipefail
BIN=${1:?usage: gpu_checks.sh BIN [OUT]}
OUT=${2:-gpu_checks}
mkdir -p "$OUT"
nvidia-smi --query-gpu=name,driver_version,clocks.sm,clocks.mem,memory.total --format=csv | tee "$OUT/gpu.csv"
echo "== exec_cuda_test"; "$BIN/exec_cuda_test" | tee "$OUT/exec_cuda_test.log"
echo "== library_cuda_test"; "$BIN/library_cuda_test" | tee "$OUT/library_cuda_test.log"
if command -v compute-sanitizer >/dev/null; then
  echo "== compute-sanitizer memcheck library_cuda_test"
  compute-sanitizer --tool memcheck --error-exitcode 99 "$BIN/library_cuda_test" 2>&1 | tail -3 | tee "$OUT/memcheck.log"
else
  echo "compute-sanitizer not found: memcheck not run" | tee "$OUT/memcheck.log"
fi
# host baselines on 2 threads (the development machine's cores), then the omp rows on every core
echo "== bench_cuda, OMP_NUM_THREADS=2"
OMP_NUM_THREADS=2 "$BIN/bench_cuda" --benchmark_min_time=0.3 --benchmark_out="$OUT/bench_cuda_2threads.json" --benchmark_out_format=json
echo "== bench_cuda omp rows, OMP_NUM_THREADS=$(nproc)"
OMP_NUM_THREADS=$(nproc) "$BIN/bench_cuda" --benchmark_filter=/omp --benchmark_min_time=0.3 \
  --benchmark_out="$OUT/bench_cuda_all_threads.json" --benchmark_out_format=json
