"""Meshes and their geometry from Python, each against an independent NumPy computation (volumes,
areas, normals, the cotangent Laplacian from its textbook formula), SciPy (sparse results), and
the library's invariants (Loop subdivision's rows sum to 1; validation names the bad element)."""
import numpy as np
import pytest

import simsr
from conftest import peer


def numpy_volumes(V, T):
    a, b, c, d = (V[T[:, i]] for i in range(4))
    return np.einsum("ij,ij->i", b - a, np.cross(c - a, d - a)) / 6


def numpy_cotangent_laplacian(V, F):
    n = len(V)
    L = np.zeros((n, n))
    for f in F:
        for k in range(3):
            i, j, o = f[k], f[(k + 1) % 3], f[(k + 2) % 3]
            u, w = V[i] - V[o], V[j] - V[o]
            cot = np.dot(u, w) / np.linalg.norm(np.cross(u, w))
            L[i, j] += cot / 2
            L[j, i] += cot / 2
    L -= np.diag(L.sum(axis=1))
    return L


def test_arrays_are_views_and_copies_where_documented(rng):
    V = rng.normal(size=(4, 3))
    T = np.array([[0, 1, 2, 3]])
    m = simsr.TetMesh(V, T)
    V[0, 0] = 99.0  # the mesh copied V
    assert m.V[0, 0] != 99.0
    view = m.V
    view[1, 1] = 5.0  # the property is a view: writing it writes the mesh
    assert m.V[1, 1] == 5.0
    assert m.T.dtype == np.int32


def test_volumes_against_numpy(rng):
    box = simsr.box_tet_mesh(3, 2, 4, [0, 0, 0], [1, 2, 3], split="five")
    box.V += rng.normal(scale=0.02, size=box.V.shape)
    for policy in ("seq", "omp"):
        np.testing.assert_allclose(box.signed_volumes(policy=policy), numpy_volumes(box.V, box.T), rtol=1e-12, atol=1e-15)
    assert box.volume() == pytest.approx(numpy_volumes(box.V, box.T).sum(), rel=1e-12)
    assert box.num_tets == 5 * 3 * 2 * 4


def test_surface_geometry_against_numpy(rng):
    s = simsr.icosphere(2, 1.5)
    V, F = s.V, s.F
    cross = np.cross(V[F[:, 1]] - V[F[:, 0]], V[F[:, 2]] - V[F[:, 0]])
    np.testing.assert_allclose(s.face_areas(), np.linalg.norm(cross, axis=1) / 2, rtol=1e-12)
    np.testing.assert_allclose(s.face_normals(), cross / np.linalg.norm(cross, axis=1)[:, None], atol=1e-12)
    # on a sphere every vertex normal points outward along the position
    n = s.vertex_normals(weighting="area")
    np.testing.assert_allclose(np.linalg.norm(n, axis=1), 1.0, rtol=1e-12)
    assert (np.einsum("ij,ij->i", n, V / np.linalg.norm(V, axis=1)[:, None]) > 0.999).all()
    assert s.voronoi_areas().sum() == pytest.approx(s.face_areas().sum(), rel=1e-12)
    assert s.barycentric_areas().sum() == pytest.approx(s.face_areas().sum(), rel=1e-12)
    with pytest.raises(simsr.ArgumentError, match="normal weighting"):
        s.vertex_normals(weighting="nope")


def test_cotangent_laplacian_against_its_formula(rng):
    peer("scipy.sparse")
    s = simsr.icosphere(1)
    s.V[:] += rng.normal(scale=0.05, size=s.V.shape)
    for policy in ("seq", "omp"):
        L = s.cotangent_laplacian(policy=policy)
        np.testing.assert_allclose(L.toarray(), numpy_cotangent_laplacian(s.V, s.F), atol=1e-12)
    M = s.mass_matrix()
    np.testing.assert_allclose(M.diagonal(), s.voronoi_areas(), rtol=1e-12)


def test_loop_subdivision_map():
    sheet = simsr.square_sheet(1.0, 4)
    fine, S = sheet.loop_subdivision(2)
    assert S.shape == (fine.num_vertices, sheet.num_vertices)
    np.testing.assert_allclose(np.asarray(S.sum(axis=1)).ravel(), 1.0, rtol=1e-14)
    np.testing.assert_allclose(S @ sheet.V, fine.V, atol=1e-15)
    assert fine.num_faces == 16 * sheet.num_faces
    with pytest.raises(simsr.ArgumentError, match="levels must be >= 0"):
        sheet.loop_subdivision(-1)


def test_validation_names_the_element():
    box = simsr.box_tet_mesh(2, 2, 2)
    box.validate()
    T = box.T.copy()
    T[7, [0, 1]] = T[7, [1, 0]]  # inverted
    bad = simsr.TetMesh(box.V, T)
    with pytest.raises(simsr.MeshError) as e:
        bad.validate(policy="seq")
    assert e.value.kind == "tet" and e.value.element == 7 and "inverted" in str(e.value)
    bad.validate(allow_inverted=True)
    report = bad.check()
    assert report["inverted"] == (1, 7) and not report["ok"]
    with pytest.raises(simsr.ArgumentError, match="policy: expected 'omp' or 'seq', got 'gpu'"):
        bad.check(policy="gpu")


def test_generators_and_topology():
    sheet = simsr.square_sheet(2.0, 3)
    assert sheet.num_vertices == 16 and sheet.num_faces == 2 * 9
    loops = sheet.boundary_loops()
    assert len(loops) == 1 and len(loops[0]) == 12
    assert len(sheet.boundary_edges()) == 12
    edges = sheet.edges()
    assert (edges[:, 0] < edges[:, 1]).all()
    disk = simsr.disk_surface(1.0, 3)
    assert len(disk.boundary_loops()) == 1
    cyl = simsr.cylinder_tet_mesh(0.5, 2.0, 8, 4)
    cyl.validate()
    assert cyl.volume() == pytest.approx(np.pi * 0.25 * 2.0, rel=0.05)
    shell = simsr.sphere_shell_tet_mesh(0.5, 1.0, 1, 2)
    shell.validate()
    assert shell.boundary_surface().num_faces > 0
    ell = simsr.ellipsoid_surface(200, 1.0, 0.5, 0.25)
    assert ell.num_vertices == 200
    with pytest.raises(simsr.ArgumentError):
        simsr.box_tet_mesh(0, 1, 1)
    with pytest.raises(simsr.ArgumentError, match="split"):
        simsr.box_tet_mesh(1, 1, 1, split="seven")
