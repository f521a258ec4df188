#!/usr/bin/env python3
"""The `compare_methods` example: every interpolator — Embedded, IDW, MLS, RBF, Ridge, the β-VAE
and the network — through one function template on the authors' bunny, a quick run (16 training
frames, 4 held-out, one epoch for the learned ones). One JSON line per method, the concept flags
as the library declares them, finite errors, the linear baselines ordered as the bunny's linear
family makes them (ridge far below Embedded), and bad input mapped to exit codes.

    /usr/bin/python3 tests/cli/test_compare_methods.py COMPARE_METHODS_EXE DATA_DIR

Exit 0: all checks passed; 1: a check failed."""
import json
import math
import os
import subprocess
import sys

from checks import check, finish

EXE, DATA = sys.argv[1], sys.argv[2]
bunny = os.path.join(DATA, "bunny")
check(os.path.exists(os.path.join(bunny, "train_frames.npz")), f"the bundled bunny data is missing under {bunny}")

p = subprocess.run([EXE, "--data-dir", bunny, "--train-frames", "16", "--test-frames", "4", "--epochs", "1", "--vae-epochs", "1"],
                   capture_output=True, text=True, timeout=900, env=dict(os.environ, OMP_NUM_THREADS="2"))
check(p.returncode == 0, f"compare_methods exits 0 (got {p.returncode}: {p.stderr.strip()[-2000:]})")
rows = [json.loads(l) for l in p.stdout.strip().splitlines() if l.startswith("{")]
names = [r.get("method") for r in rows]
check(names == ["embedded", "idw", "mls", "rbf", "ridge", "local_linear", "beta_vae", "network"], f"every method, in order: {names}")
flags = {r["method"]: (r["trainable"], r["needs_neighborhoods"]) for r in rows}
expect = {"embedded": (False, False), "idw": (False, True), "mls": (False, True), "rbf": (False, True),
          "ridge": (True, False), "local_linear": (True, True), "beta_vae": (True, False), "network": (True, True)}
for name, want in expect.items():
    check(flags.get(name) == want, f"{name}: (trainable, needs_neighborhoods) = {flags.get(name)}, expected {want}")
err = {r["method"]: r["relative_error"]["mean"] for r in rows}
for name, e in err.items():
    check(math.isfinite(e) and e > 0, f"{name}: finite positive relative mean error ({e})")
    r = next(x for x in rows if x["method"] == name)
    check(r["seconds_per_frame"] > 0 and r["fit_and_train_seconds"] >= 0, f"{name}: timings reported")
if "ridge" in err and "embedded" in err:
    check(err["ridge"] < 0.1 * err["embedded"], f"ridge far below Embedded on the bunny's linear family: {err}")
if "network" in err and "embedded" in err:  # residual over Embedded: one epoch cannot move it far
    check(err["network"] < 2 * err["embedded"], f"the residual network starts at Embedded: {err}")

p = subprocess.run([EXE, "--data-dir", os.path.join(DATA, "no_such_folder")], capture_output=True, text=True, timeout=60)
check(p.returncode == 2 and "no_such_folder" in p.stderr, f"a missing data folder: exit 2 naming it (got {p.returncode}: {p.stderr.strip()})")
finish()
