#!/usr/bin/python3
"""Reference peer for simsr::interp::RBF (run with Debian's /usr/bin/python3: numpy, scipy).

Query mode (used by tests/interp/test_rbf.cpp):
    rbf_peer.py --centres C.npy --values V.npy --queries Q.npy --epsilon E --degree D --out P.npy
runs scipy.interpolate.RBFInterpolator(C, V, kernel='gaussian', epsilon=E, degree=D) on
C (N x 3), V (N x 3) and writes its predictions at Q (M x 3) as float64 M x 3. scipy's Gaussian is
exp(-(E r)^2), so E = 1/sigma for simsr's exp(-r^2/sigma^2); degree -1 is no polynomial tail
(scipy's default for 'gaussian' is 0). Exit status 77 when scipy is missing.

Bench mode (peer timing beside benchmarks/bench_interp.cpp):
    env -u OPENBLAS_CORETYPE -u OPENBLAS_L2_SIZE /usr/bin/python3 rbf_peer.py --bench [--n 4000 --m 9000]
fits RBFInterpolator on N random points (spacing-matched epsilon, degree 0) and evaluates M
queries; prints median/min of `--repeats` runs of fit and of evaluation (2 BLAS threads).
"""
import argparse
import os
import statistics
import sys
import time

os.environ.setdefault("OPENBLAS_NUM_THREADS", "2")
os.environ.setdefault("OMP_NUM_THREADS", "2")

import numpy as np

try:
    from scipy.interpolate import RBFInterpolator
except ImportError:
    sys.exit(77)


def query(args):
    c = np.load(args.centres).astype(np.float64, copy=False)
    v = np.load(args.values).astype(np.float64, copy=False)
    q = np.load(args.queries).astype(np.float64, copy=False)
    if c.ndim != 2 or c.shape[1] != 3 or v.shape != c.shape or q.ndim != 2 or q.shape[1] != 3:
        sys.exit(f"rbf_peer: expected N x 3 centres and values, M x 3 queries; got {c.shape}, {v.shape}, {q.shape}")
    f = RBFInterpolator(c, v, kernel="gaussian", epsilon=args.epsilon, degree=args.degree)
    np.save(args.out, np.ascontiguousarray(f(q), dtype=np.float64))


def bench(args):
    rng = np.random.default_rng(0)
    c = rng.random((args.n, 3))
    v = rng.standard_normal((args.n, 3))
    q = rng.random((args.m, 3))
    eps = 1.0 / (args.n ** (-1.0 / 3.0))  # sigma = mean spacing
    fits, evals = [], []
    for r in range(args.repeats + 1):
        t0 = time.perf_counter()
        f = RBFInterpolator(c, v, kernel="gaussian", epsilon=eps, degree=0)
        t1 = time.perf_counter()
        f(q)
        t2 = time.perf_counter()
        if r:
            fits.append(t1 - t0)
            evals.append(t2 - t1)
    print(f"scipy RBFInterpolator gaussian N={args.n} M={args.m}: fit median {statistics.median(fits):.3f} s "
          f"(min {min(fits):.3f}), evaluate median {statistics.median(evals):.3f} s (min {min(evals):.3f})")


def main():
    p = argparse.ArgumentParser()
    p.add_argument("--centres")
    p.add_argument("--values")
    p.add_argument("--queries")
    p.add_argument("--epsilon", type=float)
    p.add_argument("--degree", type=int, default=0)
    p.add_argument("--out")
    p.add_argument("--bench", action="store_true")
    p.add_argument("--n", type=int, default=4000)
    p.add_argument("--m", type=int, default=9000)
    p.add_argument("--repeats", type=int, default=3)
    args = p.parse_args()
    bench(args) if args.bench else query(args)


if __name__ == "__main__":
    main()
