#!/usr/bin/python3
"""Checks the PyTorch peer of the `official` network (scripts/peers/official_model.py) and the
checkpoint converter (scripts/torch_to_simsr.py).

    /usr/bin/python3 tests/nn_peers/test_official_model.py [WORK_DIR] [SHARED_DATA_DIR]

WORK_DIR (default: a fresh temporary folder) receives the checkpoint, the converted model and two
fixture exports; SHARED_DATA_DIR (default: ../shared/data beside the repository) holds bunny/.
Exit 0 = pass, 1 = fail, 77 = skipped (no torch/numpy for this interpreter, or no bunny data); with SIMSR_REQUIRE_PEERS=1 (CI) a missing peer exits 1.
"""
import json
import os
import subprocess
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.normpath(os.path.join(HERE, "..", ".."))
PEER = os.path.join(REPO, "scripts", "peers", "official_model.py")
CONVERTER = os.path.join(REPO, "scripts", "torch_to_simsr.py")

try:
    import numpy as np
    import torch
except ImportError as e:
    print("MISSING (a failure under SIMSR_REQUIRE_PEERS=1, a skip otherwise): %s (run with /usr/bin/python3)" % e)
    sys.exit(1 if os.environ.get("SIMSR_REQUIRE_PEERS", "0") not in ("", "0") else 77)

sys.path.insert(0, os.path.dirname(PEER))
import official_model as om  # noqa: E402

torch.set_num_threads(2)
FAILURES = []


def check(cond, what):
    if cond:
        print("ok   " + what)
    else:
        print("FAIL " + what)
        FAILURES.append(what)
    return cond


def run(args, expect_rc=0):
    p = subprocess.run([sys.executable] + args, capture_output=True, text=True)
    if p.returncode != expect_rc:
        print("  command %s -> rc %d\n  stdout: %s\n  stderr: %s" % (" ".join(args), p.returncode, p.stdout[-2000:], p.stderr[-2000:]))
    return p


def expected_entries():
    """The official state dict, written out independently of the peer from the architecture:
    (full name, shape, is_trainable) in PyTorch's order. 2 EdgeConv blocks 35->64->128, upsampling
    8 x 128 + 1, SIREN 227-256-128-64-32-16-3 (+ dead layer) + linear 16->3."""
    out = []

    def bn(prefix, c):
        out.extend([(prefix + ".weight", (c,), True), (prefix + ".bias", (c,), True),
                    (prefix + ".running_mean", (c,), False), (prefix + ".running_var", (c,), False),
                    (prefix + ".num_batches_tracked", (), False)])

    for b, (i, o) in enumerate([(35, 64), (64, 128)]):
        p = "net_feat_emb.blocks.%d." % b
        out.append((p + "edge_conv.0.weight", (2 * o, 2 * i, 1, 1), True))
        bn(p + "edge_conv.1", 2 * o)
        out.append((p + "edge_conv.3.weight", (o, 2 * o, 1, 1), True))
        out.append((p + "fc_out.0.weight", (3 * o, 3 * o + i, 1), True))
        bn(p + "fc_out.1", 3 * o)
        out.append((p + "fc_out.3.weight", (2 * o, 3 * o, 1), True))
        bn(p + "fc_out.4", 2 * o)
        out.append((p + "fc_out.6.weight", (o, 2 * o, 1), True))
        bn(p + "fc_out.7", o)
        out.append((p + "fc_out.9.weight", (o, o, 1), True))
    out += [("net_feat_emb.fc_initial.0.weight", (32, 3), True), ("net_feat_emb.fc_initial.0.bias", (32,), True),
            ("net_feat_emb.fc_initial.2.weight", (32, 32), True), ("net_feat_emb.fc_initial.2.bias", (32,), True)]
    d_in = 7
    for layer in range(8):
        out.append(("net_upscale.conv_weights.%d.weight" % (3 * layer), (128, d_in, 1, 1), True))
        bn("net_upscale.conv_weights.%d" % (3 * layer + 1), 128)
        d_in = 128
    out += [("net_upscale.conv_weights.24.weight", (1, 128, 1, 1), True), ("net_upscale.conv_weights.24.bias", (1,), True)]
    dims = [227, 256, 128, 64, 32, 16, 3]
    for layer in range(6):
        out += [("net_decoder.decoder.layers.%d.fc.weight" % layer, (dims[layer + 1], dims[layer]), True),
                ("net_decoder.decoder.layers.%d.fc.bias" % layer, (dims[layer + 1],), True)]
    out += [("net_decoder.decoder.last_layer.fc.weight", (3, 16), True), ("net_decoder.decoder.last_layer.fc.bias", (3,), True)]
    return out


def npz_dict(path):
    with np.load(path) as z:
        return {k: z[k] for k in z.files}


def test_architecture(data_dir):
    entries = expected_entries()
    n_expected = sum(int(np.prod(s)) for _, s, t in entries if t)
    check(n_expected == 706871, "independent table of the official state dict sums to 706,871 parameters (%d)" % n_expected)
    p = run([PEER, "--count"])
    check(p.returncode == 0 and p.stdout.strip() == "706871", "official_model.py --count prints 706871 (%r)" % p.stdout.strip())
    model, _ = om.build_bunny_model(data_dir, seed=0)
    check(om.count_parameters(model) == 706871, "bunny model has 706,871 parameters")
    sd = om.full_state_dict(model)
    got = [(k, tuple(v.shape)) for k, v in sd.items()]
    want = [(k, s) for k, s, _ in entries]
    check(got == want, "state-dict names, order and shapes equal the official ones")
    if got != want:
        for g, w in zip(got, want):
            if g != w:
                print("  first difference: got %s, want %s" % (g, w))
                break
        print("  got %d entries, want %d" % (len(got), len(want)))
    bounds_ok = True
    dims = [227, 256, 128, 64, 32, 16, 3]
    for layer in range(6):
        bound = (1.0 / dims[layer]) if layer == 0 else (6.0 / dims[layer]) ** 0.5
        for kind in ("weight", "bias"):
            t = sd["net_decoder.decoder.layers.%d.fc.%s" % (layer, kind)]
            bounds_ok &= bool(t.abs().max() <= bound) and bool(t.abs().max() > 0.5 * bound)
    t = sd["net_decoder.decoder.last_layer.fc.weight"]
    bounds_ok &= bool(t.abs().max() <= (6.0 / 16) ** 0.5)
    check(bounds_ok, "SIREN init: U(+-1/fan_in) first layer, U(+-sqrt(6/fan_in)) after")
    pe = model.pos_emb.numpy().astype(np.float64)
    i = np.arange(pe.shape[0])[:, None]
    freq = 10000.0 ** (np.arange(0, 32, 2) / 32.0)
    check(np.allclose(pe[:, 0::2], np.sin(i / freq), atol=2e-4) and np.allclose(pe[:, 1::2], np.cos(i / freq), atol=2e-4),
          "positional encoding = sin/cos(i / 10000^(2m/32))")


def test_converter(work, data_dir):
    ckpt_path = os.path.join(work, "result", "model", "model_latest.pth")
    p = run([PEER, "--make-checkpoint", ckpt_path, "--data-dir", data_dir])
    if not check(p.returncode == 0 and os.path.isfile(ckpt_path), "checkpoint saved as the official train.py does"):
        return
    ckpt = torch.load(ckpt_path, map_location="cpu")
    check(sorted(ckpt) == sorted(["net_feat_emb", "net_upscale", "net_decoder", "optimizer", "scheduler"]),
          "checkpoint keys: net_feat_emb, net_upscale, net_decoder, optimizer, scheduler")
    check(len(ckpt["optimizer"]["state"]) > 0, "checkpoint optimizer state is populated (a training step was taken)")

    out = os.path.join(work, "model.npz")
    p = run([CONVERTER, "--checkpoint", ckpt_path, "--data-dir", data_dir, "--out", out])
    if not check(p.returncode == 0 and os.path.isfile(out), "torch_to_simsr.py converts the checkpoint"):
        return
    z = npz_dict(out)
    ok_all = True
    for name, shape, _ in expected_entries():
        module, key = name.split(".", 1)
        ref = ckpt[module][key].numpy()
        ok = name in z and z[name].shape == shape and z[name].dtype == ref.dtype and np.array_equal(z[name], ref)
        if not ok:
            print("  bad tensor %s: %s" % (name, None if name not in z else (z[name].shape, z[name].dtype)))
        ok_all &= ok
    check(ok_all, "model.npz holds every state-dict tensor with its shape, dtype and values")
    meta = {"config", "lr_rest", "lr_tets", "hr_rest", "hr_faces", "lr_graph", "up_indices", "up_distances", "norm_mean", "norm_std"}
    extra = set(z) - meta - {n for n, _, _ in expected_entries()}
    check(not extra and meta <= set(z), "model.npz has exactly the state dict + %s (extra: %s)" % (sorted(meta), sorted(extra)))

    cfg = json.loads(str(z["config"]))
    check(z["config"].shape == () and z["config"].dtype.kind == "U", "config is a 0-d unicode array")
    want = {"profile": "official", "pos_feat_dim": 32, "emb_feat_dims": [35, 64, 128], "knn": 5, "upK": 10,
            "w_up_feat_dim": 128, "n_upscale_layers": 8, "decoder_dim": 256,
            "decoder_dims": [227, 256, 128, 64, 32, 16, 3], "w0_initial": 30.0, "w0": 1.0, "n_lr": 1747,
            "n_hr": 2503, "parameter_count": 706871}
    bad = {k: cfg.get(k) for k, v in want.items() if cfg.get(k) != v}
    check(not bad, "config parses with the official sizes (mismatches: %s)" % bad)
    check(abs(cfg["norm_mean"] - (-0.00047)) < 1e-12 and abs(cfg["norm_std"] - 0.05045) < 1e-12
          and float(z["norm_mean"]) == cfg["norm_mean"] and float(z["norm_std"]) == cfg["norm_std"],
          "normalization mu = -0.00047, sigma = 0.05045")

    t2t = np.load(os.path.join(data_dir, "geo_dist_tet2tet_idx.npy"))
    s2t_idx = np.load(os.path.join(data_dir, "geo_dist_surf2tet_idx.npy"))
    s2t = np.load(os.path.join(data_dir, "geo_dist_surf2tet.npy"))
    check(z["lr_graph"].dtype == np.int64 and np.array_equal(z["lr_graph"], t2t[:, :5]), "lr_graph = tet2tet_idx[:, :5], int64")
    check(z["up_indices"].dtype == np.int64 and np.array_equal(z["up_indices"], s2t_idx[:, :10])
          and z["up_distances"].dtype == np.float64 and np.array_equal(z["up_distances"], s2t[:, :10]),
          "up_indices / up_distances = surf2tet[:, :10]")
    V, T = z["lr_rest"], z["lr_tets"]
    check(V.shape == (1747, 3) and V.dtype == np.float64 and T.shape == (4896, 4) and T.dtype == np.int64,
          "lr_rest 1747x3 float64, lr_tets 4896x4 int64")
    a, b, c, d = (V[T[:, j]] for j in range(4))
    det = np.einsum("ij,ij->i", b - a, np.cross(c - a, d - a))
    check(bool((det > 0).all()), "every lr tet positively oriented (simsr's soup convention)")
    check(z["hr_rest"].shape == (2503, 3) and z["hr_faces"].shape == (4968, 3) and z["hr_faces"].dtype == np.int64
          and z["hr_faces"].min() == 0 and z["hr_faces"].max() == 2502, "hr_rest 2503x3, hr_faces 4968x3 0-based int64")

    # The file alone rebuilds the network: strict load and the same outputs as the checkpoint.
    cfg_model = {k: cfg[k] for k in om.OFFICIAL_CONFIG}
    m1 = om.OfficialSuperRes(z["lr_rest"], z["hr_rest"], z["lr_graph"], z["up_indices"], z["up_distances"], cfg_model)
    sds = {m: {} for m in ("net_feat_emb", "net_upscale", "net_decoder")}
    for name, _, _ in expected_entries():
        module, key = name.split(".", 1)
        sds[module][key] = torch.from_numpy(z[name])
    m1.load_official_state_dicts(sds, strict=True)
    m2, _ = om.build_bunny_model(data_dir, seed=123)
    m2.load_official_state_dicts(ckpt, strict=True)
    lows, _, _ = om.bunny_frames(data_dir, 1)
    ldx = om.displacements(lows, z["lr_rest"])
    m1.eval()
    m2.eval()
    with torch.no_grad():
        y1, y2 = m1(ldx), m2(ldx)
    check(torch.equal(y1, y2), "model rebuilt from model.npz alone (strict load) = checkpoint model, eval outputs")

    out2 = os.path.join(work, "model_k3_up20.npz")
    p = run([CONVERTER, "--checkpoint", ckpt_path, "--data-dir", data_dir, "--out", out2, "--knn", "3", "--upk", "20"])
    if p.returncode == 0:
        z2 = npz_dict(out2)
        c2 = json.loads(str(z2["config"]))
        check(z2["lr_graph"].shape == (1747, 3) and z2["up_indices"].shape == (2503, 20) and c2["knn"] == 3 and c2["upK"] == 20,
              "--knn 3 --upk 20 are honoured")
    else:
        check(False, "--knn 3 --upk 20 converts")

    broken = dict(ckpt)
    del broken["net_decoder"]
    bad_path = os.path.join(work, "missing_decoder.pth")
    torch.save(broken, bad_path)
    p = run([CONVERTER, "--checkpoint", bad_path, "--data-dir", data_dir, "--out", os.path.join(work, "bad.npz")], expect_rc=1)
    check(p.returncode == 1 and "net_decoder" in p.stderr, "a checkpoint without net_decoder is refused")
    broken = {m: dict(ckpt[m]) for m in ("net_feat_emb", "net_upscale", "net_decoder")}
    broken["net_upscale"]["conv_weights.3.weight"] = torch.zeros(128, 127, 1, 1)
    torch.save(broken, bad_path)
    p = run([CONVERTER, "--checkpoint", bad_path, "--data-dir", data_dir, "--out", os.path.join(work, "bad.npz")], expect_rc=1)
    check(p.returncode == 1, "a checkpoint with a wrongly shaped tensor is refused")


def test_export(work, data_dir):
    dirs = [os.path.join(work, "export_a"), os.path.join(work, "export_b")]
    for d in dirs:
        p = run([PEER, "--export", d, "--data-dir", data_dir])
        if not check(p.returncode == 0, "official_model.py --export %s" % os.path.basename(d)):
            return
    same = True
    for f in ("state_dict.npz", "io.npz"):
        a, b = npz_dict(os.path.join(dirs[0], f)), npz_dict(os.path.join(dirs[1], f))
        if sorted(a) != sorted(b):
            same = False
            print("  %s: different member lists" % f)
            continue
        for k in a:
            if a[k].dtype != b[k].dtype or a[k].shape != b[k].shape or not np.array_equal(a[k], b[k]):
                same = False
                print("  %s: %s differs between runs" % (f, k))
    check(same, "exported fixtures are bitwise identical across two runs")

    sd = npz_dict(os.path.join(dirs[0], "state_dict.npz"))
    io = npz_dict(os.path.join(dirs[0], "io.npz"))
    check(sorted(sd) == sorted(n for n, _, _ in expected_entries())
          and all(sd[n].shape == s for n, s, _ in expected_entries()), "state_dict.npz: every tensor by its full name")
    B, N, M = 2, 1747, 2503
    shapes = {"ldx": (B, N, 3), "hdx": (B, M, 3), "pos_emb": (N, 32), "up_query": (M, 10, 7),
              "eval/z_lr": (B, N, 227), "eval/z_hr": (B, M, 227), "eval/up_weights": (B, M, 10),
              "eval/hdx_pred": (B, M, 3), "eval/feature_graph": (B, N, 5), "train/z_lr": (B, N, 227),
              "train/hdx_pred": (B, M, 3)}
    check(all(k in io and io[k].shape == s for k, s in shapes.items()), "io.npz members and shapes")

    # Inputs follow the official data convention.
    lows, highs, frames = om.bunny_frames(data_dir, 2)
    lr_rest, _ = om.read_obj(os.path.join(data_dir, "lrestshape.obj"))
    mu, sig = -0.00047, 0.05045
    ref = (lows.astype(np.float32) - np.float32(mu)) / np.float32(sig) - (lr_rest.astype(np.float32) - np.float32(mu)) / np.float32(sig)
    check(np.allclose(io["ldx"], ref, rtol=0, atol=1e-6), "ldx = norm(x_L) - norm(rest_L) in float32")
    check(np.allclose(io["up_query"][..., 6], io["up_distances"].astype(np.float32)) and
          np.array_equal(io["up_query"][..., 3:6], io["lr_rest_normalized"][io["up_indices"]]),
          "upsampling query = [x_H, x_L normalized, geodesic distance raw]")

    for mode in ("eval", "train"):
        z = io[mode + "/z_lr"]
        check(np.array_equal(z[..., :3], io["ldx"]) and np.array_equal(z[..., 3:35], np.broadcast_to(io["pos_emb"], (B, N, 32))),
              "%s: z_L = [ldx, PE, h1, h2]" % mode)
        w = io[mode + "/up_weights"]
        check(bool((w > 0).all()) and np.allclose(w.sum(-1), 1, atol=1e-5), "%s: upsampling weights are a softmax over upK" % mode)
        zh = np.einsum("bmk,bmkc->bmc", w.astype(np.float64), z[:, io["up_indices"], :].astype(np.float64))
        check(np.allclose(zh, io[mode + "/z_hr"], atol=1e-5), "%s: z_H = sum_i w_i z_i" % mode)
        g = io[mode + "/feature_graph"]
        check(not (g == np.arange(N)[None, :, None]).any(), "%s: feature-space graph excludes self" % mode)
        tot = io[mode + "/loss_recon"] + io[mode + "/loss_z_reg"] + io[mode + "/loss_face_normals"]
        check(abs(float(tot) - float(io[mode + "/loss_total"])) <= 1e-6 * abs(float(tot)), "%s: loss total = sum of terms" % mode)
        r = 10 * np.abs(io[mode + "/hdx_pred"].astype(np.float64) - io["hdx"]).mean() / B
        check(abs(r - float(io[mode + "/loss_recon"])) <= 1e-5 * r, "%s: recon = 10 mean|d| / B" % mode)
        zr = 2 * np.abs(z.astype(np.float64)).mean()
        check(abs(zr - float(io[mode + "/loss_z_reg"])) <= 1e-5 * zr, "%s: z_reg = 2 mean|z|" % mode)
        check(np.allclose(io[mode + "/dx_pred"], io[mode + "/hdx_pred"].astype(np.float64) * sig, rtol=1e-12, atol=0),
              "%s: output un-normalized by sigma only" % mode)
    check(not np.array_equal(io["eval/hdx_pred"], io["train/hdx_pred"]), "train-mode BatchNorm (batch statistics) changes the output")

    unused = set(io["train/params_without_grad"].tolist())
    check(unused == {"net_feat_emb.fc_initial.0.weight", "net_feat_emb.fc_initial.0.bias", "net_feat_emb.fc_initial.2.weight",
                     "net_feat_emb.fc_initial.2.bias", "net_decoder.decoder.layers.5.fc.weight", "net_decoder.decoder.layers.5.fc.bias"},
          "exactly fc_initial and the dead decoder layer 5 get no gradient")
    moved = [n for n, _, t in expected_entries() if t and not np.array_equal(sd[n], io["train/after/" + n])]
    check(set(moved) == {n for n, _, t in expected_entries() if t} - unused, "one Adam step moves every used parameter, no unused one")
    check(int(io["train/after/net_feat_emb.blocks.0.edge_conv.1.num_batches_tracked"]) == 1
          and not np.array_equal(io["train/after/net_upscale.conv_weights.1.running_mean"], sd["net_upscale.conv_weights.1.running_mean"]),
          "the training step updates the BatchNorm running statistics")

    # The fixtures replay: a fresh model loading state_dict.npz strictly gives the recorded outputs.
    model, _ = om.build_bunny_model(data_dir, seed=7)
    sds = {m: {} for m in ("net_feat_emb", "net_upscale", "net_decoder")}
    for k, v in sd.items():
        module, key = k.split(".", 1)
        sds[module][key] = torch.from_numpy(v)
    model.load_official_state_dicts(sds, strict=True)
    model.eval()
    with torch.no_grad():
        y = model(torch.from_numpy(io["ldx"]))
    check(np.allclose(y.numpy(), io["eval/hdx_pred"], rtol=0, atol=1e-6), "replaying state_dict.npz reproduces eval/hdx_pred")


def main():
    work = sys.argv[1] if len(sys.argv) > 1 else tempfile.mkdtemp(prefix="simsr_official_model_")
    shared = sys.argv[2] if len(sys.argv) > 2 else os.path.join(REPO, "..", "shared", "data")
    data_dir = os.path.join(shared, "bunny")
    need = ["lrestshape.obj", "hrestshape.obj", "train_frames.npz", "geo_dist_tet2tet_idx.npy",
            "geo_dist_surf2tet_idx.npy", "geo_dist_surf2tet.npy"]
    if not all(os.path.isfile(os.path.join(data_dir, f)) for f in need):
        print("MISSING (a failure under SIMSR_REQUIRE_PEERS=1, a skip otherwise): bunny data not found in %s" % data_dir)
        return 1 if os.environ.get("SIMSR_REQUIRE_PEERS", "0") not in ("", "0") else 77
    os.makedirs(work, exist_ok=True)
    test_architecture(data_dir)
    test_converter(work, data_dir)
    test_export(work, data_dir)
    if FAILURES:
        print("%d check(s) failed" % len(FAILURES))
        return 1
    print("all checks passed")
    return 0


if __name__ == "__main__":
    sys.exit(main())
