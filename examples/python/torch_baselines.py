#!/usr/bin/env python3
"""simsr's interpolators as baselines inside a PyTorch training script (issue #15).

A small PyTorch model learns the bunny's LR -> HR displacement map (the paper authors' frames,
../shared/data/bunny) as a residual over simsr's Embedded interpolation, and after every few
epochs the held-out frames go through simsr's baselines (Embedded, IDW, MLS, ridge regression)
beside it: the table a paper's ablation prints.

The tensors cross into simsr without copies. ``tensor.numpy()`` of a CPU tensor and
``torch.from_numpy(array)`` share one buffer; simsr's ``apply`` reads a C-contiguous float64
``(N, 3)`` frame in place and writes its result into ``out=``, here a frame of a torch tensor's
storage. The script asserts both (the buffers' addresses), so it fails rather than copy quietly.
DLPack is not used: for CPU tensors it gives the same shared buffer ``.numpy()`` does.

    /usr/bin/python3 examples/python/torch_baselines.py --data ../shared/data/bunny --epochs 40

Needs the module (PYTHONPATH=<build>/python or installed) and Debian's python3-torch.
"""
import argparse
import pathlib
import time

import numpy as np
import torch

import simsr


def same_buffer(array, tensor):
    """True when the NumPy array and the torch tensor start at the same address (no copy)."""
    return array.__array_interface__["data"][0] == tensor.data_ptr()


def apply_frames(method, lr_frames, out):
    """HR displacements of every LR frame (F, N, 3) into `out` (F, M, 3), both torch float64
    tensors, through simsr's apply: each frame read and written in place."""
    lr_np, out_np = lr_frames.numpy(), out.numpy()
    assert same_buffer(lr_np, lr_frames) and same_buffer(out_np, out), "a tensor was copied on its way to NumPy"
    for f in range(lr_np.shape[0]):
        method.apply(lr_np[f], out=out_np[f])
    return out


def mean_error(pred, truth):
    """Mean per-vertex Euclidean distance over frames (the paper's Table 1 measure)."""
    return (pred - truth).norm(dim=-1).mean().item()


class LowRankResidual(torch.nn.Module):
    """LR displacements (N, 3) -> a correction of Embedded's HR displacements (M, 3): two linear
    maps through a `rank`-wide tanh layer (a linear map of the whole frame, kept small)."""

    def __init__(self, n, m, rank):
        super().__init__()
        self.encode = torch.nn.Linear(3 * n, rank)
        self.decode = torch.nn.Linear(rank, 3 * m)
        torch.nn.init.zeros_(self.decode.weight)  # starts at Embedded itself
        torch.nn.init.zeros_(self.decode.bias)
        self.m = m

    def forward(self, lr):
        return self.decode(torch.tanh(self.encode(lr.flatten(1)))).view(-1, self.m, 3)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--data", type=pathlib.Path, default=pathlib.Path(__file__).resolve().parents[3] / "shared" / "data" / "bunny")
    ap.add_argument("--epochs", type=int, default=40)
    ap.add_argument("--eval-every", type=int, default=10)
    ap.add_argument("--rank", type=int, default=64)
    ap.add_argument("--holdout", type=float, default=0.25, help="fraction of frames held out, the last ones (a contiguous stretch, not every n-th)")
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--seed", type=int, default=0)
    args = ap.parse_args()
    torch.set_num_threads(args.threads)
    torch.manual_seed(args.seed)

    lr_mesh, hr_mesh = simsr.read_mesh(args.data / "lrestshape.obj"), simsr.read_mesh(args.data / "hrestshape.obj")
    problem = simsr.UpsamplingProblem(simsr.TetMesh(lr_mesh.V, lr_mesh.T), simsr.TriMesh(hr_mesh.V, hr_mesh.F))
    frames = simsr.read_paired_frames(args.data / "train_frames.npz")
    disp = simsr.displacements(frames, lr_mesh.V, hr_mesh.V)
    # the PairedFrames' arrays are views into simsr's storage; from_numpy shares them too
    lr_all, hr_all = torch.from_numpy(disp.lowres), torch.from_numpy(disp.highres)
    assert same_buffer(disp.lowres, lr_all) and same_buffer(disp.highres, hr_all)
    F = lr_all.shape[0]
    n_test = max(1, int(round(args.holdout * F)))
    train, test = slice(0, F - n_test), slice(F - n_test, F)
    print(f"bunny: N = {problem.num_lr} LR vertices, M = {problem.num_hr} HR vertices, {F - n_test} training and {n_test} held-out frames")

    t0 = time.perf_counter()
    embedded = simsr.Embedded()
    embedded.fit(problem)
    baselines = {"Embedded": embedded, "IDW": simsr.IDW(), "MLS": simsr.MLS(), "ridge": simsr.Ridge()}
    for name, method in baselines.items():
        if name != "Embedded":
            method.fit(problem)
    train_disp = simsr.PairedFrames(disp.lowres[train], disp.highres[train])
    baselines["ridge"].train(train_disp)
    print(f"simsr: baselines fitted in {time.perf_counter() - t0:.1f} s")

    # Embedded's HR displacements of every frame: the residual model's base, written by simsr
    # straight into a torch tensor
    base = apply_frames(embedded, lr_all, torch.empty_like(hr_all))
    pred = torch.empty_like(hr_all[test])
    errors = {name: mean_error(apply_frames(m, lr_all[test].contiguous(), pred), hr_all[test]) for name, m in baselines.items()}

    model = LowRankResidual(problem.num_lr, problem.num_hr, args.rank).double()
    opt = torch.optim.Adam(model.parameters(), lr=1e-3)
    x_train, y_train = lr_all[train], (hr_all[train] - base[train])
    batch = 16
    history = []
    for epoch in range(1, args.epochs + 1):
        order = torch.randperm(x_train.shape[0])
        total = 0.0
        for s in range(0, len(order), batch):
            idx = order[s:s + batch]
            opt.zero_grad()
            loss = (model(x_train[idx]) - y_train[idx]).norm(dim=-1).mean()
            loss.backward()
            opt.step()
            total += loss.item() * len(idx)
        if epoch % args.eval_every == 0 or epoch == args.epochs:
            with torch.no_grad():
                held_out = mean_error(base[test] + model(lr_all[test]), hr_all[test])
            history.append((epoch, total / len(order), held_out))
            print(f"epoch {epoch:4d}: training error {total / len(order):.3e}, held-out {held_out:.3e} "
                  f"({held_out / errors['Embedded']:.3f} x Embedded)")

    errors["torch residual"] = history[-1][2]
    print("\nheld-out mean vertex error (bunny units), lower is better:")
    for name, e in sorted(errors.items(), key=lambda kv: kv[1]):
        print(f"  {name:15s} {e:.4e}   {e / errors['Embedded']:.3f} x Embedded")
    # what the example stands for: the learned residual improves on the interpolation it starts from
    assert history[-1][2] < errors["Embedded"], "the torch residual did not improve on Embedded"


if __name__ == "__main__":
    main()
