#!/usr/bin/python3
"""Reference peer for simsr::neighbors (run with Debian's /usr/bin/python3: numpy, scipy, torch).

Query mode (used by tests/neighbors/test_kd_tree.cpp):
    knn_peer.py --points P.npy --queries Q.npy --k K --indices I.npy --distances D.npy
runs scipy.spatial.cKDTree(P).query(Q, k) and writes indices (int64, Q x k) and Euclidean
distances (float64, Q x k).

Bench mode (peer timings beside benchmarks/bench_neighbors.cpp, same sizes as the paper):
    env -u OPENBLAS_CORETYPE -u OPENBLAS_L2_SIZE /usr/bin/python3 knn_peer.py --bench
  * cKDTree build on 15,872 uniform points and query of 35,637 points, k = 20, workers = 2;
  * torch.cdist + topk for N = 15,872 features of D = 64, k = 5 (self included), float32,
    torch.set_num_threads(2), queries in blocks of 2,048 rows so no N x N matrix is held (and
    once with the full N x N matrix, DGCNN's form), plus numpy on OpenBLAS with the same blocks.
Prints the median and min of `--repeats` timed runs after one warm-up.
"""
import argparse
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from timing import report, timed  # noqa: E402


def query(args):
    from scipy.spatial import cKDTree

    points = np.load(args.points).astype(np.float64, copy=False)
    queries = np.load(args.queries).astype(np.float64, copy=False)
    if points.ndim != 2 or points.shape[1] != 3 or queries.ndim != 2 or queries.shape[1] != 3:
        sys.exit(f"knn_peer: expected N x 3 arrays, got {points.shape} and {queries.shape}")
    dist, idx = cKDTree(points).query(queries, k=[i + 1 for i in range(args.k)])
    np.save(args.indices, np.ascontiguousarray(idx, dtype=np.int64))
    np.save(args.distances, np.ascontiguousarray(dist, dtype=np.float64))


def bench(args):
    from scipy.spatial import cKDTree

    rng = np.random.default_rng(0)
    n_lr, n_hr, dim = 15872, 35637, 64
    points = rng.uniform(-1, 1, (n_lr, 3))
    queries = rng.uniform(-1, 1, (n_hr, 3))
    report("scipy cKDTree build 15872", timed(lambda: cKDTree(points), args.repeats))
    tree = cKDTree(points)
    report("scipy cKDTree query 35637 k=20 workers=2", timed(lambda: tree.query(queries, k=20, workers=2), args.repeats))
    report("scipy cKDTree query 35637 k=20 workers=1", timed(lambda: tree.query(queries, k=20, workers=1), args.repeats))

    import torch

    torch.set_num_threads(2)
    feats = torch.from_numpy(rng.standard_normal((n_lr, dim)).astype(np.float32))
    block = 2048

    def cdist_topk():
        out_d = torch.empty((n_lr, 5))
        out_i = torch.empty((n_lr, 5), dtype=torch.int64)
        for q0 in range(0, n_lr, block):
            d = torch.cdist(feats[q0:q0 + block], feats)
            vals, idx = torch.topk(d, 5, dim=1, largest=False)
            out_d[q0:q0 + block] = vals
            out_i[q0:q0 + block] = idx
        return out_d, out_i

    report(f"torch cdist+topk N=15872 D=64 k=5 threads=2 ({torch.__version__})", timed(cdist_topk, args.repeats))

    def cdist_full():  # DGCNN's reference form: the whole N x N matrix at once
        d = torch.cdist(feats, feats)
        return torch.topk(d, 5, dim=1, largest=False)

    report("torch cdist+topk N=15872 D=64 k=5, full N x N", timed(cdist_full, max(1, args.repeats // 2)))

    # numpy on OpenBLAS: the same blocked |a|^2 + |b|^2 - 2 a.b with argpartition (the GEMM
    # speed this machine's BLAS reaches; Debian's torch 1.13 matmul runs far below it here).
    f = feats.numpy()
    norms = (f * f).sum(1)

    def numpy_blocked():
        out = np.empty((n_lr, 5), dtype=np.int64)
        for q0 in range(0, n_lr, block):
            d = norms[q0:q0 + block, None] + norms[None, :] - 2 * (f[q0:q0 + block] @ f.T)
            part = np.argpartition(d, 5, axis=1)[:, :5]
            order = np.argsort(np.take_along_axis(d, part, 1), axis=1)
            out[q0:q0 + block] = np.take_along_axis(part, order, 1)
        return out

    report("numpy/OpenBLAS blocked GEMM+argpartition N=15872 D=64 k=5", timed(numpy_blocked, args.repeats))


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--bench", action="store_true", help="time scipy and torch peers at the paper's sizes")
    ap.add_argument("--repeats", type=int, default=7)
    ap.add_argument("--points")
    ap.add_argument("--queries")
    ap.add_argument("--k", type=int)
    ap.add_argument("--indices")
    ap.add_argument("--distances")
    args = ap.parse_args()
    if args.bench:
        bench(args)
    else:
        if None in (args.points, args.queries, args.k, args.indices, args.distances):
            ap.error("query mode needs --points --queries --k --indices --distances")
        query(args)


if __name__ == "__main__":
    main()
