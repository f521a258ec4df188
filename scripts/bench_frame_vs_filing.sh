#!/usr/bin/env bash
# Issue #17 item 1's frame against the code of the day the issue was filed, in one session.
#
# The bunny-lattice frame's "today 587 ms" was measured with the library of commit 7426efe (the
# last commit before the issue's first; README "Physics at the paper's LR size"). The row
# BM_frame_73k/pcg_multigrid of today's bench_physics is not that code: the same options, but every
# library change since (the element stiffness from eigen-modes, 3×3-block products, the coarsened
# hierarchy) speeds it up too, so it says nothing about how fast the machine is against that day.
# This script builds bench_physics from 7426efe's own tree (a temporary git worktree, -O3
# -march=native, as build-bench builds today's) and alternates it with today's binary, so the
# ratio of today's rows to the filing code is measured in one session, on one machine state.
#
#   bash scripts/bench_frame_vs_filing.sh [today's bench_physics] [rounds]
#
# Needs the repository's history (a clone, not an export), g++, Google Benchmark, Eigen and
# libzip (scripts/deps.sh installs them). Prints each round's rows; nothing else is written.
set -euo pipefail
here="$(cd "$(dirname "$0")/.." && pwd)"
today="${1:-$here/build-bench/benchmarks/bench_physics}"
rounds="${2:-2}"
filing_commit=7426efe
[ -x "$today" ] || { echo "bench_frame_vs_filing: no bench_physics at $today (build it: cmake --build build-bench --target bench_physics)" >&2; exit 2; }
git -C "$here" cat-file -e "$filing_commit^{commit}" 2>/dev/null || { echo "bench_frame_vs_filing: commit $filing_commit is not in this repository's history (a shallow clone?)" >&2; exit 2; }

work="$(mktemp -d)"
cleanup() { git -C "$here" worktree remove --force "$work/tree" >/dev/null 2>&1 || true; rm -rf "$work"; }
trap cleanup EXIT
git -C "$here" worktree add --detach "$work/tree" "$filing_commit" >/dev/null
echo "bench_frame_vs_filing: building bench_physics at $filing_commit (about a minute)" >&2
g++ -O3 -DNDEBUG -march=native -fopenmp -std=gnu++20 -I"$work/tree/include" -isystem /usr/include/eigen3 \
  -DSIMSR_DATA_DIR="\"$here/../shared/data\"" "$work/tree/benchmarks/bench_physics.cpp" -o "$work/bench_physics_filing" \
  -lbenchmark -lpthread -lzip

rows='BM_frame_73k/(pcg_multigrid|pcg_multigrid_doubling|pcg_multigrid_inexact_coloured_chebyshev2_chord_first_single_coarse_every_4_extrapolated_after_a(_doubling)?)/omp'
export OMP_NUM_THREADS="${OMP_NUM_THREADS:-2}"
for ((r = 1; r <= rounds; ++r)); do
  echo "round $r"
  "$work/bench_physics_filing" --benchmark_filter='BM_frame_73k/pcg_multigrid/omp' 2>/dev/null | grep '^BM_' | sed 's/^/filing code ('"$filing_commit"'): /'
  "$today" --benchmark_filter="$rows" 2>/dev/null | grep '^BM_' | sed 's/^/today: /'
done
