"""simsr's readers and writers from Python: every mesh format round-trips, meshio (the peer) reads
what simsr writes and simsr reads what meshio writes, .npy/.npz agree with NumPy's, paired frames
with np.load; malformed files raise simsr.ParseError naming the file and line."""
import numpy as np
import pytest

import simsr
from conftest import peer


@pytest.fixture
def box():
    return simsr.box_tet_mesh(2, 3, 2, [0, 0, 0], [1.0, 1.5, 0.5])


@pytest.mark.parametrize("ext", [".msh", ".mesh", ".node", ".obj"])
def test_tet_mesh_round_trip(box, tmp_path, ext):
    path = tmp_path / ("box" + ext)
    simsr.write_mesh(path, box.V, box.T)
    back = simsr.read_mesh(path)
    np.testing.assert_array_equal(back.T, box.T)
    np.testing.assert_allclose(back.V, box.V, rtol=0, atol=1e-15)
    assert back.F.shape == (0, 3)


def test_msh_versions_and_triangles(box, tmp_path):
    surf = box.boundary_surface()
    for version in ("2.2", "4.1"):
        path = tmp_path / f"box{version}.msh"
        simsr.write_mesh(path, box.V, box.T, surf.F, msh_version=version)
        back = simsr.read_mesh(path)
        assert back.format_detail == f"msh {version}"
        np.testing.assert_array_equal(back.T, box.T)
        np.testing.assert_array_equal(back.F, surf.F)
    with pytest.raises(simsr.ArgumentError, match="msh_version"):
        simsr.write_mesh(tmp_path / "x.msh", box.V, box.T, msh_version="3.0")


def test_obj_triangles(tmp_path):
    s = simsr.icosphere(2)
    simsr.write_mesh(tmp_path / "s.obj", s.V, F=s.F)
    back = simsr.read_mesh(tmp_path / "s.obj")
    assert back.format == "obj" and back.polygons == s.num_faces
    np.testing.assert_array_equal(back.F, s.F)


def test_meshio_reads_what_simsr_writes(box, tmp_path):
    meshio = peer("meshio")
    surf = box.boundary_surface()
    simsr.write_mesh(tmp_path / "b.msh", box.V, box.T, msh_version="4.1")
    m = meshio.read(tmp_path / "b.msh")
    np.testing.assert_allclose(m.points, box.V)
    np.testing.assert_array_equal(m.cells_dict["tetra"], box.T)
    simsr.write_vtu(tmp_path / "b.vtu", box.V, box.T, surf.F, point_data={"height": box.V[:, 2], "x": box.V},
                    cell_data={"id": np.arange(box.num_tets + surf.num_faces)}, format="ascii")
    m = meshio.read(tmp_path / "b.vtu")
    np.testing.assert_allclose(m.points, box.V)
    np.testing.assert_array_equal(m.cells_dict["tetra"], box.T)
    np.testing.assert_array_equal(m.cells_dict["triangle"], surf.F)
    np.testing.assert_allclose(m.point_data["height"], box.V[:, 2])
    np.testing.assert_allclose(m.point_data["x"], box.V)
    np.testing.assert_array_equal(m.cell_data["id"][0], np.arange(box.num_tets))


def test_simsr_reads_what_meshio_writes(box, tmp_path):
    meshio = peer("meshio")
    mesh = meshio.Mesh(box.V, [("tetra", box.T.astype(np.int64))])
    for fmt in ("gmsh", "gmsh22"):
        meshio.write(tmp_path / "m.msh", mesh, file_format=fmt, binary=False)
        back = simsr.read_mesh(tmp_path / "m.msh")
        np.testing.assert_array_equal(back.T, box.T)
        np.testing.assert_allclose(back.V, box.V)
    meshio.write(tmp_path / "m.mesh", mesh)
    np.testing.assert_array_equal(simsr.read_mesh(tmp_path / "m.mesh").T, box.T)
    meshio.write(tmp_path / "b.msh", mesh, file_format="gmsh", binary=True)
    with pytest.raises(simsr.ParseError, match="binary .msh is not supported"):
        simsr.read_mesh(tmp_path / "b.msh")


def test_write_checks_its_input(box, tmp_path):
    with pytest.raises(simsr.ShapeError) as e:
        simsr.write_mesh(tmp_path / "x.msh", box.V[:, :2], box.T)
    assert e.value.expected == (None, 3) and e.value.got == (box.num_vertices, 2)
    assert isinstance(e.value, ValueError) and isinstance(e.value, simsr.Error)
    big = box.T.astype(np.int64)
    big[3, 1] = 2**40
    with pytest.raises(simsr.ArgumentError, match=r"entry \(3, 1\) = 1099511627776 is outside the 32-bit index range"):
        simsr.write_mesh(tmp_path / "x.msh", box.V, big)
    bad = box.T.copy()
    bad[5, 2] = box.num_vertices + 7
    with pytest.raises(simsr.MeshError) as e:
        simsr.write_vtu(tmp_path / "x.vtu", box.V, bad)
    assert e.value.element == 5 and e.value.kind == "tet"
    with pytest.raises(simsr.WriteError) as e:
        simsr.write_mesh(tmp_path / "no such folder" / "x.msh", box.V, box.T)
    assert e.value.errno != 0 and "no such folder" in e.value.file
    with pytest.raises(simsr.ArgumentError, match="unknown mesh format '.stl'"):
        simsr.write_mesh(tmp_path / "x.stl", box.V, box.T)


def test_parse_error_names_file_and_line(tmp_path):
    path = tmp_path / "bad.obj"
    path.write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 7\n")
    with pytest.raises(simsr.ParseError) as e:
        simsr.read_mesh(path)
    assert e.value.file == str(path) and e.value.line == 4
    assert str(e.value).startswith(f"{path}:4: ")
    with pytest.raises(simsr.ParseError, match="cannot open"):
        simsr.read_mesh(tmp_path / "missing.msh")


@pytest.mark.parametrize("dtype", [np.float64, np.float32, np.int32, np.int64, np.uint8, np.bool_, ">f8", "<U5"])
def test_npy_agrees_with_numpy(tmp_path, rng, dtype):
    a = (rng.normal(size=(4, 3, 2)) * 10).astype(dtype) if np.dtype(dtype).kind != "U" else np.array([["ab", "cde"], ["", "fghij"]])
    simsr.write_npy(tmp_path / "a.npy", a)
    np.testing.assert_array_equal(np.load(tmp_path / "a.npy"), a)
    np.save(tmp_path / "b.npy", np.asfortranarray(a))
    b = simsr.read_npy(tmp_path / "b.npy")
    assert b.dtype == a.dtype
    np.testing.assert_array_equal(b, a)


def test_npz_agrees_with_numpy(tmp_path, rng):
    arrays = {"x": rng.normal(size=(5, 3)), "ids": np.arange(5), "flag": np.array(True)}
    for compress in (False, True):
        simsr.write_npz(tmp_path / "z.npz", arrays, compress=compress)
        z = np.load(tmp_path / "z.npz")
        assert set(z.files) == set(arrays)
        for k, v in arrays.items():
            np.testing.assert_array_equal(z[k], v)
    np.savez_compressed(tmp_path / "n.npz", **arrays)
    back = simsr.read_npz(tmp_path / "n.npz")
    for k, v in arrays.items():
        np.testing.assert_array_equal(back[k], v)
    (tmp_path / "junk.npz").write_bytes(b"PK\x03\x04 not really a zip")
    with pytest.raises(simsr.ParseError) as e:
        simsr.read_npz(tmp_path / "junk.npz")
    assert e.value.file == str(tmp_path / "junk.npz") and e.value.line == 0


def test_paired_frames_match_numpy(bunny):
    z = np.load(bunny["dir"] / "train_frames.npz")
    f = bunny["frames"]
    assert (f.num_frames, f.num_lr, f.num_hr) == (256, 1747, 2503)
    np.testing.assert_array_equal(f.lowres, z["lowres"])
    np.testing.assert_array_equal(f.highres, z["highres"])
    np.testing.assert_array_equal(f.ids, z["frame"])


def test_paired_frames_round_trip(tmp_path, rng):
    lo, hi = rng.normal(size=(3, 4, 3)), rng.normal(size=(3, 6, 3))
    p = simsr.PairedFrames(lo, hi, ids=[7, 8, 9])
    simsr.write_paired_frames(tmp_path / "p.npz", p)
    q = simsr.read_paired_frames(tmp_path / "p.npz")
    np.testing.assert_array_equal(q.lowres, lo)
    np.testing.assert_array_equal(q.highres, hi)
    assert q.ids == [7, 8, 9]
    with pytest.raises(simsr.ShapeError):
        simsr.PairedFrames(lo, hi[:2])
