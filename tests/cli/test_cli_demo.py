#!/usr/bin/env python3
"""`simsr demo` on the authors' bunny (baselines only: the network is tested in tests/pipeline):
Table 1 on stdout equal to report.json and statistics.csv, a rerun reuses every stage, the Fig. 6
views render (scripts/render_comparison.py: non-blank panels, errors coloured), bad options fail
with their exit codes.

    /usr/bin/python3 tests/cli/test_cli_demo.py SIMSR WORK_DIR DATA_DIR REPO_DIR NODE NODE_MODULES

Then the report page in headless chromium (tests/cli/test_report_page.js, node + playwright-core).
Exit 0: all passed; 1: a check failed; 77: numpy, python3-vtk9, the data, node, playwright-core or
chromium missing (1 under SIMSR_REQUIRE_PEERS=1)."""
import csv
import json
import os
import shutil
import subprocess
import sys

from checks import check, finish, missing_peer

SIMSR, WORK, DATA, REPO, NODE, MODULES = sys.argv[1:7]
REQUIRE = os.environ.get("SIMSR_REQUIRE_PEERS", "0") not in ("", "0")
try:
    import numpy as np
    import vtk
    from vtk.util.numpy_support import vtk_to_numpy
except ImportError as e:
    missing_peer(e)
if not os.path.exists(os.path.join(DATA, "bunny", "train_frames.npz")):
    missing_peer(f"{DATA}/bunny/train_frames.npz (the data folder)")

out = os.path.join(WORK, "demo")
shutil.rmtree(out, ignore_errors=True)
cmd = [SIMSR, "demo", "--dataset", "bunny", "--data", DATA, "--out", out, "--methods", "embedded,idw,ridge", "--no-network"]
p = subprocess.run(cmd, capture_output=True, text=True)
check(p.returncode == 0, f"simsr demo: exit {p.returncode}: {p.stderr[-2000:]}")
report = json.load(open(os.path.join(out, "report.json")))
check(report["test_frames"] == 64 and report["train_frames"] == 192, f"bunny split: {report['train_frames']} / {report['test_frames']}")
names = list(report["table1"])
check(names == ["embedded", "idw", "ridge"], f"methods in order: {names}")
rows = {r["method"]: r for r in csv.DictReader(open(os.path.join(out, "results", "statistics.csv")))}
for m in names:
    for kind, prefix in (("raw", ""), ("relative", "rel_"), ("normalized", "norm_")):
        for stat in ("mean", "median", "std", "max", "min"):
            a, b = report["table1"][m][kind][stat], float(rows[m][prefix + stat])
            check(abs(a - b) <= 1e-9 * max(abs(a), 1e-300), f"{m} {kind} {stat}: report {a} vs statistics.csv {b}")
# the printed table: the relative block's means, to the 5 digits printed
lines = p.stdout.splitlines()
start = next(i for i, l in enumerate(lines) if l.strip().startswith("method") and "(relative)" in l)
for m, line in zip(names, lines[start + 1:start + 4]):
    fields = line.split()
    check(fields[0] == m, f"printed row {fields[0]} is {m}")
    check(abs(float(fields[1]) - report["table1"][m]["relative"]["mean"]) <= 1e-4 * report["table1"][m]["relative"]["mean"], f"{m}: printed mean {fields[1]}")
check(report["table1"]["ridge"]["relative"]["mean"] < 1e-4 < report["table1"]["embedded"]["relative"]["mean"],
      "the bunny's frames are a linear family: ridge below 1e-4 of the diagonal, Embedded above")
for f in ("frame_errors.csv", "frame_errors.svg", "heatmaps.pvd"):
    check(os.path.exists(os.path.join(out, "results", f)), f"results/{f} written")

again = subprocess.run(cmd, capture_output=True, text=True)
check(again.returncode == 0, f"rerun: exit {again.returncode}")
reused = [l for l in again.stderr.splitlines() if "reused" in l]
check(len(reused) == 4, f"rerun reuses neighbors and the three methods: {len(reused)} lines")
check(json.load(open(os.path.join(out, "report.json")))["table1"] == report["table1"], "rerun: the same Table 1")

views = report["comparison_views"]
check(len(views) == 1, f"one comparison view (the bunny's hold-out): {views}")
png = os.path.join(WORK, "compare.png")
if os.path.exists(png):
    os.remove(png)
r = subprocess.run([sys.executable, os.path.join(REPO, "scripts", "render_comparison.py"), os.path.join(out, "results", "compare", views[0]),
                    "--out", png, "--size", "160"], capture_output=True, text=True)
check(r.returncode == 0, f"render_comparison.py: exit {r.returncode}: {r.stderr.strip()}")
if os.path.exists(png):
    rd = vtk.vtkPNGReader()
    rd.SetFileName(png)
    rd.Update()
    img = rd.GetOutput()
    w, h, _ = img.GetDimensions()
    check((w, h) == (5 * 160, 2 * 160), f"LR, 3 methods, truth × 2 rows of 160 px: {w}×{h}")
    rgb = vtk_to_numpy(img.GetPointData().GetScalars()).reshape(h, w, -1)[:, :, :3].astype(int)[::-1]
    for row in range(2):
        for col in range(5):
            if row == 1 and col == 4:
                continue  # no panel under the truth
            panel = rgb[row * 160:(row + 1) * 160, col * 160:(col + 1) * 160]
            drawn = (np.abs(panel - 255).sum(-1) > 60).mean()
            check(drawn > 0.05, f"panel ({row}, {col}) shows the surface: {drawn:.2f} drawn")
    emb = rgb[160:320, 160:320]
    check(((emb[:, :, 0] > emb[:, :, 2] + 80)).sum() > 20, "Embedded's error panel has red (large error) pixels")
# Fig. 7's layout (results/unseen/<sequence>/: rest_<method>.vtu beside each method, coloured by
# a field of the caller's choice), made here from the Fig. 6 folder: the rest_* files are not
# methods, the reference is the right-most panel, a field a method lacks is named
fig7 = os.path.join(WORK, "fig7")
shutil.rmtree(fig7, ignore_errors=True)
shutil.copytree(os.path.join(out, "results", "compare", views[0]), fig7)
shutil.copy(os.path.join(fig7, "truth.vtu"), os.path.join(fig7, "rest_ridge.vtu"))
os.remove(os.path.join(fig7, "truth.vtu"))
png7 = os.path.join(WORK, "fig7.png")
r = subprocess.run([sys.executable, os.path.join(REPO, "scripts", "render_comparison.py"), fig7, "--out", png7, "--size", "100",
                    "--reference", "rest_ridge", "--reference-title", "ridge, rest pose", "--field", "error"], capture_output=True, text=True)
check(r.returncode == 0 and "3 methods" in r.stdout, f"render_comparison.py --reference rest_ridge: exit {r.returncode}: {r.stdout.strip()} {r.stderr.strip()}")
if os.path.exists(png7):
    rd = vtk.vtkPNGReader()
    rd.SetFileName(png7)
    rd.Update()
    w, h, _ = rd.GetOutput().GetDimensions()
    check((w, h) == (5 * 100, 2 * 100), f"Fig. 7 layout: LR, 3 methods (rest_ridge not one), the reference: {w}×{h}")
r = subprocess.run([sys.executable, os.path.join(REPO, "scripts", "render_comparison.py"), fig7, "--out", png7, "--reference", "rest_ridge", "--field", "change"],
                   capture_output=True, text=True)
check(r.returncode == 2 and "no point data 'change'" in r.stderr, f"a field the views lack: exit 2 naming it ({r.returncode}: {r.stderr.strip()})")

bad = subprocess.run([sys.executable, os.path.join(REPO, "scripts", "render_comparison.py"), os.path.join(WORK, "missing"), "--out", png],
                     capture_output=True, text=True)
check(bad.returncode == 2 and "not found" in bad.stderr, f"render_comparison.py on a missing folder: exit {bad.returncode}")

bad = subprocess.run([SIMSR, "demo", "--dataset", "cat", "--out", out], capture_output=True, text=True)
check(bad.returncode == 64, f"--dataset cat: usage error 64, got {bad.returncode}")
bad = subprocess.run([SIMSR, "demo", "--dataset", "bunny", "--data", DATA, "--out", out, "--methods", "embedded,spline", "--no-network"],
                     capture_output=True, text=True)
check(bad.returncode == 5 and "spline" in bad.stderr, f"--methods spline: argument error 5 naming it, got {bad.returncode}: {bad.stderr.strip()}")

# The report page: loads from disk without console errors, Table 1 = report.json, the viewer draws.
check(os.path.exists(os.path.join(out, "report", "index.html")), "report/index.html written")
if not NODE or not MODULES:
    print("MISSING: node or the vendored node_modules (npm at configure time): the report page's browser test did not run")
    check(not REQUIRE, "SIMSR_REQUIRE_PEERS: the report page's browser test must run")
else:
    page = subprocess.run([NODE, os.path.join(REPO, "tests", "cli", "test_report_page.js"), out, MODULES], capture_output=True, text=True)
    print(page.stdout.strip())
    if page.returncode == 77:
        check(not REQUIRE, "SIMSR_REQUIRE_PEERS: the report page's browser test must run: " + page.stdout.strip())
    else:
        check(page.returncode == 0, f"report page in headless chromium: exit {page.returncode}: {page.stdout[-1500:]} {page.stderr[-1500:]}")

# simsr ablate: one variant trained (k = 5 is the upK = 10 network), its row printed with
# Embedded's beside it, the files written; a sweep beyond the neighbourhoods' k refused. On a
# copy of the bunny folder cut to its first 32 frames (the meshes and geodesic tables linked):
# every 2nd frame held out leaves 16 training frames, one step of the paper-size network instead
# of four (72 s of the test run here); the wiring under test is the same, and tests/pipeline's
# ablation test checks run_ablations' numbers.
small = os.path.join(WORK, "bunny32")
shutil.rmtree(small, ignore_errors=True)
os.makedirs(os.path.join(small, "bunny"))
for name in os.listdir(os.path.join(DATA, "bunny")):
    if name != "train_frames.npz":
        os.symlink(os.path.join(DATA, "bunny", name), os.path.join(small, "bunny", name))
with np.load(os.path.join(DATA, "bunny", "train_frames.npz")) as z:
    np.savez(os.path.join(small, "bunny", "train_frames.npz"), **{k: z[k][:32] for k in z.files})
out = os.path.join(WORK, "ablate")
shutil.rmtree(out, ignore_errors=True)
abl = subprocess.run([SIMSR, "ablate", "--dataset", "bunny", "--data", small, "--out", out, "--no-table2", "--upk-values", "10", "--knn-values", "5",
                      "--ablation-epochs", "1", "--batch-size", "16", "--holdout-every", "2"], capture_output=True, text=True)
check(abl.returncode == 0, f"simsr ablate: exit {abl.returncode}: {abl.stderr[-2000:]}")
if abl.returncode == 0:
    summary = json.load(open(os.path.join(out, "results", "ablations.json")))
    check(set(summary["variants"]) == {"upk10", "knn5"} and summary["variants"]["knn5"]["network"] == "abl_upk10", "ablate: knn5 is the upK = 10 network")
    check(abl.stderr.count("stage network-abl_upk10: running") == 1, "ablate: one training")
    printed = [l.split() for l in abl.stdout.splitlines() if l.startswith("upk10") or l.startswith("Embedded")]
    check(len(printed) == 2 and abs(float(printed[0][1]) - summary["variants"]["upk10"]["relative_mean_error"]) <= 1e-4 * summary["variants"]["upk10"]["relative_mean_error"]
          and abs(float(printed[1][1]) - summary["embedded"]["relative_mean"]) <= 1e-4 * summary["embedded"]["relative_mean"], f"ablate prints the JSON's errors: {abl.stdout}")
    for f in ("ablations.csv", "fig9_upk.svg", "fig9_knn.svg"):
        check(os.path.exists(os.path.join(out, "results", f)), f"ablate wrote results/{f}")
bad = subprocess.run([SIMSR, "ablate", "--dataset", "bunny", "--data", DATA, "--out", out, "--upk-values", "30"], capture_output=True, text=True)
check(bad.returncode == 5 and "interpolation neighbours 30" in bad.stderr, f"ablate --upk-values 30: argument error 5 naming it, got {bad.returncode}: {bad.stderr.strip()}")
finish()
