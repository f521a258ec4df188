#!/usr/bin/python3
"""PyTorch peer of simsr's network, profile `official` (SPEC section 7).

An independent re-implementation of the network of the public PyTorch code of Park et al. 2023
(repository hjoonpark/3d-sim-super-res, MPL-2.0; its model.py / config.py / dataset.py / train.py at
the revision whose defaults read data/lrestshape.obj and data/geo_dist_*_idx.npy). Only the facts
were taken (layer sizes, order, names, initialisations, loss, normalisation); the code is ours.
Module and parameter names equal the official state-dict names, so the three state dicts of an
official checkpoint (`net_feat_emb`, `net_upscale`, `net_decoder`) load with strict=True.

Run with Debian's /usr/bin/python3 (python3-torch, numpy):

    official_model.py --count                       # 706871 parameters at the defaults
    official_model.py --export DIR [--data-dir D] [--checkpoint X.pth]   # DIR/state_dict.npz, DIR/io.npz
    official_model.py --make-checkpoint X.pth [--steps 1]   # a checkpoint saved as train.py does

Facts (official file in brackets):
  * data [dataset.py, util.py]: OBJ coordinates parsed to float32; mu = (0.04998 - 0.05092)/2,
    sigma = (0.04998 + 0.05092)/2; rest shapes and frames normalized (x - mu)/sigma in float32;
    inputs ldx = norm(x_L) - norm(rest_L), targets hdx = norm(x_H) - norm(rest_H).
  * positional encoding [model.py PosEmb]: N x 32, column 2m = sin(i / 10000^(2m/32)), column
    2m+1 = cos(same), i = vertex index; not a parameter, not in the state dict.
  * feature embedding [model.py FeatEmb, EmbModule]: blocks 35->64, 64->128, k = 5; block 0's graph
    = first k columns of geo_dist_tet2tet_idx (self included), block 1's = kNN in feature space with
    k+1 neighbours, the first (self) dropped; edge features cat(h_j - h_i, h_i); `edge_conv` =
    Conv2d(2in,2out,no bias), BatchNorm2d, LeakyReLU(0.2), Conv2d(2out,out,no bias); max over k;
    global max and mean over the points; `fc_out` on cat(h, e, max, mean) = Conv1d 3out+in->3out,
    BN, LReLU, ->2out, BN, LReLU, ->out, BN, LReLU, ->out, all without bias; Dropout(p=0) after each
    block; `fc_initial` Linear(3,32), LReLU, Linear(32,32) is built but never called.
    z = cat(ldx, PE, h1, h2) (227).
  * upsampling [model.py Upscale]: query (x_H rest normalized, x_L rest normalized, geodesic distance
    raw) per (HR vertex, upK neighbour from geo_dist_surf2tet_idx); `conv_weights` = 8 x (Conv2d
    ->128 no bias, BatchNorm2d, sin) + Conv2d(128,1) with bias; softmax over the upK neighbours;
    z_H = sum_i w_i z_i.
  * decoder [model.py Decoder, SirenNet, Siren]: dims 227,256,128,64,32,16,3; `decoder.layers.0..5`
    are sine layers (layer 0 w0 = 30, others w0 = 1); the forward uses layers 0..4 only (zip with a
    5-tuple), layer 5 (16->3) is dead; `decoder.last_layer` Linear(16,3) identity. Init: weights and
    biases U(-1/fan_in, 1/fan_in) for layer 0, U(-sqrt(6/fan_in)/w0, +) otherwise (last layer too).
  * loss [model.py compute_losses]: 10 * L1Loss(reduce="sum")(pred, target) / B -- the deprecated
    `reduce` flag is truthy, so this is the *mean* absolute error divided by B again --
    + 2 * mean|z| (z includes ldx and the PE) + 1e-3 * mean(1 - cos(n_pred, n_true)) over HR face
    normals of rest(normalized) + displacement.  Adam lr 2e-4, StepLR(9999, 0.5), batch 32.
  * checkpoint [model.py save_networks, train.py]: torch.save({"net_feat_emb": sd, "net_upscale": sd,
    "net_decoder": sd, "optimizer": sd, "scheduler": sd}, "model/model_latest.pth").
"""
import argparse
import json
import math
import os
import sys

import numpy as np

try:
    import torch
    import torch.nn as nn
    import torch.nn.functional as F
except ImportError:  # the test skips; the CLI says why
    torch = None

DEFAULT_DATA_DIR = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "..", "shared", "data", "bunny")

# config.py defaults of the official code (train mode).
OFFICIAL_CONFIG = {
    "profile": "official",
    "pos_feat_dim": 32,
    "emb_feat_dims": [35, 64, 128],
    "knn": 5,
    "upK": 10,
    "w_up_feat_dim": 128,
    "n_upscale_layers": 8,
    "decoder_dim": 256,
    "dropout": 0.0,
    "w0_initial": 30.0,
    "w0": 1.0,
    "leaky_relu_slope": 0.2,
    "batchnorm_eps": 1e-5,
    "batchnorm_momentum": 0.1,
    "lr": 2e-4,
    "lr_decay_epoch": 9999,
    "lr_decay_gamma": 0.5,
    "batch_size": 32,
    "n_epochs": 200,
    "w_recon": 10.0,
    "w_zreg": 2.0,
    "w_fn": 1e-3,
}

# dataset.py: "manual" normalization from the LR displacement range.
LDX_MIN, LDX_MAX = -0.05092, 0.04998
NORM_MEAN = 0.5 * (LDX_MAX + LDX_MIN)
NORM_STD = 0.5 * (LDX_MAX - LDX_MIN)

PARAMETER_COUNT = 706871  # paper Table 3


def decoder_dims(cfg):
    h = cfg["decoder_dim"]
    return [sum(cfg["emb_feat_dims"]), h, h // 2, h // 4, h // 8, h // 16, 3]


# ----------------------------------------------------------------------------------------------
# data


def read_obj(path):
    """Vertices (float64, as written) and 0-based triangle indices (int64) of an OBJ file."""
    verts, faces = [], []
    with open(path) as f:
        for line in f:
            parts = line.split()
            if not parts:
                continue
            if parts[0] == "v":
                verts.append([float(parts[1]), float(parts[2]), float(parts[3])])
            elif parts[0] == "f":
                faces.append([int(p.split("/")[0]) for p in parts[1:4]])
    return np.asarray(verts, dtype=np.float64), np.asarray(faces, dtype=np.int64) - 1


def tets_from_soup(faces):
    """T x 4 tets from 4 triangles per tet, in simsr's convention (include/simsr/io/obj.hpp):
    first face (a, b, c), d the vertex not on it, tet = (a, c, b, d)."""
    if faces.shape[0] % 4:
        raise ValueError("tet soup: face count %d is not a multiple of 4" % faces.shape[0])
    groups = faces.reshape(-1, 4, 3)
    tets = np.empty((groups.shape[0], 4), dtype=np.int64)
    for t, g in enumerate(groups):
        a, b, c = g[0]
        others = set(g.ravel().tolist()) - {a, b, c}
        if len(others) != 1 or len(set(g.ravel().tolist())) != 4:
            raise ValueError("tet soup: group %d does not span exactly 4 vertices" % t)
        tets[t] = (a, c, b, others.pop())
    return tets


def normalize(x):
    """(x - mu) / sigma, elementwise, in the dtype of x (the official code: float32 tensors)."""
    return (x - NORM_MEAN) / NORM_STD


def unnormalize_displacement(dx):
    """Displacements scale by sigma only (the mean cancels in a difference)."""
    return dx * NORM_STD


def load_bunny(data_dir, knn=5, upk=10):
    """Everything the official SuperRes constructor and Dataset derive from the data folder."""
    lr_rest, lr_faces = read_obj(os.path.join(data_dir, "lrestshape.obj"))
    hr_rest, hr_faces = read_obj(os.path.join(data_dir, "hrestshape.obj"))
    t2t_idx = np.load(os.path.join(data_dir, "geo_dist_tet2tet_idx.npy"))
    s2t_idx = np.load(os.path.join(data_dir, "geo_dist_surf2tet_idx.npy"))
    s2t = np.load(os.path.join(data_dir, "geo_dist_surf2tet.npy"))
    return {
        "lr_rest": lr_rest,
        "lr_faces": lr_faces,
        "hr_rest": hr_rest,
        "hr_faces": hr_faces,
        "lr_graph": np.ascontiguousarray(t2t_idx[:, :knn]).astype(np.int64),
        "up_indices": np.ascontiguousarray(s2t_idx[:, :upk]).astype(np.int64),
        "up_distances": np.ascontiguousarray(s2t[:, :upk]).astype(np.float64),
    }


def displacements(positions, rest, dtype=np.float32):
    """Official inputs/targets: positions and rest parsed to float32, normalized in float32, then
    subtracted (dataset.py). positions: (..., n, 3), rest: (n, 3). dtype=np.float64 gives the
    same pipeline in double (the double-precision interop fixtures)."""
    p = torch.from_numpy(np.asarray(positions, dtype=dtype))
    r = torch.from_numpy(np.asarray(rest, dtype=dtype))
    return normalize(p) - normalize(r)


def to_float64(model, data):
    """The model in double precision: parameters and buffers, and the rest shapes, the upsampling
    query and the positional encoding recomputed in float64."""
    model.double()
    cfg = model.cfg
    model.lr_rest_n = normalize(torch.from_numpy(np.asarray(data["lr_rest"], dtype=np.float64)))
    model.hr_rest_n = normalize(torch.from_numpy(np.asarray(data["hr_rest"], dtype=np.float64)))
    idx = torch.as_tensor(data["up_indices"][:, : cfg["upK"]], dtype=torch.long)
    dist = torch.as_tensor(data["up_distances"][:, : cfg["upK"]], dtype=torch.float64)
    M, K = idx.shape
    query = torch.cat((model.hr_rest_n[:, None, :].expand(M, K, 3), model.lr_rest_n[idx], dist[..., None]), dim=-1)
    model.up_query = query
    model.net_upscale.query = query.permute(2, 0, 1).unsqueeze(0).contiguous()
    n, dim = model.pos_emb.shape
    i = torch.arange(0, n, dtype=torch.float64).unsqueeze(1)
    freq = 10000 ** (torch.arange(0, dim, step=2, dtype=torch.float64) / dim)
    pe = torch.empty(n, dim, dtype=torch.float64)
    pe[:, 0::2] = torch.sin(i / freq)
    pe[:, 1::2] = torch.cos(i / freq)
    model.pos_emb = pe  # the table in double (a float32 table differs by up to 6e-5 at i ~ 1700)
    return model


# ----------------------------------------------------------------------------------------------
# network (only defined when torch is present)

if torch is not None:

    def positional_encoding(n, dim):
        """Sinusoidal PE over the vertex index, float32 (PosEmb). A U(0,1) N x dim draw precedes
        the overwrite in the official code; it is kept so the RNG stream (hence every later init)
        follows the same order."""
        pe = torch.rand(n, dim)
        i = torch.arange(0, n, dtype=torch.float).unsqueeze(1)
        even = torch.arange(0, dim, step=2, dtype=torch.float)
        freq = 10000 ** (even / dim)
        pe[:, 0::2] = torch.sin(i / freq)
        pe[:, 1::2] = torch.cos(i / freq)
        return pe

    def feature_knn(h, k):
        """Indices of the k+1 nearest points in feature space (by -|hi|^2 + 2 hi.hj - |hj|^2,
        largest first), the first (self) dropped. h: (B, C, N) -> (B, N, k)."""
        gram = torch.matmul(h.transpose(2, 1), h)
        sq = (h * h).sum(dim=1, keepdim=True)
        neg_d2 = 2 * gram - sq - sq.transpose(2, 1)
        return neg_d2.topk(k=k + 1, dim=-1)[1][:, :, 1:]

    def edge_features(h, idx):
        """h: (B, N, C), idx: (B, N, k) -> (B, 2C, N, k) with channels [h_j - h_i, h_i]."""
        B, N, C = h.shape
        k = idx.shape[-1]
        flat = h.reshape(B * N, C)
        offset = (torch.arange(B, device=h.device) * N).view(B, 1, 1)
        nbr = flat[(idx + offset).reshape(-1)].view(B, N, k, C)
        centre = h.unsqueeze(2).expand(B, N, k, C)
        return torch.cat((nbr - centre, centre), dim=3).permute(0, 3, 1, 2).contiguous()

    class EdgeConvModule(nn.Module):
        """One feature-embedding block (official EmbModule): `edge_conv`, `fc_out`."""

        def __init__(self, index, in_dim, out_dim, k, graph=None, slope=0.2):
            super().__init__()
            self.index = index
            self.k = k
            self.graph = graph  # (N, k) long for block 0; a plain attribute, not state
            self.last_graph = None
            self.edge_conv = nn.Sequential(
                nn.Conv2d(2 * in_dim, 2 * out_dim, kernel_size=1, bias=False),
                nn.BatchNorm2d(2 * out_dim),
                nn.LeakyReLU(slope, True),
                nn.Conv2d(2 * out_dim, out_dim, kernel_size=1, bias=False),
            )
            dims = [3 * out_dim + in_dim, 3 * out_dim, 2 * out_dim, out_dim]
            layers = []
            for a, b in zip(dims[:-1], dims[1:]):
                layers += [nn.Conv1d(a, b, kernel_size=1, bias=False), nn.BatchNorm1d(b), nn.LeakyReLU(slope, True)]
            layers.append(nn.Conv1d(out_dim, out_dim, kernel_size=1, bias=False))
            self.fc_out = nn.Sequential(*layers)

        def forward(self, h):  # (B, N, in) -> (B, N, out)
            B, N, _ = h.shape
            if self.index == 0:
                idx = self.graph.to(h.device).unsqueeze(0).expand(B, N, self.k)
            else:
                idx = feature_knn(h.transpose(1, 2), self.k)
            self.last_graph = idx.detach()
            e, edge_arg = self.edge_conv(edge_features(h, idx)).max(dim=-1)  # (B, out, N)
            g_max, global_arg = e.max(dim=2, keepdim=True)
            g_max = g_max.expand(-1, -1, N)
            # which edge / point each max took: the interop test routes ours the same at near-ties
            self.last_edge_argmax, self.last_global_argmax = edge_arg.detach(), global_arg.detach()
            g_mean = e.mean(dim=2, keepdim=True).expand(-1, -1, N)
            cat = torch.cat((h.transpose(1, 2), e, g_max, g_mean), dim=1)
            return self.fc_out(cat).transpose(1, 2)

    class FeatureEmbedding(nn.Module):
        """Official FeatEmb: `blocks`, `drop_out`, the unused `fc_initial`."""

        def __init__(self, cfg, graph):
            super().__init__()
            dims = cfg["emb_feat_dims"]
            self.blocks = nn.ModuleList()
            for i in range(len(dims) - 1):
                self.blocks.append(EdgeConvModule(i, dims[i], dims[i + 1], cfg["knn"], graph if i == 0 else None,
                                                  cfg["leaky_relu_slope"]))
            self.drop_out = nn.Dropout(p=cfg["dropout"])
            d = cfg["pos_feat_dim"]
            self.fc_initial = nn.Sequential(nn.Linear(3, d), nn.LeakyReLU(cfg["leaky_relu_slope"], True), nn.Linear(d, d))

        def forward(self, h):
            outs = []
            for block in self.blocks:
                h = self.drop_out(block(h))
                outs.append(h)
            return torch.cat(outs, dim=-1)

    class Sin(nn.Module):
        def __init__(self, w0=1.0):
            super().__init__()
            self.w0 = w0

        def forward(self, x):
            return torch.sin(self.w0 * x)

    class Upsampling(nn.Module):
        """Official Upscale: `conv_weights` maps the 7-d query of each (HR vertex, LR neighbour) to a
        logit; softmax over the upK neighbours; z_H = sum w z_L."""

        def __init__(self, cfg, query, indices):
            super().__init__()
            self.query = query  # (1, 7, M, K) float32, plain attribute
            self.indices = indices  # (M, K) long
            self.last_weights = None
            layers = []
            d_in = 7
            for _ in range(cfg["n_upscale_layers"]):
                layers += [nn.Conv2d(d_in, cfg["w_up_feat_dim"], kernel_size=1, bias=False),
                           nn.BatchNorm2d(cfg["w_up_feat_dim"]), Sin()]
                d_in = cfg["w_up_feat_dim"]
            layers.append(nn.Conv2d(d_in, 1, kernel_size=1))
            self.conv_weights = nn.Sequential(*layers)

        def weights(self, B):
            # The official code stores the query repeated batch_size times and slices B copies, so
            # train-mode BatchNorm sees B identical copies (same statistics; B*M*K samples).
            q = self.query.repeat(B, 1, 1, 1)
            return torch.softmax(self.conv_weights(q).permute(0, 2, 3, 1), dim=2)  # (B, M, K, 1)

        def forward(self, z):  # (B, N, C) -> (B, M, C)
            B = z.shape[0]
            w = self.weights(B)
            self.last_weights = w.detach()[..., 0]
            grouped = z[:, self.indices, :]  # (B, M, K, C)
            return (w * grouped).sum(dim=2)

    class SineLayer(nn.Module):
        """Official Siren: `fc` (Linear) then sin(w0 x), or a given activation."""

        def __init__(self, d_in, d_out, w0=1.0, is_first=False, activation=None, c=6.0):
            super().__init__()
            # Same draw order as the official layer: rand weight, rand bias, re-drawn uniformly,
            # then a default-initialised Linear whose tensors are replaced.
            weight = torch.rand(d_out, d_in)
            bias = torch.rand(d_out)
            bound = (1.0 / d_in) if is_first else (math.sqrt(c / d_in) / w0)
            weight.uniform_(-bound, bound)
            bias.uniform_(-bound, bound)
            self.activation = Sin(w0) if activation is None else activation
            self.fc = nn.Linear(d_in, d_out)
            self.fc.weight = nn.Parameter(weight)
            self.fc.bias = nn.Parameter(bias)

        def forward(self, x):
            return self.activation(self.fc(x))

    class SirenStack(nn.Module):
        """Official SirenNet: `layers` (len(dims)-1 sine layers, the last one never used) and
        `last_layer` (linear)."""

        def __init__(self, dims, w0=1.0, w0_initial=30.0):
            super().__init__()
            self.n_used = len(dims) - 2
            self.layers = nn.ModuleList()
            for i in range(len(dims) - 1):
                self.layers.append(SineLayer(dims[i], dims[i + 1], w0=w0_initial if i == 0 else w0, is_first=i == 0))
            self.last_layer = SineLayer(dims[-2], dims[-1], w0=w0, activation=nn.Identity())

        def forward(self, x):
            for layer in list(self.layers)[: self.n_used]:
                x = layer(x)
            return self.last_layer(x)

    class Decoder(nn.Module):
        def __init__(self, cfg):
            super().__init__()
            self.decoder = SirenStack(decoder_dims(cfg), w0=cfg["w0"], w0_initial=cfg["w0_initial"])

        def forward(self, z):
            return self.decoder(z)

    class OfficialSuperRes(nn.Module):
        """The whole network. State dict keys: net_feat_emb.*, net_upscale.*, net_decoder.*.
        lr_graph (N,k), up_indices (M,K) int; up_distances (M,K) raw; lr_rest/hr_rest raw positions
        (float64 or float32; parsed to float32 and normalized like the official Dataset)."""

        def __init__(self, lr_rest, hr_rest, lr_graph, up_indices, up_distances, cfg=None):
            super().__init__()
            cfg = dict(OFFICIAL_CONFIG if cfg is None else cfg)
            self.cfg = cfg
            lr_n = normalize(torch.from_numpy(np.asarray(lr_rest, dtype=np.float32)))
            hr_n = normalize(torch.from_numpy(np.asarray(hr_rest, dtype=np.float32)))
            self.lr_rest_n, self.hr_rest_n = lr_n, hr_n
            N, M = lr_n.shape[0], hr_n.shape[0]
            graph = torch.as_tensor(np.asarray(lr_graph)[:, : cfg["knn"]], dtype=torch.long)
            idx = torch.as_tensor(np.asarray(up_indices)[:, : cfg["upK"]], dtype=torch.long)
            dist = torch.as_tensor(np.asarray(up_distances)[:, : cfg["upK"]])
            K = idx.shape[1]
            query = torch.cat((hr_n[:, None, :].expand(M, K, 3).double(), lr_n[idx].double(), dist[..., None].double()),
                              dim=-1).float()  # (M, K, 7)
            self.up_query = query
            # construction order = official (PosEmb, FeatEmb, Upscale, Decoder): same RNG stream
            self.pos_emb = positional_encoding(N, cfg["pos_feat_dim"])
            self.net_feat_emb = FeatureEmbedding(cfg, graph)
            self.net_upscale = Upsampling(cfg, query.permute(2, 0, 1).unsqueeze(0).contiguous(), idx)
            self.net_decoder = Decoder(cfg)
            self.z = None

        def forward(self, ldx):  # (B, N, 3) normalized LR displacements -> (B, M, 3) normalized
            B = ldx.shape[0]
            h0 = torch.cat((ldx, self.pos_emb.unsqueeze(0).expand(B, -1, -1)), dim=-1)
            self.z = torch.cat((h0, self.net_feat_emb(h0)), dim=-1)
            self.z_hr = self.net_upscale(self.z)
            return self.net_decoder(self.z_hr)

        def official_state_dicts(self):
            return {name: getattr(self, name).state_dict() for name in ("net_feat_emb", "net_upscale", "net_decoder")}

        def load_official_state_dicts(self, ckpt, strict=True):
            for name in ("net_feat_emb", "net_upscale", "net_decoder"):
                getattr(self, name).load_state_dict(ckpt[name], strict=strict)

        def make_optimizer(self):
            """Adam over the three sub-networks + StepLR, as the official SuperRes."""
            opt = torch.optim.Adam(self.parameters(), lr=self.cfg["lr"])
            sched = torch.optim.lr_scheduler.StepLR(opt, step_size=self.cfg["lr_decay_epoch"], gamma=self.cfg["lr_decay_gamma"])
            return opt, sched

    def face_normals(v, faces):
        """Unit normals of triangles (a, b, c): (b-a) x (c-a) / |.|. v: (B, M, 3)."""
        a, b, c = v[:, faces[:, 0]], v[:, faces[:, 1]], v[:, faces[:, 2]]
        n = torch.cross(b - a, c - a, dim=-1)
        return n / torch.linalg.norm(n, dim=-1).unsqueeze(-1)

    def official_loss(hdx_pred, hdx, z, hr_rest_n, hr_faces, cfg=None):
        """Loss terms as the official compute_losses stores them (each already weighted):
        recon = w_recon * mean|pred - target| / B; z_reg = w_zreg * mean|z|;
        face_normals = w_fn * mean(1 - cos(n_pred, n_true)) over B x F; total = their sum."""
        cfg = OFFICIAL_CONFIG if cfg is None else cfg
        B = hdx_pred.shape[0]
        faces = torch.as_tensor(hr_faces, dtype=torch.long)
        recon = cfg["w_recon"] * (hdx_pred - hdx).abs().mean() / B
        z_reg = cfg["w_zreg"] * z.abs().mean()
        n_true = face_normals(hr_rest_n + hdx, faces)
        n_pred = face_normals(hr_rest_n + hdx_pred, faces)
        fn = cfg["w_fn"] * (1 - F.cosine_similarity(n_pred, n_true, dim=-1)).mean()
        return {"total": recon + z_reg + fn, "recon": recon, "z_reg": z_reg, "face_normals": fn}

    def build_bunny_model(data_dir, seed=0, cfg=None):
        cfg = dict(OFFICIAL_CONFIG if cfg is None else cfg)
        data = load_bunny(data_dir, cfg["knn"], cfg["upK"])
        torch.manual_seed(seed)
        model = OfficialSuperRes(data["lr_rest"], data["hr_rest"], data["lr_graph"], data["up_indices"],
                                 data["up_distances"], cfg)
        return model, data

    def count_parameters(model):
        return sum(p.numel() for p in model.parameters())

    def build_geometry_free_model(cfg=None, n_lr=16, n_hr=8):
        """The network on a dummy geometry: the parameters do not depend on the mesh sizes."""
        cfg = dict(OFFICIAL_CONFIG if cfg is None else cfg)
        g = np.random.default_rng(0)
        lr = g.random((n_lr, 3))
        hr = g.random((n_hr, 3))
        graph = np.stack([np.roll(np.arange(n_lr), -j) for j in range(cfg["knn"])], axis=1)
        up = np.stack([np.arange(n_hr) % n_lr] * cfg["upK"], axis=1)
        return OfficialSuperRes(lr, hr, graph, up, g.random(up.shape), cfg)

    def save_official_checkpoint(model, optimizer, scheduler, path):
        """The layout of the official save_networks: the three module state dicts + optimizer +
        scheduler state, one torch.save'd dict."""
        ckpt = model.official_state_dicts()
        ckpt["optimizer"] = optimizer.state_dict()
        ckpt["scheduler"] = scheduler.state_dict()
        torch.save(ckpt, path)

    def full_state_dict(model):
        """Every state tensor by its full official name (net_feat_emb.blocks.0....)."""
        out = {}
        for name, sd in model.official_state_dicts().items():
            for k, v in sd.items():
                out[name + "." + k] = v.detach().cpu().clone()
        return out


def bunny_frames(data_dir, count):
    d = np.load(os.path.join(data_dir, "train_frames.npz"))
    return d["lowres"][:count], d["highres"][:count], d["frame"][:count]


def train_step(model, data, ldx, hdx, optimizer):
    model.train()
    pred = model(ldx)
    losses = official_loss(pred, hdx, model.z, model.hr_rest_n, data["hr_faces"], model.cfg)
    optimizer.zero_grad()
    losses["total"].backward()
    return pred, losses


def export(out_dir, data_dir, seed=0, n_frames=2, checkpoint=None, dtype="float32"):
    """Fixtures for an interop test: DIR/state_dict.npz (initial weights, full names) and DIR/io.npz
    (inputs, intermediates, outputs and losses of an eval-mode forward and of one training step).
    With `checkpoint` (an official .pth), its weights replace the seeded initial ones. With
    dtype "float64" everything runs in double (gradients of BatchNorm-projected layers are sums of
    cancelling terms: float32 runs agree only to ~1e-3 there, double runs to rounding)."""
    torch.set_num_threads(2)
    os.makedirs(out_dir, exist_ok=True)
    model, data = build_bunny_model(data_dir, seed)
    if checkpoint:
        model.load_official_state_dicts(torch.load(checkpoint, map_location="cpu"), strict=True)
    npdtype = np.float64 if dtype == "float64" else np.float32
    if dtype == "float64":
        to_float64(model, data)
    lows, highs, frames = bunny_frames(data_dir, n_frames)
    ldx = displacements(lows, data["lr_rest"], npdtype)
    hdx = displacements(highs, data["hr_rest"], npdtype)

    init = full_state_dict(model)
    np.savez(os.path.join(out_dir, "state_dict.npz"), **{k: v.numpy() for k, v in init.items()})

    io = {
        "frames": frames.astype(np.int64),
        "seed": np.int64(seed),
        "config": np.array(json.dumps(model.cfg)),
        "norm_mean": np.float64(NORM_MEAN),
        "norm_std": np.float64(NORM_STD),
        "ldx": ldx.numpy(),
        "hdx": hdx.numpy(),
        "lr_rest_normalized": model.lr_rest_n.numpy(),
        "hr_rest_normalized": model.hr_rest_n.numpy(),
        "hr_faces": data["hr_faces"],
        "pos_emb": model.pos_emb.numpy(),
        "lr_graph": data["lr_graph"],
        "up_indices": data["up_indices"],
        "up_distances": data["up_distances"],
        "up_query": model.up_query.numpy(),
    }

    def record(prefix, pred, losses):
        blocks = model.net_feat_emb.blocks
        io[prefix + "/z_lr"] = model.z.detach().numpy()
        io[prefix + "/feature_graph"] = blocks[1].last_graph[:, :, :].numpy().astype(np.int64)
        for b, block in enumerate(blocks):
            io["%s/edge_argmax/%d" % (prefix, b)] = block.last_edge_argmax.numpy().astype(np.int64)      # (B, out, N)
            io["%s/global_argmax/%d" % (prefix, b)] = block.last_global_argmax.numpy().astype(np.int64)  # (B, out, 1)
        io[prefix + "/up_weights"] = model.net_upscale.last_weights.numpy()
        io[prefix + "/z_hr"] = model.z_hr.detach().numpy()
        io[prefix + "/hdx_pred"] = pred.detach().numpy()
        io[prefix + "/dx_pred"] = unnormalize_displacement(pred.detach().double()).numpy()
        for k, v in losses.items():
            io[prefix + "/loss_" + k] = np.float64(v.item())

    model.eval()
    with torch.no_grad():
        pred = model(ldx)
        losses = official_loss(pred, hdx, model.z, model.hr_rest_n, data["hr_faces"], model.cfg)
    record("eval", pred, losses)

    optimizer, _ = model.make_optimizer()
    pred, losses = train_step(model, data, ldx, hdx, optimizer)
    record("train", pred, losses)
    unused = []
    for name, p in model.named_parameters():
        # fc_initial and the dead decoder layer get no gradient (None in PyTorch): stored as zeros;
        # Adam leaves them unchanged either way.
        if p.grad is None:
            unused.append(name)
        g = torch.zeros_like(p) if p.grad is None else p.grad
        io["train/grad/" + name] = g.detach().numpy().copy()
    io["train/params_without_grad"] = np.array(unused)
    optimizer.step()
    for k, v in full_state_dict(model).items():
        io["train/after/" + k] = v.numpy()
    np.savez(os.path.join(out_dir, "io.npz"), **io)
    return io


def make_checkpoint(path, data_dir, seed=0, steps=1, n_frames=1):
    """A checkpoint in the official train.py layout (weights after `steps` Adam steps on the first
    frames, so the optimizer state is populated)."""
    torch.set_num_threads(2)
    model, data = build_bunny_model(data_dir, seed)
    optimizer, scheduler = model.make_optimizer()
    if steps > 0:
        lows, highs, _ = bunny_frames(data_dir, n_frames)
        ldx = displacements(lows, data["lr_rest"])
        hdx = displacements(highs, data["hr_rest"])
        for _ in range(steps):
            train_step(model, data, ldx, hdx, optimizer)
            optimizer.step()
        scheduler.step()
    os.makedirs(os.path.dirname(os.path.abspath(path)), exist_ok=True)
    save_official_checkpoint(model, optimizer, scheduler, path)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--count", action="store_true", help="print the parameter count")
    ap.add_argument("--export", metavar="DIR", help="write DIR/state_dict.npz and DIR/io.npz")
    ap.add_argument("--make-checkpoint", metavar="PTH", help="save a checkpoint as the official train.py does")
    ap.add_argument("--steps", type=int, default=1, help="Adam steps before --make-checkpoint saves")
    ap.add_argument("--checkpoint", help="--export: start from this official checkpoint's weights")
    ap.add_argument("--dtype", choices=("float32", "float64"), default="float32", help="--export: precision of the run")
    ap.add_argument("--data-dir", default=DEFAULT_DATA_DIR)
    ap.add_argument("--seed", type=int, default=0)
    args = ap.parse_args(argv)
    if torch is None:
        print("official_model.py: torch is not importable by %s" % sys.executable, file=sys.stderr)
        return 77
    torch.set_num_threads(2)
    if not (args.count or args.export or args.make_checkpoint):
        ap.error("give --count, --export DIR or --make-checkpoint PTH")
    if args.count:
        print(count_parameters(build_geometry_free_model()))
    if args.export:
        export(args.export, args.data_dir, args.seed, checkpoint=args.checkpoint, dtype=args.dtype)
    if args.make_checkpoint:
        make_checkpoint(args.make_checkpoint, args.data_dir, args.seed, args.steps)
    return 0


if __name__ == "__main__":
    sys.exit(main())
