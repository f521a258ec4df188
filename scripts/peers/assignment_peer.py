#!/usr/bin/python3
"""Reference peer for simsr::neighbors::linear_assignment (run with Debian's /usr/bin/python3).
Times scipy.optimize.linear_sum_assignment on the benchmark's dense case: Euclidean costs between
1,000 and 2,000 points uniform in the unit cube (benchmarks/bench_assignment.cpp, DenseAssignment).
    env -u OPENBLAS_CORETYPE -u OPENBLAS_L2_SIZE /usr/bin/python3 scripts/peers/assignment_peer.py [--repeats 7]
The points differ from the C++ generator's (another RNG); the cost statistics and timing do not."""
import argparse
import time

import numpy as np
from scipy.optimize import linear_sum_assignment
from scipy.spatial.distance import cdist

ap = argparse.ArgumentParser()
ap.add_argument("--n", type=int, default=1000)
ap.add_argument("--m", type=int, default=2000)
ap.add_argument("--repeats", type=int, default=7)
args = ap.parse_args()
rng = np.random.default_rng(1)
C = cdist(rng.random((args.n, 3)), rng.random((args.m, 3)))
linear_sum_assignment(C)  # warm-up
times = []
for _ in range(args.repeats):
    t = time.perf_counter()
    r, c = linear_sum_assignment(C)
    times.append(time.perf_counter() - t)
print(f"scipy linear_sum_assignment {args.n}x{args.m}: median {1e3 * np.median(times):.2f} ms, "
      f"min {1e3 * min(times):.2f} ms, cost {C[r, c].sum():.4f}")
