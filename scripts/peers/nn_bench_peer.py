#!/usr/bin/python3
"""PyTorch peer timings beside benchmarks/bench_nn.cpp (the network, profile `official`).

    env -u OPENBLAS_CORETYPE -u OPENBLAS_L2_SIZE /usr/bin/python3 scripts/peers/nn_bench_peer.py \
        [--data-dir ../shared/data/bunny] [--repeats 5] [--slow-repeats 2] [--threads 2]
        [--only forward,train_mode,train_step]

Runs scripts/peers/official_model.py (OfficialSuperRes, official_loss) on this CPU with
torch.set_num_threads(--threads) and prints the median and min of `--repeats` timed runs after
one warm-up (`--slow-repeats` for the cases that run f_theta over the 712,740 upsampling queries,
which take minutes with this torch build):
  * forward at the paper's sizes (N = 15,872 LR, M = 35,637 HR vertices, upK = 20, B = 1),
    model.eval() under torch.no_grad(), on the synthetic geometry of bench_nn.cpp (built here with
    numpy/scipy: a jittered 32 x 31 x 16 lattice inside a Fibonacci ellipsoid, LR graph = 5 nearest
    LR vertices with self first, up_indices = 20 nearest LR vertices of each HR vertex with their
    Euclidean distances), in three variants:
      - official:            the upsampling weights recomputed by f_theta at every forward (what
                             the official model.py does; M*upK = 712,740 queries through 8 layers);
      - precomputed, gather: weights computed once (as simsr's prepare_inference), then the
                             official gather sum_i w_i z[idx_i] per forward;
      - precomputed, sparse: weights computed once into an M x N CSR matrix, z_H = W @ z
                             (the form simsr's infer() computes);
  * forward in train mode at the same sizes (B = 1, BatchNorm on batch statistics, f_theta run);
  * one training step on the bunny (official config: knn 5, upK 10), B = 32 and B = 8 frames of
    train_frames.npz normalized as dataset.py: model.train(), forward, official_loss,
    optimizer.zero_grad(), backward, Adam step (lr 2e-4).
Exits 77 when torch is missing. Run it with OPENBLAS_CORETYPE/OPENBLAS_L2_SIZE unset (they pin
OpenBLAS to a slower kernel on this machine).
"""
import argparse
import os
import sys
import time

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import official_model as om  # noqa: E402
from timing import report, timed  # noqa: E402

N_LR, N_HR, UPK = 15872, 35637, 20


def paper_geometry(knn=5, upk=UPK):
    """The synthetic geometry of benchmarks/bench_nn.cpp (same formulas)."""
    from scipy.spatial import cKDTree

    nx, ny, nz, h = 32, 31, 16, 0.03
    k, j, i = np.meshgrid(np.arange(nz), np.arange(ny), np.arange(nx), indexing="ij")
    v = (i + nx * (j + ny * k)).ravel().astype(np.float64)
    base = np.stack([(i.ravel() - 0.5 * (nx - 1)) * h, (j.ravel() - 0.5 * (ny - 1)) * h, (k.ravel() - 0.5 * (nz - 1)) * h], axis=1)
    c = np.arange(3, dtype=np.float64)
    lr = base + 0.2 * h * np.sin(1.7 * v[:, None] + 2.3 * c[None, :] + 0.5 * c[None, :] ** 2)
    s = np.sqrt(3.0) * 1.05
    axes = np.array([s * 0.5 * (nx - 1) * h, s * 0.5 * (ny - 1) * h, s * 0.5 * (nz - 1) * h])
    golden = np.pi * (3.0 - np.sqrt(5.0))
    jj = np.arange(N_HR, dtype=np.float64)
    z = 1.0 - (2.0 * jj + 1.0) / N_HR
    r = np.sqrt(1.0 - z * z)
    phi = golden * jj
    hr = np.stack([axes[0] * r * np.cos(phi), axes[1] * r * np.sin(phi), axes[2] * z], axis=1)
    tree = cKDTree(lr)
    _, graph = tree.query(lr, k=knn)
    dist, up = tree.query(hr, k=upk)
    return lr, hr, graph.astype(np.int64), up.astype(np.int64), dist.astype(np.float64)


def encode(model, ldx):
    B = ldx.shape[0]
    h0 = torch.cat((ldx, model.pos_emb.unsqueeze(0).expand(B, -1, -1)), dim=-1)
    return torch.cat((h0, model.net_feat_emb(h0)), dim=-1)


def paper_model(train):
    """The official network at the paper's sizes (upK 20) and one seeded input frame (B = 1)."""
    lr, hr, graph, up, dist = paper_geometry()
    torch.manual_seed(0)
    model = om.OfficialSuperRes(lr, hr, graph, up, dist, dict(om.OFFICIAL_CONFIG, upK=UPK))
    model.train(train)
    gen = torch.Generator().manual_seed(7)
    return model, 0.3 * torch.randn(1, N_LR, 3, generator=gen)


def bench_forward(args):
    model, ldx = paper_model(train=False)
    idx = model.net_upscale.indices
    with torch.no_grad():
        report("forward paper size, official (f_theta every call)", timed(lambda: model(ldx), args.slow_repeats))
        w = model.net_upscale.weights(1)[0, :, :, 0].contiguous()  # (M, K), computed once

        def gather():
            z = encode(model, ldx)
            zh = (w[None, :, :, None] * z[:, idx, :]).sum(dim=2)
            return model.net_decoder(zh)

        report("forward paper size, precomputed weights + gather", timed(gather, args.repeats))
        rows = torch.arange(N_HR).repeat_interleave(UPK)
        W = torch.sparse_coo_tensor(torch.stack([rows, idx.reshape(-1)]), w.reshape(-1), (N_HR, N_LR)).coalesce().to_sparse_csr()

        def sparse():
            z = encode(model, ldx)
            zh = (W @ z[0]).unsqueeze(0)
            return model.net_decoder(zh)

        report("forward paper size, precomputed weights + sparse CSR", timed(sparse, args.repeats))
        t = time.perf_counter()
        model.net_upscale.weights(1)
        print(f"  (f_theta alone, once: {1e3 * (time.perf_counter() - t):.1f} ms)", flush=True)


def bench_train_mode(args):
    model, ldx = paper_model(train=True)
    report("forward paper size, train mode (autograd on), B=1", timed(lambda: model(ldx), args.slow_repeats))


def bench_train_step(args):
    model, data = om.build_bunny_model(args.data_dir, 0)
    optimizer, _ = model.make_optimizer()
    lows, highs, _ = om.bunny_frames(args.data_dir, 32)
    for B in (32, 8):
        ldx = om.displacements(lows[:B], data["lr_rest"])
        hdx = om.displacements(highs[:B], data["hr_rest"])

        def step():
            model.train()
            pred = model(ldx)
            losses = om.official_loss(pred, hdx, model.z, model.hr_rest_n, data["hr_faces"], model.cfg)
            optimizer.zero_grad()
            losses["total"].backward()
            optimizer.step()
            return losses["total"].item()

        report(f"train step bunny (official config), B={B}", timed(step, args.repeats))


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--data-dir", default=om.DEFAULT_DATA_DIR)
    ap.add_argument("--repeats", type=int, default=5)
    ap.add_argument("--slow-repeats", type=int, default=2)
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--only", default="forward,train_mode,train_step")
    args = ap.parse_args(argv)
    if om.torch is None:
        print("nn_bench_peer.py: torch is not importable by %s" % sys.executable, file=sys.stderr)
        return 77
    global torch
    torch = om.torch
    torch.set_num_threads(args.threads)
    print(f"torch {torch.__version__}, {torch.get_num_threads()} threads, load average {os.getloadavg()}", flush=True)
    parts = args.only.split(",")
    if "forward" in parts:
        bench_forward(args)
    if "train_mode" in parts:
        bench_train_mode(args)
    if "train_step" in parts:
        bench_train_step(args)
    return 0


if __name__ == "__main__":
    sys.exit(main())
