#!/usr/bin/env python3
"""Renders frames of a face performance side by side (issue #11 item 6, the core paper's Fig. 4):
the skin embedded in the LR simulation, the HR skin, and the HR skin coloured by its distance to
the LR one — from the VTU series `simsr datagen` writes (DIR/vtk/<performance>/).

    /usr/bin/python3 scripts/render_face.py DIR/vtk/amazement --out amazement.png [--frames 0,12,23] [--max-mm 2]

One row per frame (indices into the series: with --vtk-every 5, series frame 12 is data frame 60),
three columns. VTK from Debian's python3-vtk9, rendered offscreen; without a display the script
runs itself under xvfb-run (Debian's xvfb). Exit 2 for a missing or malformed series."""
import argparse
import os
import re
import shutil
import subprocess
import sys


def reexec_under_xvfb():
    """VTK 9.1 in Debian renders through X/GLX: give it a virtual display when there is none."""
    if os.environ.get("DISPLAY") or os.environ.get("SIMSR_RENDER_XVFB") == "1":
        return
    xvfb = shutil.which("xvfb-run")
    if not xvfb:
        sys.exit("render_face.py: no DISPLAY and no xvfb-run (apt-get install xvfb xauth)")
    env = dict(os.environ, SIMSR_RENDER_XVFB="1")
    sys.exit(subprocess.call([xvfb, "-a", "-s", "-screen 0 1920x1080x24", sys.executable, *sys.argv], env=env))


def read_surface(path, who, smooth=True):
    """The boundary surface of a .vtu file, with smooth normals (or flat facets: a blocky LR
    lattice, where averaged normals of its opposite faces shade black); exit 2 when it has no points."""
    import vtk
    r = vtk.vtkXMLUnstructuredGridReader()
    r.SetFileName(path)
    r.Update()
    g = r.GetOutput()
    if g.GetNumberOfPoints() == 0:
        print(f"{who}: {path} has no points", file=sys.stderr)
        sys.exit(2)
    s = vtk.vtkDataSetSurfaceFilter()
    s.SetInputData(g)
    s.Update()
    if not smooth:
        return s.GetOutput()
    nrm = vtk.vtkPolyDataNormals()
    nrm.SetInputData(s.GetOutput())
    nrm.SplittingOff()
    nrm.Update()
    return nrm.GetOutput()


def label_and_frame(ren, title, centre, height, view="front"):
    """A black title in the panel's lower left and the camera every render uses: the face from
    the front, a little from the left, its height filling the panel (view "front"); or a z-up
    scene from above and aside (view "oblique": the cloths of the thin-shell paper)."""
    import vtk
    text = vtk.vtkTextActor()
    text.SetInput(title)
    text.GetTextProperty().SetColor(0, 0, 0)
    text.GetTextProperty().SetFontSize(14)
    text.GetPositionCoordinate().SetCoordinateSystemToNormalizedViewport()
    text.GetPositionCoordinate().SetValue(0.03, 0.03)
    ren.AddActor2D(text)
    cam = ren.GetActiveCamera()
    cam.SetFocalPoint(*centre)
    if view == "oblique":
        cam.SetPosition(centre[0] + 1.5 * height, centre[1] - 2.2 * height, centre[2] + 1.6 * height)
        cam.SetViewUp(0, 0, 1)
    else:
        cam.SetPosition(centre[0] + 0.35 * height, centre[1] + 0.1 * height, centre[2] + 2.2 * height)
        cam.SetViewUp(0, 1, 0)
    ren.ResetCameraClippingRange()


def write_png(window, out):
    """Renders `window` into the PNG `out`, atomically: a killed render leaves no half image under the real name."""
    import vtk
    window.Render()
    grab = vtk.vtkWindowToImageFilter()
    grab.SetInput(window)
    grab.Update()
    png = vtk.vtkPNGWriter()
    tmp = out + ".part.png"
    png.SetFileName(tmp)
    png.SetInputConnection(grab.GetOutputPort())
    png.Write()
    os.replace(tmp, out)


def series_files(folder, name):
    """The .vtu files of <folder>/<name>.pvd, in the collection's order."""
    pvd = os.path.join(folder, name + ".pvd")
    if not os.path.exists(pvd):
        print(f"render_face.py: {pvd} not found (run simsr datagen with --vtk-every > 0)", file=sys.stderr)
        sys.exit(2)
    with open(pvd) as f:
        files = re.findall(r'file="([^"]+)"', f.read())
    if not files:
        print(f"render_face.py: {pvd} lists no frames", file=sys.stderr)
        sys.exit(2)
    return [os.path.join(folder, x) for x in files]


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("series", help="DIR/vtk/<performance> (holds lr_skin.pvd and hr_skin.pvd)")
    ap.add_argument("--out", required=True, help="PNG file to write")
    ap.add_argument("--frames", default="", help="series frame indices, comma-separated (default: first, middle, last)")
    ap.add_argument("--max-mm", type=float, default=0.0, help="top of the colour scale in mm (default: the largest distance shown)")
    ap.add_argument("--size", type=int, default=420, help="pixels per panel")
    a = ap.parse_args()
    reexec_under_xvfb()
    import vtk  # Debian's python3-vtk9

    lr_files, hr_files = series_files(a.series, "lr_skin"), series_files(a.series, "hr_skin")
    if len(lr_files) != len(hr_files):
        print(f"render_face.py: lr_skin has {len(lr_files)} frames, hr_skin {len(hr_files)}", file=sys.stderr)
        sys.exit(2)
    n = len(hr_files)
    frames = [int(x) for x in a.frames.split(",") if x] if a.frames else sorted({0, n // 2, n - 1})
    for f in frames:
        if not 0 <= f < n:
            print(f"render_face.py: frame {f} outside the series' {n}", file=sys.stderr)
            sys.exit(2)

    rows = [(read_surface(lr_files[f], "render_face.py"), read_surface(hr_files[f], "render_face.py")) for f in frames]
    top = a.max_mm / 1e3 if a.max_mm > 0 else max(hr.GetPointData().GetArray("distance_to_lr").GetRange()[1] for _, hr in rows)
    lut = vtk.vtkLookupTable()
    lut.SetHueRange(0.667, 0.0)  # blue (0) to red (top)
    lut.SetTableRange(0, top)
    lut.Build()

    window = vtk.vtkRenderWindow()
    window.SetOffScreenRendering(1)
    window.SetSize(3 * a.size, len(rows) * a.size)
    titles = ["LR (embedded skin)", "HR skin", "|HR - LR| (m)"]
    for r, (lr, hr) in enumerate(rows):
        bounds = hr.GetBounds()
        centre = [(bounds[2 * i] + bounds[2 * i + 1]) / 2 for i in range(3)]
        height = bounds[3] - bounds[2]
        for c in range(3):
            ren = vtk.vtkRenderer()
            ren.SetViewport(c / 3, 1 - (r + 1) / len(rows), (c + 1) / 3, 1 - r / len(rows))
            ren.SetBackground(1, 1, 1)
            mapper = vtk.vtkPolyDataMapper()
            mapper.SetInputData(lr if c == 0 else hr)
            if c == 2:
                mapper.SetScalarModeToUsePointFieldData()
                mapper.SelectColorArray("distance_to_lr")
                mapper.SetLookupTable(lut)
                mapper.SetScalarRange(0, top)
                mapper.ScalarVisibilityOn()
                if r == 0:
                    bar = vtk.vtkScalarBarActor()
                    bar.SetLookupTable(lut)
                    bar.SetNumberOfLabels(3)
                    bar.SetLabelFormat("%.1e")
                    bar.SetWidth(0.12)
                    bar.GetLabelTextProperty().SetColor(0, 0, 0)
                    ren.AddActor2D(bar)
            else:
                mapper.ScalarVisibilityOff()
            actor = vtk.vtkActor()
            actor.SetMapper(mapper)
            if c < 2:
                actor.GetProperty().SetColor(0.85, 0.78, 0.72)
            ren.AddActor(actor)
            label_and_frame(ren, f"{titles[c]}  (series frame {frames[r]})" if c == 0 else titles[c], centre, height)
            window.AddRenderer(ren)
    write_png(window, a.out)
    print(f"render_face.py: wrote {a.out} ({len(rows)} frames, colour scale 0-{top * 1e3:.2f} mm)")


if __name__ == "__main__":
    main()
