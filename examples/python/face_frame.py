#!/usr/bin/env python3
"""One face simulation frame from Python, plotted with matplotlib (issue #15).

The core paper's face (the ICT kit's anatomy: skull, jaw hinge, muscles, lips in contact) is
built and simulated at both resolutions for a short performance written here as a controls file
(a smile with the jaw opening), through ``simsr.generate_face_data``, the function
``simsr datagen --scenario face`` runs. The last frame's skin as the LR simulation moves it (the rest skin
carried by the LR tets, simsr.Embedded) and as the HR simulation does are drawn side by side,
coloured by how far each point moved from the neutral face, into a PNG.

    /usr/bin/python3 examples/python/face_frame.py --kit ../shared/data/ict_face --out out/face_frame
    /usr/bin/python3 examples/python/face_frame.py --coarse ...   # the test suite's coarse model: seconds, not minutes

A rerun into the same --out reuses the simulated frames (the datagen resumes and reuses).
Needs the module (PYTHONPATH=<build>/python or installed), the tetgen program and matplotlib.
"""
import argparse
import pathlib

import matplotlib

matplotlib.use("Agg")  # files, no display
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import simsr  # noqa: E402


def write_controls(path, frames):
    """A controls file (.npz: names, weights F x C): the jaw opening and a smile rising over `frames`."""
    names = np.array(["jawOpen", "mouthSmile_L", "mouthSmile_R", "browInnerUp_L", "browInnerUp_R"])
    s = np.linspace(1.0 / frames, 1.0, frames)[:, None]
    weights = s * np.array([[0.3, 0.7, 0.7, 0.5, 0.5]])
    np.savez(path, names=names, weights=weights)


def draw(ax, V, F, moved_mm, title, vmax):
    """A triangle surface coloured by per-vertex motion (mm), viewed from the front."""
    face_colour = moved_mm[F].mean(axis=1)
    surf = ax.plot_trisurf(V[:, 0], V[:, 2], V[:, 1], triangles=F, cmap="viridis", linewidth=0, antialiased=False, shade=False)
    surf.set_array(face_colour)
    surf.set_clim(0, vmax)
    ax.view_init(elev=5, azim=-90)
    ax.set_title(title)
    ax.set_axis_off()
    ax.set_box_aspect(np.ptp(V[:, [0, 2, 1]], axis=0), zoom=1.4)
    return surf


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--kit", type=pathlib.Path, default=pathlib.Path(__file__).resolve().parents[3] / "shared" / "data" / "ict_face")
    ap.add_argument("--out", type=pathlib.Path, default=pathlib.Path("out/face_frame"))
    ap.add_argument("--frames", type=int, default=3, help="frames of the performance (the last is drawn)")
    ap.add_argument("--coarse", action="store_true", help="the test suite's coarse model (LR cell 2 cm, HR tets up to 1 cm^3)")
    ap.add_argument("--preset", default="default", help="mesh sizes: default, paper-ratio, paper-lr")
    args = ap.parse_args()

    args.out.mkdir(parents=True, exist_ok=True)
    controls = args.out / "smile_controls.npz"  # the performance "smile"
    write_controls(controls, args.frames)
    sizes = dict(lr_cell=2.0, skull_lattice=1.6, hr_max_volume=1.0) if args.coarse else {}
    data = args.out / "data"
    report = simsr.generate_face_data(data, kit=args.kit, preset=args.preset, performances=[], controls=[controls], vtk_every=0,
                                      unseen_forces=False, on_progress=print, **sizes)
    print(f"HR {report['hr']['tets']} tets, LR {report['lr']['tets']} tets ({report['tet_ratio']:.1f}x)")

    name = "smile"
    frames = simsr.read_paired_frames(data / f"{name}.npz")
    lr_rest = simsr.read_mesh(data / "lr_rest.msh")
    hr_rest = simsr.read_mesh(data / "hr_rest.obj")
    last = frames.num_frames - 1
    # the LR simulation seen on the skin: the HR rest skin carried by the LR tets (simsr.Embedded,
    # the paper's first baseline), so both panels show the same surface
    problem = simsr.UpsamplingProblem(simsr.TetMesh(lr_rest.V, lr_rest.T), simsr.TriMesh(hr_rest.V, hr_rest.F))
    embedded = simsr.Embedded()
    embedded.fit(problem)
    lr_disp = frames.lowres[last] - lr_rest.V
    lr_skin = hr_rest.V + embedded.apply(lr_disp)
    hr_x = frames.highres[last]
    lr_moved = 1e3 * np.linalg.norm(lr_skin - hr_rest.V, axis=1)  # metres -> mm
    hr_moved = 1e3 * np.linalg.norm(hr_x - hr_rest.V, axis=1)
    gap = 1e3 * np.linalg.norm(lr_skin - hr_x, axis=1)
    vmax = float(np.percentile(hr_moved, 99))

    fig = plt.figure(figsize=(10, 6), dpi=120)
    a = fig.add_subplot(1, 2, 1, projection="3d")
    draw(a, lr_skin, hr_rest.F, lr_moved, f"LR simulation ({lr_rest.T.shape[0]} tets), embedded skin", vmax)
    b = fig.add_subplot(1, 2, 2, projection="3d")
    surf = draw(b, hr_x, hr_rest.F, hr_moved, f"HR simulation ({report['hr']['tets']} tets)", vmax)
    fig.subplots_adjust(left=0, right=0.9, bottom=0, top=0.92, wspace=0)
    fig.colorbar(surf, ax=[a, b], shrink=0.6, label="motion from the neutral face (mm)")
    fig.suptitle(f"simsr face, frame {last + 1} of '{name}' (jawOpen 0.3, smile 0.7)")
    png = args.out / "face_frame.png"
    fig.savefig(png)
    assert png.stat().st_size > 10_000, f"{png}: {png.stat().st_size} bytes, not a drawn figure"
    print(f"largest skin motion: HR {hr_moved.max():.1f} mm, LR (embedded) {lr_moved.max():.1f} mm; LR to HR skin: mean {gap.mean():.2f} mm, "
          f"largest {gap.max():.1f} mm; wrote {png}")


if __name__ == "__main__":
    main()
