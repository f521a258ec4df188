#!/usr/bin/env python3
"""Renders the core paper's Fig. 6 from the views `simsr demo` writes (DIR/results/compare/<sequence>_<frame>/):
top row the LR input, every method's predicted surface and the HR truth; bottom row every method's
per-vertex error on one colour scale (blue 0 → red top).

    /usr/bin/python3 scripts/render_comparison.py out/demo/results/compare/anger_41 --out anger_41.png [--max-mm 1] [--methods embedded,ridge,network]

Fig. 7 (the unseen forces, DIR/results/unseen/<sequence>/): each method at the peak force coloured
by its change from its own rest-pose prediction, the network's rest pose on the right:

    /usr/bin/python3 scripts/render_comparison.py out/demo/results/unseen/cheek_sphere --out cheek.png \
        --reference rest_network --reference-title "network, rest pose" --field change

VTK from Debian's python3-vtk9, offscreen; without a display the script runs itself under
xvfb-run (Debian's xvfb), as render_face.py does. Exit 2 for a missing or malformed folder."""
import argparse
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from render_face import label_and_frame, read_surface, reexec_under_xvfb, write_png  # noqa: E402


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("folder", help="DIR/results/compare/<sequence>_<frame> (lr_input.vtu, truth.vtu, <method>.vtu)")
    ap.add_argument("--out", required=True, help="PNG file to write")
    ap.add_argument("--methods", default="", help="methods to show, comma-separated (default: every <method>.vtu, report order)")
    ap.add_argument("--max-mm", type=float, default=0.0, help="top of the error colour scale in mm (default: the 99th percentile of Embedded's error, else of all)")
    ap.add_argument("--size", type=int, default=300, help="pixels per panel")
    ap.add_argument("--reference", default="truth", help="the right-most surface's file stem (default truth: the HR truth)")
    ap.add_argument("--reference-title", default="HR truth", help="its title")
    ap.add_argument("--view", default="front", choices=["front", "oblique"],
                    help="camera: front (the face) or oblique (a z-up cloth from above and aside: simsr demo --dataset sheet|disk)")
    ap.add_argument("--field", default="error", help="the point data the bottom row colours by (default error; change for Fig. 7)")
    a = ap.parse_args()
    for f in ("lr_input.vtu", a.reference + ".vtu"):
        if not os.path.exists(os.path.join(a.folder, f)):
            print(f"render_comparison.py: {os.path.join(a.folder, f)} not found (run simsr demo first)", file=sys.stderr)
            sys.exit(2)
    if a.methods:
        methods = [m for m in a.methods.split(",") if m]
    else:
        order = ["embedded", "idw", "rbf", "mls", "ridge", "beta_vae", "network", "subdivided", "synthesized", "refined"]
        found = [f[:-4] for f in os.listdir(a.folder)
                 if f.endswith(".vtu") and f not in ("lr_input.vtu", "truth.vtu", a.reference + ".vtu") and not f.startswith("rest_")]
        methods = sorted(found, key=lambda m: (order.index(m) if m in order else len(order), m))
    for m in methods:
        if not os.path.exists(os.path.join(a.folder, m + ".vtu")):
            print(f"render_comparison.py: no {m}.vtu in {a.folder}", file=sys.stderr)
            sys.exit(2)
    if not methods:
        print(f"render_comparison.py: no method views in {a.folder}", file=sys.stderr)
        sys.exit(2)
    reexec_under_xvfb()
    import vtk  # Debian's python3-vtk9
    from vtk.util.numpy_support import vtk_to_numpy

    def read(name, smooth=True):
        return read_surface(os.path.join(a.folder, name + ".vtu"), "render_comparison.py", smooth)

    lr, truth = read("lr_input", smooth=False), read(a.reference)
    preds = {m: read(m) for m in methods}
    for m, poly in list(preds.items()) + [(a.reference, truth)]:
        if poly.GetPointData().GetArray(a.field) is None:
            print(f"render_comparison.py: {m}.vtu has no point data '{a.field}'", file=sys.stderr)
            sys.exit(2)
    import numpy as np
    if a.max_mm > 0:
        top = a.max_mm / 1e3
    else:
        ref = preds.get("embedded")
        errs = vtk_to_numpy((ref or next(iter(preds.values()))).GetPointData().GetArray(a.field))
        top = float(np.percentile(errs, 99)) or 1e-6
    lut = vtk.vtkLookupTable()
    lut.SetHueRange(0.667, 0.0)
    lut.SetTableRange(0, top)
    lut.Build()

    cols = len(methods) + 2
    window = vtk.vtkRenderWindow()
    window.SetOffScreenRendering(1)
    window.SetSize(cols * a.size, 2 * a.size)
    bounds = truth.GetBounds()
    centre = [(bounds[2 * i] + bounds[2 * i + 1]) / 2 for i in range(3)]
    height = max(bounds[3] - bounds[2], bounds[1] - bounds[0], bounds[5] - bounds[4])

    def panel(row, col, poly, title, coloured):
        ren = vtk.vtkRenderer()
        ren.SetViewport(col / cols, 1 - (row + 1) / 2, (col + 1) / cols, 1 - row / 2)
        ren.SetBackground(1, 1, 1)
        mapper = vtk.vtkPolyDataMapper()
        mapper.SetInputData(poly)
        if coloured:
            mapper.SetScalarModeToUsePointFieldData()
            mapper.SelectColorArray(a.field)
            mapper.SetLookupTable(lut)
            mapper.SetScalarRange(0, top)
            mapper.ScalarVisibilityOn()
        else:
            mapper.ScalarVisibilityOff()
        actor = vtk.vtkActor()
        actor.SetMapper(mapper)
        if not coloured:
            actor.GetProperty().SetColor(0.85, 0.78, 0.72)
        if poly is lr:
            actor.GetProperty().SetInterpolationToFlat()
        ren.AddActor(actor)
        label_and_frame(ren, title, centre, height, a.view)
        window.AddRenderer(ren)
        return ren

    panel(0, 0, lr, "LR input", False)
    for i, m in enumerate(methods):
        panel(0, i + 1, preds[m], m, False)
        mean = float(np.mean(vtk_to_numpy(preds[m].GetPointData().GetArray(a.field))))
        panel(1, i + 1, preds[m], f"{m}: mean {mean:.3g}", True)
    panel(0, cols - 1, truth, a.reference_title, False)
    blank = vtk.vtkRenderer()  # under the truth: nothing to show, the page's white
    blank.SetViewport((cols - 1) / cols, 0, 1, 0.5)
    blank.SetBackground(1, 1, 1)
    window.AddRenderer(blank)
    ren = panel(1, 0, truth, f"{a.field} (m)", True)
    bar = vtk.vtkScalarBarActor()
    bar.SetLookupTable(lut)
    bar.SetNumberOfLabels(3)
    bar.SetLabelFormat("%.1e")
    bar.SetWidth(0.15)
    bar.GetLabelTextProperty().SetColor(0, 0, 0)
    ren.AddActor2D(bar)
    write_png(window, a.out)
    print(f"render_comparison.py: wrote {a.out} ({len(methods)} methods, colour scale 0-{top * 1e3:.2f} mm)")


if __name__ == "__main__":
    main()
