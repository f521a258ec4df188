#!/usr/bin/env python3
"""The thin-shell pipeline from the command line (issue #14): `simsr datagen --scenario sheet` at a
reduced size (3 cells, one Loop level: 16 / 49 vertices, one sequence), its files, its summary
and progress lines, a finished run reused, the same frames with `--linear-solver cholmod` and with
two sequences side by side (`--sequence-workers 2`), a coarser sheet beside the same fine one
taking its fine frames from another dataset (`--fine-cells`, `--fine-frames-from`), and bad
options named; `simsr demo --dataset sheet` at
the same size (5 sequences, the 5th held out; 3 epochs): its report, per-frame errors and views
(rendered by scripts/render_comparison.py --view oblique), the core paper's local-linear map and
network beside, a rerun that trains nothing, and the other --fine-target or --residual-lift refused as another run's
checkpoint.

    /usr/bin/python3 tests/cli/test_cli_cloth.py SIMSR_EXE WORK_DIR

Exit 0: all checks passed; 1: a check failed; 77: numpy is missing (1 with SIMSR_REQUIRE_PEERS=1)."""
import json
import os
import shutil
import subprocess
import sys

from checks import check, finish, missing_peer, tool

try:
    import numpy as np
except ImportError as e:  # peer missing: skip, do not pass silently
    missing_peer(e)

SIMSR, WORK = sys.argv[1], sys.argv[2]
shutil.rmtree(WORK, ignore_errors=True)
os.makedirs(WORK)
data = os.path.join(WORK, "sheet")


simsr = tool(SIMSR)


args = ["datagen", "--scenario", "sheet", "--cells", "3", "--levels", "1", "--sequences", "1", "--out", data]
p = simsr(*args)
summary = json.loads(p.stdout) if p.returncode == 0 else {}
check(summary.get("coarse", {}).get("vertices") == 16 and summary.get("fine", {}).get("vertices") == 49, f"16 / 49 vertices: {summary}")
seqs = summary.get("sequences", [])
check(len(seqs) == 1 and seqs[0].get("name") == "sheet_000" and seqs[0].get("split") == "train", f"one training sequence: {seqs}")
check(summary.get("seed") == 7, f"without --seed the demo's sequences (seed 7): {summary.get('seed')}")
check(summary.get("substeps") == 8, f"without --substeps the default (8): {summary.get('substeps')}")
newton = summary.get("newton", {})
check(newton.get("max_iterations") == 3 and newton.get("accept_at_max_iterations") is True and newton.get("hessian") == "projected",
      f"without --stepping inexact steps (at most 3 projected Newton iterations each): {newton}")
check(seqs and seqs[0].get("scene", {}).get("pole") == 1 and "heading_rad" in seqs[0]["scene"], f"the sequence's parameters (sequence 0: the pole): {seqs[:1]}")
frames = seqs[0].get("frames", 0) if seqs else 0
check(frames > 60, f"a sequence of seconds at 30 frames per second: {frames} frames")
check(p.stderr.count("sheet_000 frame ") >= frames // 10, "a progress line per 10 frames on stderr")
check(p.stderr.count("settle frame ") >= 4, "progress lines while the shared start settles (45 frames)")
for name in ("coarse_rest.obj", "fine_rest.obj", "cloth_data.json", "sheet_000.npz"):
    check(os.path.exists(os.path.join(data, name)), f"datagen wrote {name}")
if not os.path.exists(os.path.join(data, "sheet_000.npz")):
    finish()
z = np.load(os.path.join(data, "sheet_000.npz"))
check(z["lowres"].shape == (frames, 16, 3) and z["highres"].shape == (frames, 49, 3), f"frames x N x 3 and x M x 3: {z['lowres'].shape} {z['highres'].shape}")
check(np.isfinite(z["lowres"]).all() and np.isfinite(z["highres"]).all(), "finite frames")
# the sheet moved: the obstacle came down into it
lr = z["lowres"]
check(lr[:, :, 2].min() < -0.1, f"the sheet was pushed down: lowest {lr[:, :, 2].min():.3f} m")
# run again: the finished sequence is reused, nothing simulated
again = simsr(*args)
s2 = json.loads(again.stdout) if again.returncode == 0 else {}
check(s2.get("sequences", [{}])[0].get("reused") is True and "frame" not in again.stderr, "a second run reuses the finished sequence")
# the same data with CHOLMOD factoring the Newton steps (the test run builds the tool with it): the
# same frames to the factorizations' round-off, and a file the simplicial run reuses (the solver is
# no part of a dataset's fingerprint)
chol = os.path.join(WORK, "sheet_cholmod")
pc = simsr("datagen", "--scenario", "sheet", "--cells", "3", "--levels", "1", "--sequences", "1", "--linear-solver", "cholmod", "--out", chol)
if pc.returncode == 0:
    zc = np.load(os.path.join(chol, "sheet_000.npz"))
    gap = max(np.abs(zc["lowres"] - z["lowres"]).max(), np.abs(zc["highres"] - z["highres"]).max())
    check(gap < 1e-7, f"--linear-solver cholmod: the same frames as simplicial ({gap:.2e} m apart)")
    shutil.copy(os.path.join(chol, "sheet_000.npz"), os.path.join(data, "sheet_000.npz"))
    reuse = simsr(*args)
    check(reuse.returncode == 0 and "frame" not in reuse.stderr, "the simplicial run reuses the CHOLMOD run's file")
# two sequences side by side (--sequence-workers 2) and one at a time: bitwise the same files
side = {}
for w in ("1", "2"):
    out = os.path.join(WORK, f"sheet_workers{w}")
    pw = simsr("datagen", "--scenario", "sheet", "--cells", "3", "--levels", "1", "--sequences", "2", "--sequence-workers", w, "--out", out)
    check(pw.returncode == 0 and pw.stderr.count("sheet_001 frame ") > 0, f"--sequence-workers {w}: both sequences simulated")
    side[w] = out
if all(os.path.exists(os.path.join(o, "sheet_001.npz")) for o in side.values()):
    for name in ("sheet_000.npz", "sheet_001.npz"):
        a, b = np.load(os.path.join(side["1"], name)), np.load(os.path.join(side["2"], name))
        check((a["lowres"] == b["lowres"]).all() and (a["highres"] == b["highres"]).all(), f"--sequence-workers 2: {name} bitwise as with 1")
# --fine-cells / --fine-frames-from (the scale study's pairing): a 2-cell coarse sheet beside the
# same 49-vertex fine sheet, its fine frames taken from the one-worker dataset: bitwise those frames,
# nothing of the fine cloth simulated; another seed's fine cloth refused, naming the file
coarser = os.path.join(WORK, "sheet_coarser")
pf = simsr("datagen", "--scenario", "sheet", "--cells", "2", "--fine-cells", "3", "--levels", "1", "--sequences", "1",
           "--fine-frames-from", side["1"], "--out", coarser)
sf = json.loads(pf.stdout) if pf.returncode == 0 else {}
check(sf.get("coarse", {}).get("vertices") == 9 and sf.get("fine", {}).get("vertices") == 49 and sf.get("fine", {}).get("cells") == 3,
      f"--cells 2 --fine-cells 3: 9 / 49 vertices: {sf.get('coarse')} {sf.get('fine')}")
check(sf.get("sequences", [{}])[0].get("fine_reused") is True and "fine 0.000 s (0 Newton)" in pf.stderr,
      f"--fine-frames-from: the fine frames taken, not simulated: {pf.stderr.strip()[-200:]}")
if pf.returncode == 0 and os.path.exists(os.path.join(side["1"], "sheet_000.npz")):
    zf, zs = np.load(os.path.join(coarser, "sheet_000.npz")), np.load(os.path.join(side["1"], "sheet_000.npz"))
    check(zf["lowres"].shape[1] == 9 and (zf["highres"] == zs["highres"]).all(), "--fine-frames-from: the source's fine frames, bitwise")
bad = simsr("datagen", "--scenario", "sheet", "--cells", "2", "--fine-cells", "3", "--levels", "1", "--sequences", "1", "--seed", "8",
            "--fine-frames-from", side["1"], "--out", os.path.join(WORK, "x"), expect=1)
check("sheet_000.npz" in bad.stderr and "another simulation's" in bad.stderr, f"another seed's fine frames refused: {bad.stderr.strip()[-300:]}")
bad = simsr("datagen", "--scenario", "disk", "--fine-cells", "4", "--out", os.path.join(WORK, "x"), expect=1)
check("first ring" in bad.stderr, f"--fine-cells for DISK refused: {bad.stderr.strip()[-200:]}")
bad = simsr("demo", "--dataset", "disk", "--fine-cells", "4", "--out", os.path.join(WORK, "x"), expect=1)
check("first ring" in bad.stderr, f"demo --fine-cells for DISK refused: {bad.stderr.strip()[-200:]}")
# --substeps: another step is another run (simulated again), and its count is in the summary
p3 = simsr("datagen", "--scenario", "sheet", "--cells", "3", "--levels", "1", "--sequences", "1", "--substeps", "3", "--out", os.path.join(WORK, "sheet_substeps3"))
s3 = json.loads(p3.stdout) if p3.returncode == 0 else {}
check(s3.get("substeps") == 3 and s3.get("sequences", [{}])[0].get("simulated") == frames, f"--substeps 3: {s3.get('substeps')}")
# --stepping converged: Newton to convergence in each step, another run, recorded in the summary
pconv = simsr("datagen", "--scenario", "sheet", "--cells", "3", "--levels", "1", "--sequences", "1", "--stepping", "converged",
              "--out", os.path.join(WORK, "sheet_converged"))
sconv = json.loads(pconv.stdout) if pconv.returncode == 0 else {}
check(sconv.get("newton", {}).get("hessian") == "regularized" and sconv.get("newton", {}).get("accept_at_max_iterations") is False
      and sconv.get("sequences", [{}])[0].get("simulated") == frames, f"--stepping converged: {sconv.get('newton')}")
if pconv.returncode == 0:
    zconv = np.load(os.path.join(WORK, "sheet_converged", "sheet_000.npz"))
    gap = np.linalg.norm(zconv["lowres"] - lr, axis=-1).max()  # lr: read before the file was replaced (above)
    check(0 < gap < 0.01, f"inexact and converged steps: the same motion within a centimetre ({gap * 1e3:.2f} mm at most)")
# --step-iterations 1: ARCSim's linearized steps, another run
plin = simsr("datagen", "--scenario", "sheet", "--cells", "3", "--levels", "1", "--sequences", "1", "--step-iterations", "1",
             "--out", os.path.join(WORK, "sheet_linearized"))
slin = json.loads(plin.stdout) if plin.returncode == 0 else {}
check(slin.get("newton", {}).get("max_iterations") == 1 and slin.get("sequences", [{}])[0].get("simulated") == frames,
      f"--step-iterations 1: {slin.get('newton')}")
bad = simsr("datagen", "--scenario", "sheet", "--stepping", "exact", "--out", os.path.join(WORK, "x"), expect=1)
check("--stepping" in bad.stderr and "exact" in bad.stderr, f"an unknown --stepping is named: {bad.stderr.strip()[-200:]}")
bad = simsr("datagen", "--scenario", "sheet", "--substeps", "-1", "--out", os.path.join(WORK, "x"), expect=1)
check("--substeps" in bad.stderr, f"a negative substep count is refused: {bad.stderr.strip()[-200:]}")
bad = simsr("datagen", "--scenario", "sheet", "--sequence-workers", "-1", "--out", os.path.join(WORK, "x"), expect=1)
check("--sequence-workers" in bad.stderr, f"a negative worker count is refused: {bad.stderr.strip()[-200:]}")
bad = simsr("datagen", "--scenario", "sheet", "--linear-solver", "lu", "--out", os.path.join(WORK, "x"), expect=1)
check("--linear-solver" in bad.stderr and "lu" in bad.stderr, f"an unknown linear solver is named: {bad.stderr.strip()[-200:]}")
# bad options
bad = simsr("datagen", "--scenario", "skirt", "--out", os.path.join(WORK, "x"), expect=1)
check("skirt" in bad.stderr, f"an unknown scenario is named: {bad.stderr.strip()[-200:]}")
simsr("datagen", "--scenario", "disk", "--cells", "1", "--out", os.path.join(WORK, "y"), expect=1)

# the demo end to end at the reduced size
demo = os.path.join(WORK, "demo")
dargs = ["demo", "--dataset", "sheet", "--cells", "3", "--levels", "1", "--sequences", "5", "--epochs", "3", "--baseline-epochs", "2", "--out", demo]
d = simsr(*dargs)
check("RMSE to the fine simulation" in d.stdout and "coarse_simulation" in d.stdout, f"the tables on stdout: {d.stdout[-400:]}")
check(d.stderr.count("train: epoch ") == 3, "a progress line per epoch")
report = {}
if os.path.exists(os.path.join(demo, "report.json")):
    with open(os.path.join(demo, "report.json")) as f:
        report = json.load(f)
rm = report.get("rmse_m", {})
check(all(k in rm and rm[k] > 0 for k in ("subdivided", "synthesized", "synthesized_refined", "decoded_truth", "decoded_subdivided")), f"five RMSEs: {rm}")
check(report.get("fine_target") == "residual", f"the default fine target: {report.get('fine_target')}")
rj = report.get("feature_jumps", {}).get("residual_beyond_pi", {})
check(report.get("residual_lift") == "nearest" and rj.get("trained", -1) <= rj.get("own", -1) and rj.get("vertex_frames", 0) > 0,
      f"the default residual lift and its counts: {report.get('residual_lift')} {rj}")
check(all(k in rm and rm[k] > 0 for k in ("local_linear", "upsampling_network")), f"the core paper's methods beside: {rm}")
check(d.stderr.count("baselines: network epoch ") == 2, "the upsampling network's epochs (--baseline-epochs 2) as progress lines")
seq0 = (report.get("sequences") or [{}])[0]
check("local_linear_m" in seq0 and "upsampling_network_m" in seq0, f"their per-sequence figures: {seq0}")
check(report.get("coarse_vertices") == 16 and report.get("fine_vertices") == 49, "the pair's sizes")
check(report.get("face_scale_factor") == 4 and "(x4 faces)" in d.stdout, f"the scale factor (Loop once: x4 faces): {report.get('face_scale_factor')}")
check(len(report.get("training", [])) == 3, "the training history")
sec = report.get("seconds_per_frame", {})
check(all(sec.get(k, 0) > 0 for k in ("coarse_simulation", "fine_simulation", "ts_acap_extraction", "synthesis")), f"Table 1's stages timed: {sec}")
test_frames = report.get("test_frames", 0)
csv = os.path.join(demo, "results", "frame_errors.csv")
rows = open(csv).read().strip().splitlines() if os.path.exists(csv) else []
check(test_frames > 0 and len(rows) == test_frames + 1 and all(r.startswith("sheet_004,") for r in rows[1:]), f"a csv row per held-out frame: {len(rows)}")
# the RMSE in the report is the root mean square of the csv's per-frame figures
if len(rows) > 1:
    header = rows[0].split(",")
    check(header == ["sequence", "frame", "subdivided_m", "synthesized_m", "refined_m", "local_linear_m", "upsampling_network_m"], f"the csv's columns: {header}")
    cols = np.array([[float(x) for x in r.split(",")[2:]] for r in rows[1:]])
    rms = np.sqrt(np.mean(cols ** 2, axis=0))
    check(abs(rms[0] - rm.get("subdivided", 0)) < 1e-9, "the csv and the report agree")
    # the baselines' per-frame columns are the frames of their per-sequence figures
    for j, key in ((3, "local_linear_m"), (4, "upsampling_network_m")):
        check(cols.shape[1] > j and abs(rms[j] - seq0.get(key, 0)) < 1e-9, f"the csv's {key} column and the report agree")
svg = os.path.join(demo, "results", "sheet_004_errors.svg")
check(os.path.exists(svg) and open(svg).read().count("<polyline") == 5, "the held-out sequence's per-frame plot, five series (three + two baselines)")
cmp_root = os.path.join(demo, "results", "compare")
views = sorted(os.listdir(cmp_root)) if os.path.isdir(cmp_root) else []
check(len(views) == 1 and views[0].startswith("sheet_004_"), f"one view folder for the held-out sequence: {views}")
if views:
    files = sorted(os.listdir(os.path.join(cmp_root, views[0])))
    check(files == ["lr_input.vtu", "refined.vtu", "subdivided.vtu", "synthesized.vtu", "truth.vtu"], f"the view's files: {files}")
    png = os.path.join(WORK, "sheet_view.png")
    script = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "scripts", "render_comparison.py")
    r = subprocess.run([sys.executable, script, os.path.join(cmp_root, views[0]), "--out", png, "--view", "oblique"], capture_output=True, text=True)
    check(r.returncode == 0 and os.path.exists(png) and os.path.getsize(png) > 1000, f"render_comparison.py --view oblique: {r.stderr.strip()[-300:]}")
# a rerun: the data reused, the training resumed at its end (no epoch trained), the same figures
d2 = simsr(*dargs)
check("train: epoch" not in d2.stderr and "data: sheet_" not in d2.stderr and "network epoch" not in d2.stderr,
      f"a rerun simulates and trains nothing: {d2.stderr[-300:]}")
if os.path.exists(os.path.join(demo, "report.json")):
    with open(os.path.join(demo, "report.json")) as f:
        check(json.load(f).get("rmse_m") == rm, "the rerun's figures are the first run's")
# the other fine target is another run: its checkpoint is refused, not resumed into
d3 = simsr(*dargs, "--fine-target", "features", expect=1)
check("another run" in d3.stderr, f"a checkpoint of the other fine target refused: {d3.stderr.strip()[-300:]}")
d4 = simsr(*dargs, "--residual-lift", "own", expect=1)
check("another run" in d4.stderr, f"a checkpoint of the other residual lift refused: {d4.stderr.strip()[-300:]}")
bad = simsr(*dargs, "--baselines", "kriging", expect=1)
check("kriging" in bad.stderr, f"an unknown baseline is named: {bad.stderr.strip()[-200:]}")
bad = simsr(*dargs, "--fine-target", "both", expect=1)
check("fine-target" in bad.stderr, f"an unknown fine target is named: {bad.stderr.strip()[-200:]}")
bad = simsr(*dargs, "--residual-lift", "closest", expect=1)
check("residual-lift" in bad.stderr, f"an unknown residual lift is named: {bad.stderr.strip()[-200:]}")
finish()
