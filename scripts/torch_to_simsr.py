#!/usr/bin/python3
"""Convert an official PyTorch checkpoint of Park et al. 2023 (hjoonpark/3d-sim-super-res) into
simsr's self-contained model file (SPEC section 7, "Weights are saved as .npz").

    /usr/bin/python3 scripts/torch_to_simsr.py --checkpoint model_latest.pth --data-dir D \
        --out MODEL.npz [--knn 5] [--upk 10]

Input
  * the checkpoint as the official train.py saves it (model.py save_networks):
    torch.save({"net_feat_emb": state_dict, "net_upscale": state_dict, "net_decoder": state_dict,
    "optimizer": ..., "scheduler": ...}); optimizer and scheduler are ignored. A bare dict holding
    only the three state dicts is accepted too.
  * D/lrestshape.obj (LR volume, 4 triangles per tet), D/hrestshape.obj (HR surface),
    D/geo_dist_tet2tet_idx.npy, D/geo_dist_surf2tet_idx.npy, D/geo_dist_surf2tet.npy (the
    authors' geodesic neighbour files, sorted nearest first, self first in tet2tet).
  * --knn / --upk: the config.py values the checkpoint was trained with (not stored in it).

Output: one uncompressed .npz (np.savez), arrays in this order
  <module>.<state-dict key>   every tensor of the three state dicts, named with its module prefix
                              (e.g. net_feat_emb.blocks.0.edge_conv.0.weight), PyTorch's shape and
                              dtype kept: Conv2d weights out x in x 1 x 1, Conv1d out x in x 1,
                              Linear out x in, BatchNorm weight/bias/running_mean/running_var (C,)
                              float32, num_batches_tracked 0-d int64.
  config          0-d unicode, JSON: profile "official", pos_feat_dim, emb_feat_dims, knn, upK,
                  w_up_feat_dim, n_upscale_layers, decoder_dim, decoder_dims, w0_initial (30),
                  w0 (1), leaky_relu_slope, batchnorm_eps, batchnorm_momentum, dropout,
                  norm_mean, norm_std, n_lr, n_hr, n_tets, n_hr_faces, the training settings of
                  config.py (lr, batch_size, loss weights), parameter_count, source.
  lr_rest         N x 3 float64  LR rest positions as written in the OBJ (not normalized)
  lr_tets         T x 4 int64    0-based, simsr's tet-soup convention (include/simsr/io/obj.hpp):
                                 first face (a,b,c) of a group, d the 4th vertex -> (a, c, b, d)
  hr_rest         M x 3 float64  HR rest positions as written (not normalized)
  hr_faces        F x 3 int64    0-based, as in the OBJ
  lr_graph        N x knn int64  geo_dist_tet2tet_idx[:, :knn] (self first): the graph of the
                                 first feature-embedding block
  up_indices      M x upK int64  geo_dist_surf2tet_idx[:, :upK]
  up_distances    M x upK float64 geo_dist_surf2tet[:, :upK], raw (mesh) units
  norm_mean       0-d float64    mu = (0.04998 - 0.05092) / 2
  norm_std        0-d float64    sigma = (0.04998 + 0.05092) / 2
Inference conventions of the official code (dataset.py, model.py): positions are parsed to
float32, then normalized (x - mu) / sigma in float32; network input = normalized LR positions
minus normalized LR rest; the upsampling query per (HR vertex j, neighbour i) is
[hr_rest_n[j], lr_rest_n[up_indices[j,i]], up_distances[j,i]] cast to float32; the output is a
normalized HR displacement: multiply by sigma (not + mu) for world units.
"""
import argparse
import json
import os
import sys

try:
    import numpy as np
except ImportError:
    print("torch_to_simsr.py: numpy is not importable by %s (use /usr/bin/python3)" % sys.executable, file=sys.stderr)
    sys.exit(77)

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, "peers"))

MODULES = ("net_feat_emb", "net_upscale", "net_decoder")


def infer_config(sds, knn, upk):
    """Architecture sizes from the tensors themselves (knn/upK are not stored in a checkpoint)."""
    import official_model as om

    fe, up, de = sds["net_feat_emb"], sds["net_upscale"], sds["net_decoder"]
    n_blocks = 1 + max(int(k.split(".")[1]) for k in fe if k.startswith("blocks."))
    emb = [int(fe["blocks.0.edge_conv.0.weight"].shape[1]) // 2]
    for b in range(n_blocks):
        emb.append(int(fe["blocks.%d.edge_conv.3.weight" % b].shape[0]))
    conv_ids = sorted(int(k.split(".")[1]) for k in up if k.startswith("conv_weights.") and k.endswith(".weight")
                      and up[k].dim() == 4)
    cfg = dict(om.OFFICIAL_CONFIG)
    cfg.update({
        "pos_feat_dim": int(fe["fc_initial.0.weight"].shape[0]),
        "emb_feat_dims": emb,
        "knn": int(knn),
        "upK": int(upk),
        "w_up_feat_dim": int(up["conv_weights.0.weight"].shape[0]),
        "n_upscale_layers": len(conv_ids) - 1,
        "decoder_dim": int(de["decoder.layers.0.fc.weight"].shape[0]),
    })
    if emb[0] != 3 + cfg["pos_feat_dim"]:
        raise ValueError("block 0 input width %d != 3 + pos_feat_dim %d" % (emb[0], cfg["pos_feat_dim"]))
    cfg["decoder_dims"] = om.decoder_dims(cfg)
    return cfg


def convert(checkpoint, data_dir, out, knn=5, upk=10):
    import torch
    import official_model as om

    torch.set_num_threads(2)
    ckpt = torch.load(checkpoint, map_location="cpu")
    if not isinstance(ckpt, dict):
        raise ValueError("%s: not a dict of state dicts" % checkpoint)
    missing = [m for m in MODULES if m not in ckpt]
    if missing:
        raise ValueError("%s: missing %s (keys: %s)" % (checkpoint, ", ".join(missing), ", ".join(map(str, ckpt))))
    sds = {m: ckpt[m] for m in MODULES}
    cfg = infer_config(sds, knn, upk)

    data = om.load_bunny(data_dir, knn, upk)
    N, M = data["lr_rest"].shape[0], data["hr_rest"].shape[0]
    if data["lr_graph"].shape != (N, knn) or data["up_indices"].shape != (M, upk):
        raise ValueError("neighbour files: tet2tet %s, surf2tet %s for N=%d, M=%d, knn=%d, upK=%d" % (
            data["lr_graph"].shape, data["up_indices"].shape, N, M, knn, upk))
    if not np.array_equal(data["lr_graph"][:, 0], np.arange(N)):
        raise ValueError("geo_dist_tet2tet_idx: column 0 is not the vertex itself")
    for name, idx, n in (("lr_graph", data["lr_graph"], N), ("up_indices", data["up_indices"], N)):
        if idx.min() < 0 or idx.max() >= n:
            raise ValueError("%s: index out of range [0, %d)" % (name, n))
    tets = om.tets_from_soup(data["lr_faces"])

    # The tensors must fit the official network exactly: load them strictly into our peer.
    model = om.OfficialSuperRes(data["lr_rest"], data["hr_rest"], data["lr_graph"], data["up_indices"],
                                data["up_distances"], cfg)
    model.load_official_state_dicts(sds, strict=True)
    cfg.update({
        "norm_mean": om.NORM_MEAN,
        "norm_std": om.NORM_STD,
        "n_lr": int(N),
        "n_hr": int(M),
        "n_tets": int(tets.shape[0]),
        "n_hr_faces": int(data["hr_faces"].shape[0]),
        "parameter_count": int(om.count_parameters(model)),
        "source": os.path.basename(checkpoint),
    })

    arrays = {}
    for m in MODULES:
        for k, v in sds[m].items():
            arrays[m + "." + k] = v.detach().cpu().numpy()
    arrays["config"] = np.array(json.dumps(cfg, sort_keys=True))
    arrays["lr_rest"] = data["lr_rest"].astype(np.float64)
    arrays["lr_tets"] = tets.astype(np.int64)
    arrays["hr_rest"] = data["hr_rest"].astype(np.float64)
    arrays["hr_faces"] = data["hr_faces"].astype(np.int64)
    arrays["lr_graph"] = data["lr_graph"]
    arrays["up_indices"] = data["up_indices"]
    arrays["up_distances"] = data["up_distances"]
    arrays["norm_mean"] = np.float64(om.NORM_MEAN)
    arrays["norm_std"] = np.float64(om.NORM_STD)
    out_dir = os.path.dirname(os.path.abspath(out))
    os.makedirs(out_dir, exist_ok=True)
    with open(out, "wb") as f:
        np.savez(f, **arrays)
    return arrays


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--checkpoint", required=True)
    ap.add_argument("--data-dir", required=True)
    ap.add_argument("--out", required=True)
    ap.add_argument("--knn", type=int, default=5)
    ap.add_argument("--upk", type=int, default=10)
    args = ap.parse_args(argv)
    try:
        import torch  # noqa: F401
    except ImportError:
        print("torch_to_simsr.py: torch is not importable by %s (use /usr/bin/python3)" % sys.executable, file=sys.stderr)
        return 77
    try:
        arrays = convert(args.checkpoint, args.data_dir, args.out, args.knn, args.upk)
    except (ValueError, KeyError, RuntimeError, OSError) as e:
        print("torch_to_simsr.py: %s" % e, file=sys.stderr)
        return 1
    cfg = json.loads(str(arrays["config"]))
    print("%s: %d arrays, %d parameters, N=%d M=%d knn=%d upK=%d" % (
        args.out, len(arrays), cfg["parameter_count"], cfg["n_lr"], cfg["n_hr"], cfg["knn"], cfg["upK"]))
    return 0


if __name__ == "__main__":
    sys.exit(main())
