#!/usr/bin/env python3
"""`simsr eval` on small .npz fixtures written here: exact values (zero error, a constant offset),
numpy's statistics of random errors, frame matching by `frame` id, the --out files, and the errors
(shape exit code 4, NaN/Inf and wrong dtypes exit code 5, naming file, frame and vertex).

    /usr/bin/python3 tests/cli/test_cli_eval.py SIMSR_EXE WORK_DIR

Exit 0: all checks passed; 1: a check failed; 77: numpy is missing (1 with SIMSR_REQUIRE_PEERS=1, as in CI). meshio, where present, reads
the heatmap back."""
import csv
import json
import math
import os
import subprocess
import sys

from checks import check, finish, missing_peer

try:
    import numpy as np
except ImportError as e:  # peer missing: skip, do not pass silently
    missing_peer(e)
try:
    import meshio
except ImportError:
    meshio = None

SIMSR, WORK = sys.argv[1], sys.argv[2]
os.makedirs(WORK, exist_ok=True)


def simsr(*args, expect=0):
    p = subprocess.run([SIMSR, *args], capture_output=True, text=True)
    check(p.returncode == expect, f"simsr {' '.join(args)}: exit {p.returncode}, expected {expect}; stderr: {p.stderr.strip()}")
    return p


def path(name):
    return os.path.join(WORK, name)


def eval_json(pred, truth, *extra, expect=0):
    p = simsr("eval", "--pred", pred, "--truth", truth, "--hr-rest", path("cube.obj"), *extra, expect=expect)
    if expect != 0:
        return p
    try:
        return json.loads(p.stdout)
    except json.JSONDecodeError:
        check(False, f"eval stdout is not JSON: {p.stdout!r}")
        return {"error": {}, "relative_error": {}}


# --- Fixtures: a 2×3×4 box (8 vertices, 12 triangles; bbox diagonal sqrt(29)) and F frames of it
# with dyadic coordinates, so that offsets of 0.5 or 0.375 are exact in float32 and float64.
V = np.array([[x, y, z] for x in (0, 2) for y in (0, 3) for z in (0, 4)], float)
T = np.array([[0, 1, 3], [0, 3, 2], [4, 6, 7], [4, 7, 5], [0, 4, 5], [0, 5, 1],
              [2, 3, 7], [2, 7, 6], [0, 2, 6], [0, 6, 4], [1, 5, 7], [1, 7, 3]])
with open(path("cube.obj"), "w") as f:
    f.writelines(f"v {x:g} {y:g} {z:g}\n" for x, y, z in V)
    f.writelines(f"f {a + 1} {b + 1} {c + 1}\n" for a, b, c in T)
DIAG = math.sqrt(29.0)
F, M = 6, len(V)
rng = np.random.default_rng(3)
truth = V[None] + np.round(rng.normal(size=(F, M, 3)) * 64) / 256  # dyadic: exact in float32
np.savez(path("truth.npz"), highres=truth)
STATS = ("mean", "median", "std", "max", "min")

# --- 1. Identical prediction: every statistic 0.
j = eval_json(path("truth.npz"), path("truth.npz"))
check(j.get("frames") == F and j.get("vertices") == M, f"identical: counts {j}")
check(all(j["error"].get(k) == 0.0 for k in STATS), f"identical: error {j['error']}")
check(all(j["relative_error"].get(k) == 0.0 for k in STATS), f"identical: relative error {j['relative_error']}")
check(abs(j.get("bbox_diagonal", 0) - DIAG) <= 1e-15 * DIAG, f"bbox diagonal {j.get('bbox_diagonal')} vs {DIAG}")

# --- 2. A constant offset of d on every vertex (a different direction per frame): mean = median =
# max = min = d exactly, std 0; float32 prediction against float64 truth.
d = 0.5
dirs = np.array([[1, 0, 0], [0, -1, 0], [0, 0, 1], [-1, 0, 0], [0, 1, 0], [0, 0, -1]], float)
offset = truth + d * dirs[:, None, :]
np.savez(path("offset.npz"), highres=offset)
np.savez(path("offset32.npz"), highres=offset.astype(np.float32))
for name in ("offset.npz", "offset32.npz"):
    j = eval_json(path(name), path("truth.npz"))
    e = j["error"]
    check(e.get("mean") == d and e.get("median") == d and e.get("max") == d and e.get("min") == d and e.get("std") == 0,
          f"{name}: constant offset {d} gives {e}")
    check(j["relative_error"].get("mean") == d / DIAG, f"{name}: relative mean {j['relative_error'].get('mean')} vs {d / DIAG}")
# --frames-key names the array in both files.
np.savez(path("positions.npz"), positions=offset)
np.savez(path("truth_positions.npz"), positions=truth)
j = eval_json(path("positions.npz"), path("truth_positions.npz"), "--frames-key", "positions")
check(j["error"].get("mean") == d and j["error"].get("min") == d, f"--frames-key positions: {j['error']}")
# An offset of (0.3, 0.4, 1.2) has length 1.3 up to rounding of the inputs.
np.savez(path("offset3d.npz"), highres=truth + np.array([0.3, 0.4, 1.2]))
j = eval_json(path("offset3d.npz"), path("truth.npz"))
check(all(abs(j["error"].get(k, 0) - 1.3) <= 1e-14 for k in ("mean", "median", "max", "min")), f"offset (0.3, 0.4, 1.2): {j['error']}")

# --- 3. Random errors against numpy's statistics (std with ddof 0, median of an even count).
pred = truth + rng.normal(size=truth.shape) * 0.1
np.savez(path("random.npz"), highres=pred)
err = np.linalg.norm(pred - truth, axis=2)
ref = {"mean": err.mean(), "median": np.median(err), "std": err.std(), "max": err.max(), "min": err.min()}
j = eval_json(path("random.npz"), path("truth.npz"))
for k, v in ref.items():
    check(abs(j["error"].get(k, -1) - v) <= 1e-12 * v, f"random: {k} {j['error'].get(k)} vs numpy {v}")
    check(abs(j["relative_error"].get(k, -1) - v / DIAG) <= 1e-12 * v, f"random: relative {k} vs numpy")

# --- 4. Frame matching by id: the truth holds all frames, the prediction a shuffled subset.
ids = np.array([10, 11, 12, 13, 14, 15], np.int64)
np.savez(path("truth_ids.npz"), highres=truth, frame=ids)
subset = [4, 1, 3]
np.savez(path("subset.npz"), highres=pred[subset], frame=ids[subset])
sub = err[subset]
j = eval_json(path("subset.npz"), path("truth_ids.npz"))
check(j.get("frames") == 3 and abs(j["error"].get("mean", -1) - sub.mean()) <= 1e-12 * sub.mean()
      and abs(j["error"].get("max", -1) - sub.max()) <= 1e-12 * sub.max(), f"frame ids: {j} vs mean {sub.mean()}")
np.savez(path("subset_noids.npz"), highres=pred[subset])  # no ids: counts must match
p = eval_json(path("subset_noids.npz"), path("truth_ids.npz"), expect=4)
check("frame" in p.stderr and path("truth_ids.npz") in p.stderr, f"frame-count mismatch message: {p.stderr}")
np.savez(path("subset_badid.npz"), highres=pred[subset], frame=np.array([14, 99, 13]))
p = eval_json(path("subset_badid.npz"), path("truth_ids.npz"), expect=4)
check("99" in p.stderr, f"unknown frame id message: {p.stderr}")

# --- 5. --out: frame_errors.csv/.svg, error_heatmap.vtu, statistics.csv.
out = path("eval_out")
j = eval_json(path("subset.npz"), path("truth_ids.npz"), "--out", out)
for name in ("frame_errors.csv", "frame_errors.svg", "error_heatmap.vtu", "statistics.csv"):
    check(os.path.exists(os.path.join(out, name)), f"--out did not write {name}")
with open(os.path.join(out, "frame_errors.csv")) as f:
    rows = list(csv.DictReader(f))
check([int(r["frame"]) for r in rows] == [14, 11, 13], f"frame_errors.csv frame ids: {[r.get('frame') for r in rows]}")
check(all(abs(float(r["mean"]) - sub[i].mean()) <= 1e-9 * sub[i].mean() and abs(float(r["max"]) - sub[i].max()) <= 1e-9 * sub[i].max()
          for i, r in enumerate(rows)), "frame_errors.csv per-frame mean/max vs numpy")
with open(os.path.join(out, "statistics.csv")) as f:
    srow = list(csv.DictReader(f))
check(len(srow) == 1 and int(srow[0]["count"]) == sub.size and abs(float(srow[0]["mean"]) - sub.mean()) <= 1e-9 * sub.mean(),
      f"statistics.csv: {srow}")
if meshio is not None:
    hm = meshio.read(os.path.join(out, "error_heatmap.vtu"))
    check(np.array_equal(hm.points, V) and np.array_equal(hm.cells_dict.get("triangle"), T), "heatmap: the HR rest surface")
    check(np.allclose(hm.point_data["mean_error"], sub.mean(axis=0), rtol=1e-14, atol=0), "heatmap: per-vertex mean error")
    check(np.array_equal(hm.point_data["max_error"], sub.max(axis=0)), "heatmap: per-vertex max error")

# --- 6. Errors.
np.savez(path("fewer.npz"), highres=truth[:4])  # frame counts differ, no ids
p = eval_json(path("fewer.npz"), path("truth.npz"), expect=4)
check("(4, 8, 3)" in p.stderr and "(6, 8, 3)" in p.stderr, f"frame-count mismatch names both shapes: {p.stderr}")
np.savez(path("wrong_m.npz"), highres=np.zeros((F, M + 1, 3)))  # vertex count differs from the rest surface
p = eval_json(path("wrong_m.npz"), path("truth.npz"), expect=4)
check(path("wrong_m.npz") in p.stderr, f"vertex-count mismatch names the file: {p.stderr}")
nan = truth.copy()
nan[2, 5, 1] = np.nan
np.savez(path("nan.npz"), highres=nan)
p = eval_json(path("nan.npz"), path("truth.npz"), expect=5)
check(path("nan.npz") in p.stderr and "frame 2" in p.stderr and "vertex 5" in p.stderr, f"NaN message: {p.stderr}")
inf = truth.astype(np.float32)
inf[4, 7, 0] = np.inf
np.savez(path("inf_ids.npz"), highres=inf, frame=ids)
p = eval_json(path("subset.npz"), path("inf_ids.npz"), expect=5)
check(path("inf_ids.npz") in p.stderr and "frame 4 (id 14)" in p.stderr and "vertex 7" in p.stderr, f"Inf message: {p.stderr}")
np.savez(path("ints.npz"), highres=np.zeros((F, M, 3), np.int64))
p = eval_json(path("ints.npz"), path("truth.npz"), expect=5)
check("float32 or float64" in p.stderr, f"integer dtype message: {p.stderr}")
eval_json(path("truth.npz"), path("truth.npz"), "--frames-key", "lowres", expect=5)  # no such array
simsr("eval", "--pred", path("truth.npz"), expect=64)

finish()
