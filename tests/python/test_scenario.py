"""The scenario datagen from Python (python/src/scenario.cpp) on reduced scenes: each generator
writes bitwise the files `simsr datagen` writes with the same options (the same library functions
behind both), reports its progress through the callback (every frame once, in order), resumes a
run a raising callback stopped and then equals the uninterrupted one, reuses a finished run, and
refuses bad options with the library's typed errors."""
import json
import os
import pathlib
import shutil

import numpy as np
import pytest

import simsr
from conftest import need


def npz_files(folder):
    """Every .npz below `folder` (hidden checkpoint folders left out), relative path -> arrays."""
    folder = pathlib.Path(folder)
    out = {}
    for f in sorted(folder.rglob("*.npz")):
        rel = f.relative_to(folder)
        if any(part.startswith(".") for part in rel.parts):
            continue
        with np.load(f, allow_pickle=False) as z:
            out[str(rel)] = {k: z[k] for k in z.files}
    return out


# arrays that hold wall-clock time, which two runs cannot share
TIMINGS = {"seconds"}


def assert_same_files(a, b):
    fa, fb = npz_files(a), npz_files(b)
    assert fa.keys() == fb.keys() and fa
    for name in fa:
        assert fa[name].keys() == fb[name].keys(), name
        for k in fa[name]:
            if k in TIMINGS:
                continue
            assert fa[name][k].dtype == fb[name][k].dtype, (name, k)
            np.testing.assert_array_equal(fa[name][k], fb[name][k], err_msg=f"{name}: {k}")


class Stop(Exception):
    pass


# ---- cloth (the thin-shell paper's SHEET, 16 / 49 vertices) -------------------------------------

SHEET = dict(cells=3, levels=1, sequences=1)


def test_cloth_data_equals_the_tool_and_reports_every_frame(tmp_path, tool):
    frames = []
    report = simsr.generate_cloth_data("sheet", tmp_path / "py", on_frame=frames.append, **SHEET)
    tool("datagen", "--scenario", "sheet", "--cells", 3, "--levels", 1, "--sequences", 1, "--out", tmp_path / "cli")
    assert_same_files(tmp_path / "py", tmp_path / "cli")
    assert report == json.loads((tmp_path / "py" / "cloth_data.json").read_text())
    assert report["coarse"]["vertices"] == 16 and report["fine"]["vertices"] == 49
    settle = [f for f in frames if f["sequence"] == "settle"]
    seq = [f for f in frames if f["sequence"] != "settle"]
    assert [f["frame"] for f in settle] == list(range(45))  # the shared start's settling
    assert seq and {f["sequence"] for f in seq} == {"sheet_000"}
    assert [f["frame"] for f in seq] == list(range(seq[0]["frames"]))  # every frame once, in order
    assert all(f["fine_newton_iterations"] >= 1 and f["fine_seconds"] >= 0 for f in seq)
    # a finished run is reused: nothing simulated again
    again = []
    simsr.generate_cloth_data("sheet", tmp_path / "py", on_frame=again.append, **SHEET)
    assert again == []


def test_cloth_data_stopped_by_its_callback_resumes_to_the_same_files(tmp_path):
    simsr.generate_cloth_data("sheet", tmp_path / "whole", checkpoint_every=5, policy="seq", **SHEET)

    def stop_at_12(f):
        if f["sequence"] != "settle" and f["frame"] == 12:
            raise Stop("stopped by the test")

    with pytest.raises(Stop, match="stopped by the test"):
        simsr.generate_cloth_data("sheet", tmp_path / "part", checkpoint_every=5, on_frame=stop_at_12, policy="seq", **SHEET)
    resumed = []
    simsr.generate_cloth_data("sheet", tmp_path / "part", checkpoint_every=5, on_frame=resumed.append, policy="seq", **SHEET)
    seq = [f["frame"] for f in resumed if f["sequence"] != "settle"]
    assert seq[0] == 10  # from the checkpoint at frame 10, not from the start
    assert all(f["sequence"] != "settle" for f in resumed)  # the settled start read from its file
    assert_same_files(tmp_path / "part", tmp_path / "whole")


def test_cloth_data_refuses_bad_options(tmp_path):
    with pytest.raises(simsr.ArgumentError, match="skirt"):
        simsr.generate_cloth_data("skirt", tmp_path / "x")
    with pytest.raises(simsr.ArgumentError, match="exact"):
        simsr.generate_cloth_data("sheet", tmp_path / "x", stepping="exact")
    with pytest.raises(simsr.ArgumentError, match="sequence_workers"):
        simsr.generate_cloth_data("sheet", tmp_path / "x", sequence_workers=-1, **SHEET)
    with pytest.raises(simsr.ArgumentError):
        simsr.generate_cloth_data("sheet", tmp_path / "x", policy="gpu", **SHEET)
    # a killed run's checkpoint, then another seed into the same folder: refused by name, the
    # checkpoint kept (the first run resumes from it)

    def stop_at_12(f):
        if f["sequence"] != "settle" and f["frame"] == 12:
            raise Stop()

    with pytest.raises(Stop):
        simsr.generate_cloth_data("sheet", tmp_path / "run", checkpoint_every=5, on_frame=stop_at_12, **SHEET)
    with pytest.raises(simsr.ArgumentError, match="is a checkpoint of another run"):
        simsr.generate_cloth_data("sheet", tmp_path / "run", checkpoint_every=5, seed=8, **SHEET)
    resumed = []
    simsr.generate_cloth_data("sheet", tmp_path / "run", checkpoint_every=5, on_frame=resumed.append, **SHEET)
    assert [f["frame"] for f in resumed][0] == 10


# ---- SoftDECA (the sphere stand-in: level 1, 42 skin vertices) ----------------------------------

def test_softdeca_data_equals_the_tool(tmp_path, tool):
    lines = []
    report = simsr.generate_softdeca_data(tmp_path / "py", samples=2, template="sphere", sphere_level=1, on_progress=lines.append)
    tool("datagen", "--scenario", "softdeca", "--template", "sphere", "--sphere-level", 1, "--samples", 2, "--out", tmp_path / "cli")
    assert_same_files(tmp_path / "py", tmp_path / "cli")
    assert report["samples"] == 2 and report["simulated"] + report["resumed"] == 2
    assert lines, "no progress lines"
    with pytest.raises(simsr.ArgumentError, match="local_global or newton"):
        simsr.generate_softdeca_data(tmp_path / "x", samples=1, template="sphere", solver="lbfgs")
    with pytest.raises(simsr.ArgumentError, match="'ict' or 'sphere'"):
        simsr.generate_softdeca_data(tmp_path / "x", samples=1, template="cube")
    with pytest.raises(simsr.ArgumentError, match="samples"):
        simsr.generate_softdeca_data(tmp_path / "x", samples=0, template="sphere", sphere_level=1)


# ---- the face (the core paper's; the coarse model of the C++ suite, one controls file) ---------

COARSE = dict(lr_cell=2.0, skull_lattice=1.6, hr_max_volume=1.0)


@pytest.fixture(scope="module")
def kit(data_dir):
    k = data_dir / "ict_face"
    need((k / "full_neutral.obj").exists(), f"the ICT kit ({k})")
    need(shutil.which("tetgen") is not None, "the tetgen program")
    return k


def controls_file(folder):
    """Two frames of a jaw opening with a smile, as a controls file (`simsr datagen --controls`)."""
    f = pathlib.Path(folder) / "smile_controls.npz"
    names = np.array(["jawOpen", "mouthSmile_L", "mouthSmile_R"])
    np.savez(f, names=names, weights=np.array([[0.1, 0.2, 0.2], [0.25, 0.5, 0.5]]))
    return f


def test_face_data_equals_the_tool(tmp_path, tool, kit):
    c = controls_file(tmp_path)
    lines = []
    opts = dict(kit=kit, performances=[], controls=[c], vtk_every=0, unseen_forces=False, **COARSE)
    report = simsr.generate_face_data(tmp_path / "py", on_progress=lines.append, **opts)
    tool("datagen", "--scenario", "face", "--kit", kit, "--performances", "", "--controls", c, "--vtk-every", 0, "--no-unseen-forces",
         "--lr-cell", 2.0, "--skull-lattice", 1.6, "--hr-max-volume", 1.0, "--out", tmp_path / "cli")
    assert_same_files(tmp_path / "py", tmp_path / "cli")
    assert report["performances"][0]["name"] == "smile" and report["performances"][0]["frames"] == 2
    frames = simsr.read_paired_frames(tmp_path / "py" / "smile.npz")
    assert frames.lowres.shape[0] == 2
    assert any("frame    2/2" in l for l in lines), lines
    assert any("building the face model" in l for l in lines)
    # rerun: the finished performance reused, no frame simulated
    again = []
    simsr.generate_face_data(tmp_path / "py", on_progress=again.append, **opts)
    assert not any("frame" in l and "/2" in l for l in again), again
    with pytest.raises(simsr.ArgumentError, match="preset"):
        simsr.generate_face_data(tmp_path / "x", kit=kit, preset="huge", performances=[], controls=[c])
    with pytest.raises(simsr.Error):
        simsr.generate_face_data(tmp_path / "x", kit=tmp_path / "no_kit", performances=[], controls=[c])
