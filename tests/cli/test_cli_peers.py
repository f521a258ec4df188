#!/usr/bin/env python3
"""`simsr info` / `simsr convert` against reference peers: Gmsh (live, .msh 2.2 and 4.1), meshio
(MEDIT, TetGen, VTU it writes or reads back) and numpy (volumes, bounding boxes).

    /usr/bin/python3 tests/cli/test_cli_peers.py SIMSR_EXE WORK_DIR DATA_DIR

Exit 0: all checks passed; 1: a check failed; 77: a peer (gmsh, meshio, numpy) is missing (1 with SIMSR_REQUIRE_PEERS=1, as in CI).
Run with Debian's /usr/bin/python3 (python3-meshio, python3-numpy, gmsh)."""
import json
import os
import re
import shutil
import subprocess
import sys

from checks import check, finish, missing_peer

try:
    import numpy as np
    import meshio
except ImportError as e:  # peer missing: skip, do not pass silently
    missing_peer(e)

SIMSR, WORK, DATA = sys.argv[1], sys.argv[2], sys.argv[3]
os.makedirs(WORK, exist_ok=True)


def simsr(*args, expect=0):
    p = subprocess.run([SIMSR, *args], capture_output=True, text=True)
    check(p.returncode == expect, f"simsr {' '.join(args)}: exit {p.returncode}, expected {expect}; stderr: {p.stderr.strip()}")
    return p


def info(path):
    p = simsr("info", path)
    return json.loads(p.stdout) if p.returncode == 0 else {}


def tet_volume(points, tets):
    a, b, c, d = (points[tets[:, i]] for i in range(4))
    return float(np.einsum("ij,ij->i", b - a, np.cross(c - a, d - a)).sum() / 6.0)


def cells(m, kind):
    return np.concatenate([c.data for c in m.cells if c.type == kind]) if any(c.type == kind for c in m.cells) else np.zeros((0, 4 if kind == "tetra" else 3), int)


def agree_with_meshio(path, m, what):
    """simsr info of `path` against meshio's arrays `m` of the same mesh."""
    j = info(path)
    tets, tris = cells(m, "tetra"), cells(m, "triangle")
    check(j.get("vertices") == len(m.points), f"{what}: vertices {j.get('vertices')} vs meshio {len(m.points)}")
    check(j.get("tets", 0) == len(tets), f"{what}: tets {j.get('tets')} vs meshio {len(tets)}")
    check(j.get("triangles", 0) == len(tris), f"{what}: triangles {j.get('triangles')} vs meshio {len(tris)}")
    vol = tet_volume(m.points, tets)
    check(abs(j.get("volume", 0) - vol) <= 1e-12 * max(1, abs(vol)), f"{what}: volume {j.get('volume')} vs numpy {vol}")
    bbox = [m.points.min(0).tolist(), m.points.max(0).tolist()]
    check(np.allclose(j.get("bbox"), bbox, rtol=0, atol=1e-15), f"{what}: bbox {j.get('bbox')} vs {bbox}")
    return j


# --- 1. Gmsh writes the same sphere-in-box mesh in 2.2 and 4.1; gmsh's own counts are the truth.
if shutil.which("gmsh") is None:
    missing_peer("gmsh not found")
geo = os.path.join(WORK, "ball.geo")
with open(geo, "w") as f:
    f.write('SetFactory("OpenCASCADE");\nSphere(1) = {0.1, -0.2, 0.3, 1.0};\n'
            'Physical Volume("flesh", 7) = {1};\nPhysical Surface("skin", 3) = {1};\nMesh.CharacteristicLengthMax = 0.3;\n')
gmsh_counts = {}
for version in ("2.2", "4.1"):
    out = os.path.join(WORK, f"ball{version.replace('.', '')}.msh")
    p = subprocess.run(["gmsh", "-3", geo, "-format", f"msh{version.replace('.', '')}", "-o", out], capture_output=True, text=True)
    check(p.returncode == 0, f"gmsh {version} failed: {p.stderr}")
    # What gmsh itself reads back from the file it wrote (its meshing log also counts the
    # seam lines and points that the physical groups leave out of the file).
    p = subprocess.run(["gmsh", out, "-0", "-o", os.path.join(WORK, "readback.msh")], capture_output=True, text=True)
    nodes = int(re.findall(r"Info\s*:\s*(\d+) nodes", p.stdout)[-1])
    elements = int(re.findall(r"Info\s*:\s*(\d+) elements", p.stdout)[-1])
    gmsh_counts[version] = (nodes, elements)
    j = info(out)
    check(j.get("format") == f"msh {version}", f"format {j.get('format')} for {out}")
    check(j.get("vertices") == nodes, f"msh {version}: vertices {j.get('vertices')} vs gmsh {nodes}")
    check(j.get("tets", 0) + j.get("triangles", 0) == elements,
          f"msh {version}: tets+triangles {j.get('tets')}+{j.get('triangles')} vs gmsh {elements} elements")
    check(j.get("inverted_tets") == 0, f"msh {version}: gmsh tets should be positively oriented")
    m = meshio.read(out)
    agree_with_meshio(out, m, f"msh {version} vs meshio")
check(gmsh_counts["2.2"] == gmsh_counts["4.1"], f"gmsh counts differ between versions: {gmsh_counts}")
j22, j41 = info(os.path.join(WORK, "ball22.msh")), info(os.path.join(WORK, "ball41.msh"))
check(j22.get("volume") == j41.get("volume"), "msh 2.2 and 4.1 volumes differ")
check(0.9 * 4 / 3 * np.pi < j41.get("volume", 0) < 4 / 3 * np.pi, f"inscribed ball volume {j41.get('volume')} not just below 4π/3")

# --- 2. meshio writes MEDIT and TetGen files of the same mesh; simsr reads what meshio wrote.
ball = meshio.read(os.path.join(WORK, "ball41.msh"))
ball = meshio.Mesh(ball.points, [("tetra", cells(ball, "tetra")), ("triangle", cells(ball, "triangle"))])
ball_tets = meshio.Mesh(ball.points, [("tetra", cells(ball, "tetra"))])
meshio.write(os.path.join(WORK, "ball_meshio.mesh"), ball, file_format="medit")
agree_with_meshio(os.path.join(WORK, "ball_meshio.mesh"), meshio.read(os.path.join(WORK, "ball_meshio.mesh")), "medit written by meshio")
meshio.write(os.path.join(WORK, "ball_meshio.node"), ball_tets, file_format="tetgen")
agree_with_meshio(os.path.join(WORK, "ball_meshio.ele"), ball_tets, "tetgen written by meshio")

# --- 3. simsr convert; meshio reads back what simsr wrote: points and cells equal.
src = os.path.join(WORK, "ball41.msh")
for ext, fmt in ((".vtu", "vtu"), (".mesh", "medit"), (".msh", "gmsh")):
    out = os.path.join(WORK, "converted" + ext)
    simsr("convert", src, out)
    back = meshio.read(out, file_format=fmt)
    check(np.array_equal(back.points, ball.points), f"{ext}: points differ after convert (max {np.abs(back.points - ball.points).max()})")
    for kind in ("tetra", "triangle"):
        check(np.array_equal(cells(back, kind), cells(ball, kind)), f"{ext}: {kind} cells differ after convert")
out = os.path.join(WORK, "converted22.msh")
simsr("convert", "--msh-version", "2.2", src, out)
check(np.array_equal(meshio.read(out).points, ball.points), "msh 2.2 convert: points differ")
simsr("convert", src, os.path.join(WORK, "converted.node"))
back = meshio.read(os.path.join(WORK, "converted.node"), file_format="tetgen")
check(np.array_equal(back.points, ball.points) and np.array_equal(cells(back, "tetra"), cells(ball, "tetra")), "tetgen convert differs")
simsr("convert", src, os.path.join(WORK, "both.obj"), expect=5)  # tets and triangles do not fit one OBJ
simsr("convert", "--keep", "tets", src, os.path.join(WORK, "tets.obj"))
jt = info(os.path.join(WORK, "tets.obj"))
check(jt.get("tets") == len(cells(ball, "tetra")) and jt.get("volume") == j41.get("volume"), "tet-soup OBJ round trip")

# --- 4. The bundled data.
bunny = os.path.join(DATA, "bunny", "lrestshape.obj")
if os.path.exists(bunny):
    j = info(bunny)
    check(j.get("vertices") == 1747 and j.get("tets") == 4896, f"bunny LR: {j}")
    check(j.get("inverted_tets") == 0, "bunny LR has inverted tets")
    j = info(os.path.join(DATA, "bunny", "train_frames.npz"))
    check(j.get("arrays", {}).get("lowres", {}).get("shape") == [256, 1747, 3], f"train_frames lowres: {j}")
    check(j.get("arrays", {}).get("frame", {}).get("dtype") == "int64", "train_frames frame dtype")

# --- 5. simsr knn against scipy's cKDTree; simsr neighbors on the bunny.
try:
    from scipy.spatial import cKDTree
except ImportError:
    cKDTree = None
if cKDTree is not None:
    rng = np.random.default_rng(7)
    P, Q = rng.random((2000, 3)), rng.random((700, 3))
    np.save(os.path.join(WORK, "P.npy"), P)
    np.save(os.path.join(WORK, "Q.npy"), Q)
    p = simsr("knn", "--points", os.path.join(WORK, "P.npy"), "--queries", os.path.join(WORK, "Q.npy"), "--k", "9",
              "--out", os.path.join(WORK, "knn.npz"))
    timing = json.loads(p.stdout) if p.returncode == 0 else {}
    check({"build_ms", "query_ms"} <= set(timing), f"knn timing JSON: {p.stdout}")
    z = np.load(os.path.join(WORK, "knn.npz"))
    d, i = cKDTree(P).query(Q, 9)
    check(z["indices"].dtype == np.int64 and z["distances"].dtype == np.float64, "knn dtypes")
    check(np.array_equal(z["indices"], i), "knn indices differ from cKDTree")
    check(np.abs(z["distances"] - d).max() <= 1e-12, "knn distances differ from cKDTree")
    simsr("knn", "--points", os.path.join(WORK, "P.npy"), "--queries", os.path.join(WORK, "Q.npy"), "--k", "2001",
          "--out", os.path.join(WORK, "knn.npz"), expect=5)
if os.path.exists(bunny):
    out = os.path.join(WORK, "bunny_neighbors.npz")
    p = simsr("neighbors", "--lr-rest", bunny, "--hr-rest", os.path.join(DATA, "bunny", "hrestshape.obj"), "--k", "20",
              "--lr-k", "5", "--out", out)
    z = np.load(out)
    check(z["indices"].shape == (2503, 20) and z["lr_indices"].shape == (1747, 5), "neighbors shapes")
    check(np.array_equal(z["lr_indices"][:, 0], np.arange(1747)), "LR geodesic graph: self first")
    check(np.all(np.diff(z["distances"], axis=1) >= 0), "neighbourhood distances sorted")
    mapped = z["lr_to_hr"]
    check(len(np.unique(mapped)) == 1747, "LR→HR assignment is one-to-one")
    check(np.array_equal(z["indices"][mapped, 0], np.arange(1747)) and np.all(z["distances"][mapped, 0] == 0),
          "each mapped HR vertex has its own LR vertex first at distance 0")

    # baselines: ridge (the data-driven linear baseline) must beat Embedded on held-out bunny frames
    bdir = os.path.join(WORK, "baselines")
    p = simsr("baselines", "--lr-rest", bunny, "--hr-rest", os.path.join(DATA, "bunny", "hrestshape.obj"), "--frames",
              os.path.join(DATA, "bunny", "train_frames.npz"), "--methods", "embedded", "ridge", "--holdout-every", "8",
              "--out-dir", bdir)
    res = json.loads(p.stdout) if p.returncode == 0 else {"methods": {}}
    check(res.get("test_frames") == 32 and res.get("train_frames") == 224, f"baselines split: {p.stdout}")
    m = res["methods"]
    check("ridge" in m and "embedded" in m and m["ridge"]["relative_mean"] < m["embedded"]["relative_mean"], f"ridge vs embedded: {m}")
    for f in ("statistics.csv", "frame_errors.csv", "frame_errors.svg", "heatmaps.pvd"):
        check(os.path.exists(os.path.join(bdir, f)), f"baselines did not write {f}")
    hm = meshio.read(os.path.join(bdir, "heatmaps", "heatmaps_000000.vtu"))
    check(set(hm.point_data) == {"error_embedded", "error_ridge"} and len(hm.points) == 2503, "heatmap arrays")

    # several --frames files are one set, a sequence each; --test-sequences holds whole ones out
    z = np.load(os.path.join(DATA, "bunny", "train_frames.npz"))
    for name, rows in (("first", slice(0, 160)), ("second", slice(160, 256))):
        np.savez(os.path.join(WORK, name + ".npz"), lowres=z["lowres"][rows], highres=z["highres"][rows], frame=np.arange(rows.stop - rows.start))
    base = ["baselines", "--lr-rest", bunny, "--hr-rest", os.path.join(DATA, "bunny", "hrestshape.obj"), "--frames",
            os.path.join(WORK, "first.npz") + "," + os.path.join(WORK, "second.npz"), "--methods", "embedded,ridge", "--out-dir", bdir + "_seq"]
    p = simsr(*base, "--test-sequences", "second")
    res = json.loads(p.stdout) if p.returncode == 0 else {"methods": {}}
    check(res.get("train_frames") == 160 and res.get("test_frames") == 96 and res.get("test_sequences") == ["second"], f"baselines by sequence: {p.stdout}")
    check(set(res["methods"]) == {"embedded", "ridge"}, f"baselines by sequence: {res['methods']}")
    bad_seq = subprocess.run([SIMSR, *base, "--test-sequences", "third"], capture_output=True, text=True)
    check(bad_seq.returncode != 0 and "no sequence 'third'" in bad_seq.stderr, f"unknown sequence: {bad_seq.returncode} {bad_seq.stderr}")
    both = subprocess.run([SIMSR, *base, "--test-sequences", "second", "--holdout-every", "4"], capture_output=True, text=True)
    check(both.returncode != 0 and "excludes" in both.stderr, f"--test-sequences with --holdout-every: {both.returncode} {both.stderr}")

# --- 6. Errors: message names the file, exit code by error class.
bad = os.path.join(WORK, "bad.msh")
with open(bad, "w") as f:
    f.write("$MeshFormat\n4.1 0 8\n$EndMeshFormat\n$Nodes\n1 999999999999 1 3\n")
p = simsr("info", bad, expect=2)
check(bad in p.stderr, f"error message does not name the file: {p.stderr}")
simsr("info", os.path.join(WORK, "missing.obj"), expect=2)
simsr("info", os.path.join(WORK, "x.unknown"), expect=5)
simsr("convert", src, expect=64)

finish()
