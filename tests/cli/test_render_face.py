#!/usr/bin/env python3
"""scripts/render_face.py on a small VTU series (an ellipsoid standing in for the face, with a
distance field that grows along one axis): the PNG has three panels per frame, the surface drawn
in each, the third coloured from blue to red; bad input exits 2.

    /usr/bin/python3 tests/cli/test_render_face.py REPO_DIR WORK_DIR

Exit 0: all passed; 1: a check failed; 77: python3-vtk9 or meshio missing (1 under SIMSR_REQUIRE_PEERS=1)."""
import os
import subprocess
import sys

from checks import check, finish, missing_peer

try:
    import numpy as np
    import meshio
    import vtk
except ImportError as e:
    missing_peer(e)

REPO, WORK = sys.argv[1], sys.argv[2]
series = os.path.join(WORK, "series")
os.makedirs(series, exist_ok=True)

# an ellipsoid (face-sized, metres) as a triangulated UV sphere
nu, nv = 40, 24
u, v = np.meshgrid(np.linspace(0, 2 * np.pi, nu, endpoint=False), np.linspace(0.1, np.pi - 0.1, nv))
P = np.stack([0.08 * np.cos(u) * np.sin(v), 0.11 * np.cos(v), 0.07 * np.sin(u) * np.sin(v)], -1).reshape(-1, 3)
tris = []
for j in range(nv - 1):
    for i in range(nu):
        a, b, c, d = j * nu + i, j * nu + (i + 1) % nu, (j + 1) * nu + i, (j + 1) * nu + (i + 1) % nu
        tris += [[a, c, b], [b, c, d]]
tris = np.array(tris)
for name in ("lr_skin", "hr_skin"):
    os.makedirs(os.path.join(series, name), exist_ok=True)
    files = []
    for k in range(3):
        X = P * (1 + 0.05 * k)
        d = (X[:, 1] - X[:, 1].min()) * 0.01 * (k + 1)
        rel = f"{name}/{name}_{k:06d}.vtu"
        meshio.write(os.path.join(series, rel), meshio.Mesh(X, [("triangle", tris)], point_data={"distance_to_lr": d, "displacement": d}))
        files.append(rel)
    with open(os.path.join(series, name + ".pvd"), "w") as f:
        f.write('<?xml version="1.0"?>\n<VTKFile type="Collection"><Collection>\n')
        f.writelines(f'<DataSet timestep="{k}" file="{rel}"/>\n' for k, rel in enumerate(files))
        f.write("</Collection></VTKFile>\n")

script = os.path.join(REPO, "scripts", "render_face.py")
png = os.path.join(WORK, "render.png")
if os.path.exists(png):
    os.remove(png)
p = subprocess.run([sys.executable, script, series, "--out", png, "--frames", "0,2", "--size", "200"], capture_output=True, text=True)
check(p.returncode == 0, f"render_face.py: exit {p.returncode}: {p.stderr.strip()}")
check(os.path.exists(png) and not os.path.exists(png + ".part.png"), "the PNG is written under its name, no partial file left")
if os.path.exists(png):
    r = vtk.vtkPNGReader()
    r.SetFileName(png)
    r.Update()
    img = r.GetOutput()
    w, h, _ = img.GetDimensions()
    check((w, h) == (600, 400), f"3 panels × 2 frames of 200 px: got {w}×{h}")
    from vtk.util.numpy_support import vtk_to_numpy
    rgb = vtk_to_numpy(img.GetPointData().GetScalars()).reshape(h, w, -1)[:, :, :3].astype(int)
    for row in range(2):
        for col in range(3):
            panel = rgb[row * 200:(row + 1) * 200, col * 200:(col + 1) * 200]
            drawn = np.abs(panel - 255).sum(-1) > 60  # not background
            check(drawn.mean() > 0.15, f"panel ({row}, {col}): the surface covers {drawn.mean():.2f} of it")
            if col == 2:
                blue = (panel[:, :, 2] > panel[:, :, 0] + 80) & drawn
                red = (panel[:, :, 0] > panel[:, :, 2] + 80) & drawn
                check(blue.sum() > 100 and red.sum() > 100, f"panel ({row}, 2): distance colours from blue to red ({blue.sum()} blue, {red.sum()} red px)")

bad = subprocess.run([sys.executable, script, os.path.join(WORK, "missing"), "--out", png], capture_output=True, text=True)
check(bad.returncode == 2 and "not found" in bad.stderr, f"a missing series: exit {bad.returncode}, {bad.stderr.strip()}")
bad = subprocess.run([sys.executable, script, series, "--out", png, "--frames", "7"], capture_output=True, text=True)
check(bad.returncode == 2 and "outside" in bad.stderr, f"a frame outside the series: exit {bad.returncode}, {bad.stderr.strip()}")
finish()
