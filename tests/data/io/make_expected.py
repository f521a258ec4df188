"""Writes expected.json: what meshio (the peer) reports for each fixture of this folder.

Run with Debian's interpreter: /usr/bin/python3 make_expected.py  (python3-meshio 5.0, numpy).
Volumes are sums of signed tet volumes (v1-v0).((v2-v0)x(v3-v0))/6 over meshio's arrays.
Files meshio cannot read (gmsh -save_all 4.1, TetGen 10-node) are parsed here with numpy only.
"""
import json
import re
from collections import Counter

import meshio
import numpy as np


def stats(points, tets, tris):
    p = np.asarray(points, dtype=float)
    t = np.asarray(tets, dtype=np.int64).reshape(-1, 4)
    a, b, c, d = (p[t[:, i]] for i in range(4))
    vol = np.einsum("ij,ij->i", b - a, np.cross(c - a, d - a)) / 6.0
    return {
        "nodes": int(len(p)),
        "tets": int(len(t)),
        "tris": int(len(np.asarray(tris).reshape(-1, 3))),
        "bbox_min": p.min(axis=0).tolist(),
        "bbox_max": p.max(axis=0).tolist(),
        "volume": float(vol.sum()),
        "positive_tets": int((vol > 0).sum()),
    }


def via_meshio(name, **kw):
    m = meshio.read(name, **kw)
    tets = np.concatenate([c.data for c in m.cells if c.type == "tetra"] or [np.zeros((0, 4), int)])
    tris = np.concatenate([c.data for c in m.cells if c.type == "triangle"] or [np.zeros((0, 3), int)])
    return stats(m.points, tets, tris)


def msh41_all(name):
    """Element type histogram of a gmsh 4.1 ASCII file (meshio 5.0 rejects -save_all files)."""
    text = open(name).read()
    nodes = text.split("$Nodes\n")[1].split("$EndNodes")[0].split("\n")
    nblocks, nnodes = map(int, nodes[0].split()[:2])
    els = text.split("$Elements\n")[1].split("$EndElements")[0].strip().split("\n")
    hist = Counter()
    i = 1
    while i < len(els):
        dim, tag, etype, n = map(int, els[i].split())
        hist[etype] += n
        i += 1 + n
    return {"nodes": nnodes, "element_types": {str(k): v for k, v in sorted(hist.items())}}


def tetgen_10(prefix):
    rows = lambda f: [l.split() for l in open(f) if l.split() and not l.startswith("#")]
    n, e = rows(prefix + ".node"), rows(prefix + ".ele")
    p = np.array([[float(x) for x in r[1:4]] for r in n[1:]])
    base = int(n[1][0])
    t = np.array([[int(x) for x in r[1:5]] for r in e[1:]]) - base
    f = rows(prefix + ".face")
    s = stats(p, t, np.zeros((len(f) - 1, 3), int))
    s["nodes_per_tet"] = int(e[0][1])
    return s


out = {
    "cube_msh22.msh": via_meshio("cube_msh22.msh"),
    "cube_msh41.msh": via_meshio("cube_msh41.msh"),
    "cube_meshio.mesh": via_meshio("cube_meshio.mesh"),
    "cube_gmsh.mesh": via_meshio("cube_gmsh.mesh"),
    "cube_meshio.node": via_meshio("cube_meshio.node"),
    "cube.1.node": via_meshio("cube.1.node"),
    "cubez.1.node": tetgen_10("cubez.1"),
    "cube_msh41_all.msh": msh41_all("cube_msh41_all.msh"),
    "cube_msh22_all.msh": via_meshio("cube_msh22_all.msh"),
}
m = meshio.read("cube_o2_msh41.msh")
types = Counter()
for c in m.cells:
    types[c.type] += int(len(c.data))
out["cube_o2_msh41.msh"] = {"nodes": int(len(m.points)), "element_types": dict(types)}
json.dump(out, open("expected.json", "w"), indent=1)
print(json.dumps(out, indent=1))
