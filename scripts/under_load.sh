#!/usr/bin/env bash
# Under load: a second busy process must slow simsr down, never collapse it (issue #10).
# Times `cantilever --cells C --solver S` (its own "seconds": the solve) sequentially and with
# --omp, on the machine as it is ("idle") and beside one `yes > /dev/null` ("busy"), and prints
# the medians and the ratios. `omp-always` is exec::omp forking a team for every loop
# (SIMSR_OMP_FORK=always: the behaviour before the adaptive fork), for comparison.
#
#   scripts/under_load.sh                                  # build/examples/cantilever, --cells 6, 3 runs each
#   scripts/under_load.sh --bin build-x/examples/cantilever --cells 5 --reps 5
#   scripts/under_load.sh --check 1.5    # exit 1 when busy omp takes more than 1.5 × busy seq
#
# Measure on an otherwise idle machine: other work makes "idle" busy too.
set -euo pipefail

bin=build/examples/cantilever
cells=6
solver=pcg-multigrid
reps=3
check=""
while [[ $# -gt 0 ]]; do
  case "$1" in
    --bin) bin="$2"; shift 2 ;;
    --cells) cells="$2"; shift 2 ;;
    --solver) solver="$2"; shift 2 ;;
    --reps) reps="$2"; shift 2 ;;
    --check) check="$2"; shift 2 ;;
    -h|--help) sed -n '2,13p' "$0"; exit 0 ;;
    *) echo "under_load.sh: unknown argument $1" >&2; exit 2 ;;
  esac
done
[[ -x "$bin" ]] || { echo "under_load.sh: no cantilever at $bin (build it: ninja -C build cantilever, or --bin)" >&2; exit 2; }

busy_pid=""
stop_busy() { if [[ -n "$busy_pid" ]]; then kill "$busy_pid" 2>/dev/null || true; wait "$busy_pid" 2>/dev/null || true; busy_pid=""; fi; }
trap stop_busy EXIT

# seconds of one run: run VARIANT
run() {
  local args=(--cells "$cells" --solver "$solver") env=()
  case "$1" in
    seq) ;;
    omp) args+=(--omp) ;;
    omp-always) args+=(--omp); env=(SIMSR_OMP_FORK=always) ;;
  esac
  env "${env[@]}" "$bin" "${args[@]}" | sed -n 's/.*"seconds":\([0-9.eE+-]*\).*/\1/p'
}

median() { sort -g | awk '{ v[NR] = $1 } END { if (NR % 2) print v[(NR + 1) / 2]; else print (v[NR / 2] + v[NR / 2 + 1]) / 2 }'; }

declare -A result
variants=(seq omp omp-always)
for load in idle busy; do
  if [[ $load == busy ]]; then
    yes > /dev/null &
    busy_pid=$!
    sleep 0.2
  fi
  for v in "${variants[@]}"; do
    times=()
    for ((r = 0; r < reps; ++r)); do times+=("$(run "$v")"); done
    result[$load,$v]=$(printf '%s\n' "${times[@]}" | median)
    echo "$load $v: ${times[*]} s (median ${result[$load,$v]})" >&2
  done
  stop_busy
done

echo "cantilever --cells $cells --solver $solver: median of $reps solves (s), $(nproc) cores, OMP_NUM_THREADS=${OMP_NUM_THREADS:-unset}"
printf '%-11s %8s %8s %11s\n' variant idle busy busy/idle
for v in "${variants[@]}"; do
  printf '%-11s %8.2f %8.2f %11.2f\n' "$v" "${result[idle,$v]}" "${result[busy,$v]}" "$(echo "${result[busy,$v]} / ${result[idle,$v]}" | bc -l)"
done
ratio=$(echo "${result[busy,omp]} / ${result[busy,seq]}" | bc -l)
printf 'busy omp / busy seq: %.2f (omp-always: %.2f)\n' "$ratio" "$(echo "${result[busy,omp-always]} / ${result[busy,seq]}" | bc -l)"
if [[ -n "$check" ]] && (( $(echo "$ratio > $check" | bc -l) )); then
  echo "under_load.sh: beside a busy process --omp took $(printf '%.2f' "$ratio") × the sequential time (limit $check)" >&2
  exit 1
fi
