#!/usr/bin/python3
"""`simsr train` / `simsr infer` / `simsr eval` end to end on a small synthetic pair (issue #4 item 5).

    /usr/bin/python3 tests/cli/test_cli_nn.py SIMSR_EXE [WORK_DIR]

An LR tet box (MEDIT .mesh, 4x4x4 vertices, 6 tets per cube) and an HR surface (OBJ, the boundary
of a 7x7x7 grid of the same box) deform with a smooth random map per frame (F = 12 frames, ids
100..111). Checks: the JSON of train (counts, steps, held-out error against Embedded), the
history files, the model file's contents, resuming from a checkpoint gives the identical model,
infer writes highres F×M×3 with the frame ids and seconds_per_frame, eval agrees with infer's
error statistics, a seed fixes the run, and bad input exits with the documented codes.
Exit 0 pass, 1 fail, 77 skip (no numpy); with SIMSR_REQUIRE_PEERS=1 (CI) a missing peer exits 1.
"""
import json
import os
import subprocess
import sys
import tempfile

try:
    import numpy as np
except ImportError as e:
    print("MISSING (a failure under SIMSR_REQUIRE_PEERS=1, a skip otherwise): %s" % e)
    sys.exit(1 if os.environ.get("SIMSR_REQUIRE_PEERS", "0") not in ("", "0") else 77)

FAILURES = []


def check(cond, what):
    print(("ok   " if cond else "FAIL ") + what)
    if not cond:
        FAILURES.append(what)
    return cond


def run(exe, args, expect=0):
    p = subprocess.run([exe] + args, capture_output=True, text=True, env=dict(os.environ, OMP_NUM_THREADS="2"))
    if p.returncode != expect:
        print("  %s -> rc %d (expected %d)\n  stdout: %s\n  stderr: %s" % (" ".join(args), p.returncode, expect, p.stdout[-1500:], p.stderr[-1500:]))
    return p


def grid(n):
    g = np.linspace(0.0, 1.0, n)
    x, y, z = np.meshgrid(g, g, g, indexing="ij")
    return np.stack([x.ravel(), y.ravel(), z.ravel()], axis=1)


def box_tets(n):
    """Freudenthal split of each cube of an n^3 vertex grid into 6 positive tets."""
    vid = np.arange(n ** 3).reshape(n, n, n)
    tets = []
    for i in range(n - 1):
        for j in range(n - 1):
            for k in range(n - 1):
                c = [vid[i + a, j + b, k + d] for a in (0, 1) for b in (0, 1) for d in (0, 1)]  # index = 4a+2b+d
                v0, v7 = c[0], c[7]
                for p, q in ((4, 6), (6, 2), (2, 3), (3, 1), (1, 5), (5, 4)):
                    tets.append([v0, c[p], c[q], v7])
    T = np.array(tets)
    V = grid(n)
    vol = np.einsum("ij,ij->i", np.cross(V[T[:, 1]] - V[T[:, 0]], V[T[:, 2]] - V[T[:, 0]]), V[T[:, 3]] - V[T[:, 0]])
    T[vol < 0] = T[vol < 0][:, [0, 2, 1, 3]]
    return V, T


def box_surface(n):
    """Boundary vertices and outward-agnostic triangles of an n^3 grid's box (2 per square)."""
    V = grid(n)
    on = np.any((V == 0) | (V == 1), axis=1)
    new = -np.ones(len(V), dtype=int)
    new[on] = np.arange(on.sum())
    vid = np.arange(n ** 3).reshape(n, n, n)
    tris = []
    for axis in range(3):
        for side in (0, n - 1):
            sl = [slice(None)] * 3
            sl[axis] = side
            face = vid[tuple(sl)]
            for a in range(n - 1):
                for b in range(n - 1):
                    q = [face[a, b], face[a + 1, b], face[a + 1, b + 1], face[a, b + 1]]
                    tris += [[q[0], q[1], q[2]], [q[0], q[2], q[3]]]
    return V[on], new[np.array(tris)]


def deform(X, A, w):
    return X + X @ A.T + 0.02 * np.sin(3.0 * X[:, [1, 2, 0]] + w)


def write_mesh(path, V, T):
    with open(path, "w") as f:
        f.write("MeshVersionFormatted 2\nDimension 3\nVertices\n%d\n" % len(V))
        for v in V:
            f.write("%.17g %.17g %.17g 0\n" % tuple(v))
        f.write("Tetrahedra\n%d\n" % len(T))
        for t in T:
            f.write("%d %d %d %d 0\n" % tuple(t + 1))
        f.write("End\n")


def write_obj(path, V, F):
    with open(path, "w") as f:
        for v in V:
            f.write("v %.17g %.17g %.17g\n" % tuple(v))
        for t in F:
            f.write("f %d %d %d\n" % tuple(t + 1))


def write_box_pair(work, n_lr, n_hr, frames, seed, **extra):
    """work/lr.mesh (n_lr^3 LR tet box), work/hr.obj (n_hr^3 grid boundary), work/frames.npz:
    `frames` frames of a smooth random map (lowres, highres, plus the `extra` arrays).
    Returns (lrV, lrT, hrV, hrF, low, high)."""
    lrV, lrT = box_tets(n_lr)
    hrV, hrF = box_surface(n_hr)
    write_mesh(os.path.join(work, "lr.mesh"), lrV, lrT)
    write_obj(os.path.join(work, "hr.obj"), hrV, hrF)
    rng = np.random.default_rng(seed)
    low, high = [], []
    for _ in range(frames):
        A, w = 0.05 * rng.standard_normal((3, 3)), rng.uniform(0, 6, 3)
        low.append(deform(lrV, A, w))
        high.append(deform(hrV, A, w))
    low, high = np.array(low), np.array(high)
    np.savez(os.path.join(work, "frames.npz"), lowres=low, highres=high, **extra)
    return lrV, lrT, hrV, hrF, low, high


def main():
    if len(sys.argv) < 2:
        print("usage: test_cli_nn.py SIMSR_EXE [WORK_DIR]")
        return 2
    exe = sys.argv[1]
    work = sys.argv[2] if len(sys.argv) > 2 else tempfile.mkdtemp(prefix="simsr_cli_nn_")
    os.makedirs(work, exist_ok=True)
    P = lambda *a: os.path.join(work, *a)  # noqa: E731

    F = 12
    ids = np.arange(100, 100 + F, dtype=np.int64)
    lrV, lrT, hrV, hrF, low, high = write_box_pair(work, 4, 7, F, 5, frame=ids)
    N, M = len(lrV), len(hrV)

    base = ["train", "--lr-rest", P("lr.mesh"), "--hr-rest", P("hr.obj"), "--frames", P("frames.npz"), "--knn", "3", "--upk", "4",
            "--batch-size", "4", "--seed", "3", "--quiet"]
    p = run(exe, base + ["--epochs", "2", "--out", P("m.npz"), "--out-dir", P("hist")])
    if not check(p.returncode == 0, "train exits 0"):
        return 1
    j = json.loads(p.stdout)
    check(j["parameters"] == 706871, "official network: 706,871 parameters")
    check(j["train_frames"] == 9 and j["holdout_frames"] == 3, "frames f %% 4 == 0 held out: 9 train, 3 held out")
    check(j["epochs"] == 2 and j["steps"] == 6, "2 epochs of ceil(9/4) = 3 steps")
    check(j["holdout_mean_error"] > 0 and j["embedded_relative_mean_error"] > 0, "held-out error and the Embedded baseline reported")
    # the default recipe scales displacements so that the training frames' normalized HR displacement has RMS 1
    sigma = 0.5 * (0.04998 + 0.05092)
    trained_rows = [i for i in range(F) if ids[i] % 4 != 0]
    rms = np.sqrt(np.mean((high[trained_rows] - hrV[None]) ** 2)) / sigma
    check(abs(j["displacement_scale"] * rms - 1) < 1e-5, "default displacement scale: 1 / RMS of the training frames' normalized HR displacement")
    hist = open(P("hist", "training_history.csv")).read().strip().splitlines()
    check(len(hist) == 3 and hist[0].startswith("epoch,steps,loss"), "training_history.csv: header + one row per epoch")
    check(os.path.getsize(P("hist", "training_loss.svg")) > 500 and os.path.getsize(P("hist", "holdout_error.svg")) > 500, "SVG plots written")
    m = np.load(P("m.npz"))
    cfg = json.loads(str(m["config"]))
    check(cfg["knn"] == 3 and cfg["upK"] == 4 and cfg["profile"] == "official", "config JSON records knn, upK, profile")
    check(m["net_feat_emb.blocks.0.edge_conv.0.weight"].shape == (128, 70, 1, 1) and m["net_feat_emb.blocks.0.edge_conv.0.weight"].dtype == np.float32,
          "state tensors under PyTorch names, shapes and float32")
    check(m["net_upscale.conv_weights.1.num_batches_tracked"].dtype == np.int64 and m["net_upscale.conv_weights.1.num_batches_tracked"] == 6,
          "num_batches_tracked int64, one per step")
    check(m["lr_rest"].shape == (N, 3) and m["hr_faces"].shape == (len(hrF), 3) and m["up_indices"].shape == (M, 4) and m["lr_graph"].shape == (N, 3),
          "model file holds rest shapes, faces and neighbourhoods")

    # --eval-every 2: the held-out frames evaluated at epochs 2 and 3 (the last) only; the weights as evaluated every epoch
    p = run(exe, base + ["--epochs", "3", "--eval-every", "2", "--out", P("e2.npz"), "--out-dir", P("hist_e2")])
    p1 = run(exe, base + ["--epochs", "3", "--out", P("e1.npz")])
    if check(p.returncode == 0 and p1.returncode == 0, "train --eval-every 2 exits 0"):
        rows = [r.split(",") for r in open(P("hist_e2", "training_history.csv")).read().strip().splitlines()[1:]]
        check([r[10] != "" for r in rows] == [False, True, True], "--eval-every 2: held-out error at epochs 2 and 3 (the last), none at 1")
        check(json.loads(p.stdout)["holdout_mean_error"] == json.loads(p1.stdout)["holdout_mean_error"], "the last epoch's held-out error as with --eval-every 1")
        e1, e2 = np.load(P("e1.npz")), np.load(P("e2.npz"))
        check(all(np.array_equal(e1[k], e2[k]) for k in e1.files if k.startswith("net_")), "evaluating less often changes no weight")
    check(run(exe, base + ["--epochs", "1", "--eval-every", "-1", "--out", P("x.npz")], 64).returncode == 64, "train: --eval-every -1 refused (usage error)")

    # the same seed gives the same model; resuming a checkpoint continues identically
    p1 = run(exe, base + ["--epochs", "1", "--out", P("m1.npz"), "--checkpoint", P("c1.npz")])
    p2 = run(exe, base + ["--epochs", "2", "--resume", P("c1.npz"), "--out", P("m2.npz")])
    if check(p1.returncode == 0 and p2.returncode == 0, "train with --checkpoint, then --resume, exit 0"):
        m2 = np.load(P("m2.npz"))
        same = all(np.array_equal(m[k], m2[k]) for k in m.files if k.startswith("net_"))
        check(same, "resumed model == uninterrupted model, bit for bit")
        check(json.loads(p2.stdout)["steps"] == 6, "resumed run reports the total step count")
    # a checkpoint written before the first step resumes too; another run's checkpoint is refused, naming what differs
    p0 = run(exe, base + ["--epochs", "0", "--out", P("m0.npz"), "--checkpoint", P("c0.npz")])
    p4 = run(exe, base + ["--epochs", "2", "--resume", P("c0.npz"), "--out", P("m4.npz")])
    if check(p0.returncode == 0 and p4.returncode == 0, "train --epochs 0 --checkpoint, then --resume, exit 0"):
        m4 = np.load(P("m4.npz"))
        check(all(np.array_equal(m[k], m4[k]) for k in m.files if k.startswith("net_")), "resumed from step 0 == uninterrupted model")
    p = run(exe, base[:-3] + ["--seed", "9", "--quiet", "--epochs", "2", "--resume", P("c1.npz"), "--out", P("x.npz")], 5)
    check(p.returncode == 5 and "seed (checkpoint 3, this run 9)" in p.stderr, "train --resume with another seed exits 5 naming the seed")
    changed = dict(np.load(P("frames.npz")))
    changed["highres"] = changed["highres"] * 1.001
    np.savez(P("frames_changed.npz"), **changed)
    other = [x if x != P("frames.npz") else P("frames_changed.npz") for x in base]
    p = run(exe, other + ["--epochs", "2", "--resume", P("c1.npz"), "--out", P("x.npz")], 5)
    check(p.returncode == 5 and "training_fingerprint" in p.stderr, "train --resume on other frames exits 5 naming the data")
    bs3 = [x if x != "4" or base[i - 1] != "--batch-size" else "3" for i, x in enumerate(base)]
    p = run(exe, bs3 + ["--epochs", "2", "--resume", P("c1.npz"), "--out", P("x.npz")], 5)
    check(p.returncode == 5 and "batch_size (checkpoint 4, this run 3)" in p.stderr, "train --resume with another batch size exits 5 naming it")
    p3 = run(exe, base[:-3] + ["--seed", "4", "--quiet", "--epochs", "2", "--out", P("m3.npz")])
    if check(p3.returncode == 0, "train with another seed"):
        m3 = np.load(P("m3.npz"))
        check(not np.array_equal(m["net_decoder.decoder.last_layer.fc.weight"], m3["net_decoder.decoder.last_layer.fc.weight"]),
              "another seed gives other weights")

    # inference
    p = run(exe, ["infer", "--model", P("m.npz"), "--frames", P("frames.npz"), "--out", P("pred.npz")])
    if check(p.returncode == 0, "infer exits 0"):
        ji = json.loads(p.stdout)
        check(ji["seconds_per_frame"] > 0 and ji["frames"] == F, "infer reports seconds_per_frame and the frame count")
        o = np.load(P("pred.npz"))
        check(o["highres"].shape == (F, M, 3) and o["highres"].dtype == np.float64, "highres F×M×3 float64")
        check(np.array_equal(o["frame"], ids), "frame ids copied")
        check(np.isfinite(o["highres"]).all(), "predictions finite")
        err = np.linalg.norm(o["highres"] - high, axis=2)
        check(abs(err.mean() - ji["error"]["mean"]) < 1e-12 * max(1.0, err.mean()), "infer's error mean = numpy's")
        pe = run(exe, ["eval", "--pred", P("pred.npz"), "--truth", P("frames.npz"), "--hr-rest", P("hr.obj")])
        if check(pe.returncode == 0, "eval of infer's output exits 0"):
            check(abs(json.loads(pe.stdout)["error"]["mean"] - ji["error"]["mean"]) < 1e-12, "eval agrees with infer")
    # bad input
    np.savez(P("bad_n.npz"), lowres=np.zeros((2, N + 1, 3)))
    check(run(exe, ["infer", "--model", P("m.npz"), "--frames", P("bad_n.npz"), "--out", P("x.npz")], 4).returncode == 4, "infer: wrong N exits 4 (shape)")
    bad = dict(np.load(P("frames.npz")))
    bad["lowres"] = bad["lowres"].copy()
    bad["lowres"][3, 5, 1] = np.nan
    np.savez(P("bad_nan.npz"), **bad)
    check(run(exe, ["infer", "--model", P("m.npz"), "--frames", P("bad_nan.npz"), "--out", P("x.npz")], 5).returncode == 5, "infer: NaN exits 5")
    nan_args = [x if x != P("frames.npz") else P("bad_nan.npz") for x in base]
    check(run(exe, nan_args + ["--epochs", "1", "--out", P("x.npz")], 5).returncode == 5, "train: NaN exits 5")
    arrays = dict(np.load(P("m.npz")))
    del arrays["net_decoder.decoder.last_layer.fc.bias"]
    np.savez(P("bad_model.npz"), **arrays)
    p = run(exe, ["infer", "--model", P("bad_model.npz"), "--frames", P("frames.npz"), "--out", P("x.npz")], 5)
    check(p.returncode == 5 and "last_layer.fc.bias" in p.stderr, "infer: a model without a tensor exits 5 naming it")
    check(run(exe, base + ["--holdout-every", "1", "--out", P("x.npz")], 5).returncode == 5, "train: --holdout-every 1 exits 5")
    # a small model file must not be able to ask for a huge network: the config's bounds and the
    # shapes it implies are checked before anything is allocated
    arrays = dict(np.load(P("m.npz")))
    c = json.loads(str(arrays["config"]))
    c["decoder_dims"] = [c["decoder_dims"][0], 200000, 200000, 3]
    arrays["config"] = np.array(json.dumps(c))
    np.savez(P("huge_model.npz"), **arrays)
    p = run(exe, ["infer", "--model", P("huge_model.npz"), "--frames", P("frames.npz"), "--out", P("x.npz")], 5)
    check(p.returncode == 5 and "decoder_dims = 200000 exceeds the sane bound" in p.stderr, "infer: a config asking for 160 GB exits 5 naming the field")
    c["decoder_dims"][1:3] = [4000, 4000]
    arrays["config"] = np.array(json.dumps(c))
    np.savez(P("wide_model.npz"), **arrays)
    p = run(exe, ["infer", "--model", P("wide_model.npz"), "--frames", P("frames.npz"), "--out", P("x.npz")], 5)
    check(p.returncode == 5 and "the config implies (4000," in p.stderr, "infer: a config its tensors do not match exits 5 naming the tensor")
    arrays = dict(np.load(P("m.npz")))
    arrays["net_decoder.decoder.last_layer.fc.weight"] = arrays["net_decoder.decoder.last_layer.fc.weight"].copy()
    arrays["net_decoder.decoder.last_layer.fc.weight"][1, 2] = np.inf
    np.savez(P("inf_model.npz"), **arrays)
    p = run(exe, ["infer", "--model", P("inf_model.npz"), "--frames", P("frames.npz"), "--out", P("x.npz")], 5)
    check(p.returncode == 5 and "last_layer.fc.weight" in p.stderr and "not finite" in p.stderr, "infer: a non-finite weight exits 5 naming the tensor")
    return 1 if FAILURES else 0


if __name__ == "__main__":
    sys.exit(main())
