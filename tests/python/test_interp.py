"""The interpolation baselines from Python: each against the C++ tool (`simsr upsample`, the same
library called from C++) on bunny frames, IDW against its formula, Embedded against an affine
field it must reproduce, RBF against SciPy's RBFInterpolator; apply reads C-contiguous float64 in
place and writes out= in place (measured with tracemalloc); 1,000 warm calls grow no memory."""
import gc
import threading
import tracemalloc

import numpy as np
import pytest

import simsr
from conftest import assert_no_memory_growth, peer

FRAMES = [3, 100, 201, 255]


def positions_from(method, bunny, lowres):
    lr0, hr0 = bunny["lr"].V, bunny["hr"].V
    return np.stack([hr0 + method.apply(f - lr0) for f in lowres])


@pytest.fixture(scope="module")
def bunny_frames(bunny, tmp_path_factory):
    d = tmp_path_factory.mktemp("bunny")
    f = bunny["frames"]
    test = simsr.PairedFrames(f.lowres[FRAMES], f.highres[FRAMES], ids=FRAMES)
    train_ids = [i for i in range(0, 256, 4) if i not in FRAMES]
    train = simsr.PairedFrames(f.lowres[train_ids], f.highres[train_ids], ids=train_ids)
    simsr.write_paired_frames(d / "test.npz", test)
    simsr.write_paired_frames(d / "train.npz", train)
    return {"dir": d, "test": test, "train": train}


@pytest.mark.parametrize("name,options,cli", [
    ("embedded", {}, []),
    ("idw", {"k": 12, "power": 3.0}, ["--k", 12, "--power", 3]),
    ("mls", {}, []),
    ("rbf", {}, []),
    ("ridge", {}, []),
])
def test_methods_match_the_tool(bunny, bunny_problem, bunny_frames, tmp_path, tool, name, options, cli):
    d, fr = bunny["dir"], bunny_frames
    bunny_problem.neighborhoods.save(tmp_path / "nb.npz")
    args = ["upsample", "--method", name, "--lr-rest", d / "lrestshape.obj", "--hr-rest", d / "hrestshape.obj",
            "--frames", fr["dir"] / "test.npz", "--neighbors", tmp_path / "nb.npz", "--out", tmp_path / "out.npz", *cli]
    method = simsr.make_method(name, **options)
    method.fit(bunny_problem)
    if name == "ridge":
        args += ["--train", fr["dir"] / "train.npz"]
        method.train(simsr.displacements(fr["train"], bunny["lr"].V, bunny["hr"].V))
    tool(*args)
    ours = positions_from(method, bunny, fr["test"].lowres)
    theirs = np.load(tmp_path / "out.npz")["highres"]
    np.testing.assert_allclose(ours, theirs, rtol=0, atol=1e-12)
    # every method improves on leaving the HR surface at rest
    err = np.linalg.norm(ours - fr["test"].highres, axis=2).mean()
    rest = np.linalg.norm(bunny["hr"].V - fr["test"].highres, axis=2).mean()
    assert err < rest


def test_idw_is_its_formula(bunny, bunny_problem, rng):
    m = simsr.IDW(k=20, power=2.0)
    m.fit(bunny_problem, policy="seq")
    nb = bunny_problem.neighborhoods
    D = nb.distances
    hit = D[:, 0] == 0  # an LR vertex assigned to this HR vertex: an exact hit, weight 1 on it
    w = np.zeros_like(D)
    w[~hit] = 1.0 / D[~hit] ** 2
    w[~hit] /= w[~hit].sum(axis=1, keepdims=True)
    w[hit, 0] = 1.0
    assert hit.sum() == bunny["lr"].num_vertices  # every LR vertex sits on its own HR vertex
    x = rng.normal(size=(bunny["lr"].num_vertices, 3))
    ref = np.einsum("mk,mkc->mc", w, x[nb.indices])
    np.testing.assert_allclose(m.apply(x), ref, rtol=1e-12, atol=1e-14)


def test_embedded_reproduces_affine_fields(rng):
    lr = simsr.box_tet_mesh(3, 3, 3, [-1, -1, -1], [1, 1, 1])
    hr = simsr.icosphere(2, 0.8)
    problem = simsr.UpsamplingProblem(lr, hr)
    m = simsr.Embedded()
    m.fit(problem)
    assert (m.num_lr, m.num_hr) == (lr.num_vertices, hr.num_vertices)
    A, b = rng.normal(size=(3, 3)), rng.normal(size=3)
    out = np.empty((hr.num_vertices, 3))
    result = m.apply(lr.V @ A.T + b, out=out)
    assert result is out
    np.testing.assert_allclose(out, hr.V @ A.T + b, atol=1e-12)


def test_rbf_matches_scipy(rng):
    interpolate = peer("scipy.interpolate")
    lr = simsr.box_tet_mesh(2, 2, 2)
    hr = simsr.icosphere(1, 0.4)
    hr.V[:] += 0.5
    problem = simsr.UpsamplingProblem(lr, hr)
    m = simsr.RBF(distance="euclidean", sigma=0.6)
    m.fit(problem)
    x = rng.normal(size=(lr.num_vertices, 3))
    ref = interpolate.RBFInterpolator(lr.V, x, kernel="gaussian", epsilon=1 / 0.6, degree=-1)(hr.V)
    np.testing.assert_allclose(m.apply(x), ref, rtol=1e-8, atol=1e-10)
    with pytest.raises(simsr.ArgumentError, match="RbfDistance: unknown value 'manhattan'"):
        simsr.RBF(distance="manhattan")


def test_local_linear_learns_the_bunny(bunny, bunny_problem, bunny_frames):
    m = simsr.LocalLinear(k=20)
    m.fit(bunny_problem)
    m.train(simsr.displacements(bunny_frames["train"], bunny["lr"].V, bunny["hr"].V))
    assert m.lambda_relative > 0
    ours = positions_from(m, bunny, bunny_frames["test"].lowres)
    embedded = simsr.Embedded()
    embedded.fit(bunny_problem)
    base = positions_from(embedded, bunny, bunny_frames["test"].lowres)
    truth = bunny_frames["test"].highres
    assert np.linalg.norm(ours - truth, axis=2).mean() < 0.5 * np.linalg.norm(base - truth, axis=2).mean()


def test_policies_agree_bitwise(bunny, bunny_problem, rng):
    x = rng.normal(scale=0.01, size=(bunny["lr"].num_vertices, 3))
    for name in ("embedded", "idw", "mls"):
        m = simsr.make_method(name)
        m.fit(bunny_problem)
        np.testing.assert_array_equal(m.apply(x, policy="seq"), m.apply(x, policy="omp"))


def test_errors_name_the_method_and_shape(bunny_problem, bunny):
    m = simsr.MLS()
    with pytest.raises(simsr.ArgumentError, match="MLS.apply before fit"):
        m.apply(np.zeros((bunny["lr"].num_vertices, 3)))
    m.fit(bunny_problem)
    with pytest.raises(simsr.ShapeError) as e:
        m.apply(np.zeros((5, 3)))
    assert e.value.expected == (bunny["lr"].num_vertices, 3) and e.value.got == (5, 3)
    with pytest.raises(simsr.ArgumentError, match="unknown option 'kk'"):
        simsr.MLS(kk=3)
    with pytest.raises(simsr.ArgumentError, match="Ridge.train before fit"):
        simsr.Ridge().train(simsr.PairedFrames(np.zeros((1, 2, 3)), np.zeros((1, 2, 3))))
    x, M = np.zeros((bunny["lr"].num_vertices, 3)), bunny["hr"].num_vertices
    # out must be float64, C-ordered, writable: never a converted copy that is written and lost
    with pytest.raises(TypeError, match="out must be a float64 array, got float32"):
        m.apply(x, out=np.zeros((M, 3), np.float32))
    with pytest.raises(TypeError, match="C-contiguous"):
        m.apply(x, out=np.zeros((M, 3), order="F"))
    readonly = np.zeros((M, 3))
    readonly.flags.writeable = False
    with pytest.raises(TypeError, match="read-only"):
        m.apply(x, out=readonly)
    with pytest.raises(simsr.ShapeError):
        m.apply(x, out=np.zeros((M - 1, 3)))
    with pytest.raises(simsr.ArgumentError, match="unknown method"):
        simsr.make_method("nearest")


def traced_peak(call):
    gc.collect()
    tracemalloc.start()
    tracemalloc.reset_peak()
    before = tracemalloc.get_traced_memory()[0]
    call()
    peak = tracemalloc.get_traced_memory()[1] - before
    tracemalloc.stop()
    return peak


def test_apply_reads_and_writes_in_place(bunny, bunny_problem, rng):
    m = simsr.IDW()
    m.fit(bunny_problem)
    n, mm = bunny["lr"].num_vertices, bunny["hr"].num_vertices
    x64 = rng.normal(size=(n, 3))
    x32 = x64.astype(np.float32)
    xF = np.asfortranarray(x64)
    out = np.empty((mm, 3))
    m.apply(x64, out=out)  # warm
    # NumPy reports its buffers to tracemalloc: a converted input is a new (n, 3) float64 buffer
    assert traced_peak(lambda: m.apply(x64, out=out)) < 1024
    assert traced_peak(lambda: m.apply(x32, out=out)) >= n * 3 * 8
    assert traced_peak(lambda: m.apply(xF, out=out)) >= n * 3 * 8
    np.testing.assert_array_equal(m.apply(xF), m.apply(x64))


@pytest.mark.parametrize("name", ["idw", "ridge"])
def test_warm_apply_does_not_grow_memory(bunny, bunny_problem, bunny_frames, rng, name):
    m = simsr.make_method(name)
    m.fit(bunny_problem)
    if name == "ridge":
        m.train(simsr.displacements(bunny_frames["train"], bunny["lr"].V, bunny["hr"].V))
    x = rng.normal(scale=0.01, size=(bunny["lr"].num_vertices, 3))
    out = np.empty((bunny["hr"].num_vertices, 3))
    # the process: less than one result's size (60 kB)
    assert_no_memory_growth(lambda: (m.apply(x, out=out), m.apply(x)), rss_limit=60_000)


def test_fits_on_one_problem_from_threads(bunny, rng):
    """Fits compute the problem's neighbourhoods with the GIL released: on one problem they take turns
    (the problem's lock), and every method fits as it does alone."""
    problem = simsr.UpsamplingProblem(bunny["lr"], bunny["hr"])
    methods = [simsr.IDW(), simsr.MLS(), simsr.IDW(power=3.0), simsr.Embedded()]
    errors = []

    def fit(m):
        try:
            m.fit(problem)
        except Exception as e:  # noqa: BLE001 (reported below)
            errors.append(e)

    threads = [threading.Thread(target=fit, args=(m,)) for m in methods]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert not errors
    x = rng.normal(scale=0.01, size=(bunny["lr"].num_vertices, 3))
    alone = simsr.UpsamplingProblem(bunny["lr"], bunny["hr"])
    for m, fresh in zip(methods, [simsr.IDW(), simsr.MLS(), simsr.IDW(power=3.0), simsr.Embedded()]):
        fresh.fit(alone)
        np.testing.assert_array_equal(m.apply(x), fresh.apply(x))


def test_refused_neighborhoods_leave_the_problem_as_it_was(bunny, bunny_problem):
    other = simsr.UpsamplingProblem(simsr.box_tet_mesh(1, 1, 1), simsr.icosphere(1))
    other.ensure_neighborhoods(4)
    before = other.neighborhoods.indices.copy()
    with pytest.raises(simsr.ShapeError):
        other.neighborhoods = bunny_problem.neighborhoods  # the bunny's: another HR size
    np.testing.assert_array_equal(other.neighborhoods.indices, before)
