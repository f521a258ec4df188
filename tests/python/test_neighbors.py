"""Neighbour searches from Python against SciPy (cKDTree, csgraph's Dijkstra), NumPy brute force,
and the C++ tool (`simsr knn`, `simsr neighbors`): the same neighbours, ties by index."""
import numpy as np
import pytest

import simsr
from conftest import peer


@pytest.mark.parametrize("k", [1, 5, 17])
def test_kd_tree_against_ckdtree(rng, k):
    spatial = peer("scipy.spatial")
    P = rng.uniform(size=(700, 3))
    Q = rng.uniform(size=(150, 3))
    tree = simsr.KdTree(P)
    assert tree.size == 700
    d_ref, i_ref = spatial.cKDTree(P).query(Q, k=k)
    for policy in ("seq", "omp"):
        r = tree.query(Q, k, policy=policy)
        idx, dist = r
        np.testing.assert_array_equal(idx, np.asarray(i_ref).reshape(150, k))
        np.testing.assert_allclose(dist, np.asarray(d_ref).reshape(150, k), rtol=1e-12)
    out = simsr.KnnResult()
    tree.query_into(Q, k, out)
    view = out.indices
    tree.query_into(Q[::-1].copy(), k, out)  # same shape: the view sees the new result
    np.testing.assert_array_equal(view, np.asarray(i_ref).reshape(150, k)[::-1])
    with pytest.raises(simsr.ShapeError, match="keeps its shape"):
        tree.query_into(Q[:3], k, out)


def test_kd_tree_keeps_its_points_and_checks_input(rng):
    P = rng.uniform(size=(50, 3))
    tree = simsr.KdTree(P.astype(np.float32))  # converted once, the copy kept by the tree
    del P
    assert tree.query(np.zeros((1, 3)), 3).k == 3
    with pytest.raises(simsr.ArgumentError, match="k = 51"):
        tree.query(np.zeros((1, 3)), 51)
    with pytest.raises(simsr.ArgumentError, match="non-finite"):
        tree.query(np.array([[0.0, np.nan, 0.0]]), 1)
    with pytest.raises(simsr.ShapeError):
        simsr.KdTree(np.zeros((5, 2)))
    idx, dist = tree.radius(np.zeros(3), 0.5)
    assert (np.diff(dist) >= 0).all()


def test_brute_force_against_numpy(rng):
    F = rng.normal(size=(300, 24)).astype(np.float32)
    knn = simsr.BruteForceKnn(F)
    r = knn.query_self(6)
    d2 = ((F[:, None, :].astype(np.float64) - F[None, :, :]) ** 2).sum(-1)
    np.fill_diagonal(d2, np.inf)
    ref = np.argsort(d2, axis=1, kind="stable")[:, :6]
    np.testing.assert_array_equal(r.indices, ref)
    np.testing.assert_allclose(r.distances, np.sqrt(np.take_along_axis(d2, ref, 1)), rtol=1e-5)
    assert knn.query(F[:4], 1, policy="seq").indices.ravel().tolist() == [0, 1, 2, 3]


def test_geodesic_knn_against_dijkstra():
    csgraph = peer("scipy.sparse.csgraph")
    sparse = peer("scipy.sparse")
    s = simsr.icosphere(2)
    E = s.edges()
    w = np.linalg.norm(s.V[E[:, 0]] - s.V[E[:, 1]], axis=1)
    G = sparse.coo_matrix((w, (E[:, 0], E[:, 1])), shape=(s.num_vertices,) * 2)
    D = csgraph.dijkstra(G, directed=False)
    r = simsr.geodesic_knn(s.V, s.F, 8)
    np.testing.assert_allclose(r.distances, np.sort(D, axis=1)[:, :8], rtol=1e-12)
    np.testing.assert_allclose(np.take_along_axis(D, r.indices.astype(np.int64), 1), r.distances, rtol=1e-12)
    assert (r.indices[:, 0] == np.arange(s.num_vertices)).all()
    np.testing.assert_array_equal(simsr.geodesic_knn(s.V, E, 8, policy="seq").indices, r.indices)


def test_kd_tree_against_the_tool(rng, tmp_path, tool):
    P, Q = rng.uniform(size=(400, 3)), rng.uniform(size=(60, 3))
    np.save(tmp_path / "p.npy", P)
    np.save(tmp_path / "q.npy", Q)
    tool("knn", "--points", tmp_path / "p.npy", "--queries", tmp_path / "q.npy", "--k", 7, "--out", tmp_path / "knn.npz")
    z = np.load(tmp_path / "knn.npz")
    r = simsr.KdTree(P).query(Q, 7)
    np.testing.assert_array_equal(r.indices, z["indices"])
    np.testing.assert_array_equal(r.distances, z["distances"])


def test_upsampling_neighborhoods_against_the_tool(bunny, bunny_problem, tmp_path, tool):
    d = bunny["dir"]
    tool("neighbors", "--lr-rest", d / "lrestshape.obj", "--hr-rest", d / "hrestshape.obj", "--k", 20, "--out", tmp_path / "nb.npz")
    z = np.load(tmp_path / "nb.npz")
    nb = bunny_problem.neighborhoods
    assert nb.k == 20 and nb.assignment_globally_optimal
    np.testing.assert_array_equal(nb.indices, z["indices"])
    np.testing.assert_array_equal(nb.distances, z["distances"])
    np.testing.assert_array_equal(nb.lr_to_hr, z["lr_to_hr"])
    nb.save(tmp_path / "mine.npz")
    back = simsr.load_upsampling_neighborhoods(tmp_path / "mine.npz")
    np.testing.assert_array_equal(back.indices, nb.indices)
    # rows ascending, every id an LR vertex
    assert (np.diff(nb.distances, axis=1) >= 0).all()
    assert nb.indices.min() >= 0 and nb.indices.max() < bunny["lr"].num_vertices
