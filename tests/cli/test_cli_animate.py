#!/usr/bin/env python3
"""`simsr animate` on the real face (a coarse LR lattice, 2 frames, an untrained network: the
library's own test checks the frames; this one the tool): stdout's JSON equals OUT/animate.json,
both runs' frame rates are there, the frames file holds the LR and HR frames of the controls, the
VTU series is written, and bad options fail with their exit codes. (That the live LR frames are
datagen's: tests/scenario/test_face_datagen.cpp.)

    /usr/bin/python3 tests/cli/test_cli_animate.py SIMSR WORK_DIR DATA_DIR

Exit 0: all passed; 1: a check failed; 77: numpy, the ICT kit or tetgen missing (1 under
SIMSR_REQUIRE_PEERS=1)."""
import json
import os
import shutil
import subprocess
import sys

from checks import check, finish

SIMSR, WORK, DATA = sys.argv[1:4]
REQUIRE = os.environ.get("SIMSR_REQUIRE_PEERS", "0") not in ("", "0")
KIT = os.path.join(DATA, "ict_face")


def missing(what):
    print(f"MISSING (a failure under SIMSR_REQUIRE_PEERS=1, a skip otherwise): {what}")
    sys.exit(1 if REQUIRE else 77)


try:
    import numpy as np
except ImportError as e:
    missing(e)
if not os.path.exists(os.path.join(KIT, "full_neutral.obj")):
    missing(f"the ICT kit in {KIT}")
if shutil.which("tetgen") is None:
    missing("the tetgen program (apt-get install tetgen)")

shutil.rmtree(WORK, ignore_errors=True)
os.makedirs(WORK)
controls = os.path.join(WORK, "smile_controls.npz")
np.savez(controls, names=np.array(["jawOpen", "mouthSmile_L", "mouthSmile_R"]),
         weights=np.array([[0.1, 0.0, 0.0], [0.25, 0.4, 0.3], [0.4, 0.8, 0.6]]))
common = ["--kit", KIT, "--controls", controls, "--lr-cell", "2.0", "--frames", "2"]

out = os.path.join(WORK, "live")
p = subprocess.run([SIMSR, "animate", "--untrained", "--out", out, "--vtk-every", "1"] + common, capture_output=True, text=True)
check(p.returncode == 0, f"simsr animate: exit {p.returncode}: {p.stderr[-2000:]}")
if p.returncode == 0:
    report = json.loads(p.stdout)
    check(report == json.load(open(os.path.join(out, "animate.json"))), "stdout's JSON is OUT/animate.json")
    perf = report["performances"][0]
    check(perf["name"] == "smile" and perf["frames"] == 2, f"performance smile, 2 frames (--frames): {perf['name']}, {perf['frames']}")
    for mode in ("pipelined", "unpipelined"):
        for key in ("lr_simulation_fps", "inference_fps", "end_to_end_fps"):
            check(perf[mode][key] > 0, f"{mode} {key} > 0")
    check(perf["pipelined"]["source_threads"] == 1, "pipelined: one thread for the LR simulation by default")
    check(perf["pipelined_vs_unpipelined_max_difference_m"] <= 1e-9, "pipelined and unpipelined give the same frames")
    check("untrained" in report["network"], "the report says the network is untrained")
    z = np.load(os.path.join(out, "smile.npz"))
    n, m = report["lr"]["vertices"], report["hr_surface_vertices"]
    check(z["lowres"].shape == (2, n, 3) and z["highres"].shape == (2, m, 3), f"frame shapes {z['lowres'].shape} {z['highres'].shape}")
    check(np.isfinite(z["highres"]).all(), "HR frames finite")
    check(np.abs(np.diff(z["lowres"], axis=0)).max() > 1e-4, "the LR face moves between the frames")
    for f in (0, 1):
        check(os.path.getsize(os.path.join(out, "vtk", "smile", "hr_skin", f"hr_skin_{f:06d}.vtu")) > 1000, f"VTU of frame {f}")

# Embedded instead of the network (no model): the same LR frames
p = subprocess.run([SIMSR, "animate", "--method", "embedded", "--out", os.path.join(WORK, "embedded"), "--vtk-every", "0", "--no-unpipelined"] + common,
                   capture_output=True, text=True)
check(p.returncode == 0, f"simsr animate --method embedded: exit {p.returncode}: {p.stderr[-2000:]}")
if p.returncode == 0:
    report = json.loads(p.stdout)
    check(report["method"] == "embedded" and report["network"] is None, "the report names Embedded and no network")
    check("unpipelined" not in report["performances"][0], "--no-unpipelined: no unpipelined run")
    e = np.load(os.path.join(WORK, "embedded", "smile.npz"))
    check(np.abs(e["lowres"] - np.load(os.path.join(out, "smile.npz"))["lowres"]).max() <= 1e-12, "the same LR frames as the network's run")

# bad options: exit codes of errors.hpp
p = subprocess.run([SIMSR, "animate", "--model", os.path.join(WORK, "missing.npz"), "--out", os.path.join(WORK, "x")] + common, capture_output=True, text=True)
check(p.returncode == 2 and "missing.npz" in p.stderr, f"missing model: exit 2 naming it ({p.returncode}: {p.stderr.strip()})")
p = subprocess.run([SIMSR, "animate", "--out", os.path.join(WORK, "x")] + common, capture_output=True, text=True)
check(p.returncode == 5 and "no model file" in p.stderr, f"no model and not untrained: exit 5 ({p.returncode}: {p.stderr.strip()})")
p = subprocess.run([SIMSR, "animate", "--untrained", "--out", os.path.join(WORK, "x")], capture_output=True, text=True)
check(p.returncode == 64, f"no --controls: usage exit 64 ({p.returncode})")
p = subprocess.run([SIMSR, "animate", "--method", "embedded", "--untrained", "--out", os.path.join(WORK, "x")] + common, capture_output=True, text=True)
check(p.returncode == 5 and "embedded takes no model" in p.stderr, f"embedded + untrained: exit 5 ({p.returncode}: {p.stderr.strip()})")
finish()
