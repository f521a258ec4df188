"""Shared fixtures and checks of the Python module's suite (tests/python mirrors python/src's areas).

ctest runs it with the build's python/ folder on PYTHONPATH, SIMSR_DATA_DIR the bundled data
and SIMSR_TOOL the command-line tool, the C++ reference several tests compare against. With
SIMSR_REQUIRE_PEERS=1 (scripts/test.sh, CI) a missing peer (SciPy, meshio, the tool, the data)
fails the test instead of skipping it.
"""
import gc
import os
import pathlib
import subprocess
import tracemalloc

import numpy as np
import pytest

import simsr

REQUIRE_PEERS = os.environ.get("SIMSR_REQUIRE_PEERS", "0") not in ("", "0")


def need(condition, what):
    """Skips (or, with SIMSR_REQUIRE_PEERS, fails) a test whose peer is missing."""
    if condition:
        return
    if REQUIRE_PEERS:
        pytest.fail(f"{what} is missing and SIMSR_REQUIRE_PEERS is set")
    pytest.skip(f"{what} is missing")


def peer(module):
    """Imports a peer module (scipy.spatial, meshio, ...) or skips/fails as `need` says."""
    try:
        return __import__(module, fromlist=["_"])
    except ImportError:
        need(False, f"the peer {module}")


@pytest.fixture(scope="session")
def data_dir():
    d = pathlib.Path(os.environ.get("SIMSR_DATA_DIR", pathlib.Path(__file__).resolve().parents[3] / "shared" / "data"))
    need((d / "bunny" / "train_frames.npz").exists(), f"the bundled data ({d})")
    return d


@pytest.fixture(scope="session")
def tool():
    """Runs the simsr command-line tool (the C++ reference): tool("knn", "--points", ...)."""
    exe = os.environ.get("SIMSR_TOOL", "")
    need(exe and os.access(exe, os.X_OK), "the simsr tool (SIMSR_TOOL)")

    def run(*args):
        r = subprocess.run([exe, *map(str, args)], capture_output=True, text=True, env={**os.environ, "OMP_NUM_THREADS": "2"})
        assert r.returncode == 0, f"simsr {' '.join(map(str, args))} failed ({r.returncode}):\n{r.stderr}"
        return r.stdout

    return run


@pytest.fixture(scope="session")
def bunny(data_dir):
    """The bunny's rest shapes and frames (N = 1747 LR vertices, M = 2503 HR vertices, 256 frames)."""
    d = data_dir / "bunny"
    lr = simsr.read_mesh(d / "lrestshape.obj")
    hr = simsr.read_mesh(d / "hrestshape.obj")
    frames = simsr.read_paired_frames(d / "train_frames.npz")
    return {
        "dir": d,
        "lr": simsr.TetMesh(lr.V, lr.T),
        "hr": simsr.TriMesh(hr.V, hr.F),
        "frames": frames,
    }


@pytest.fixture(scope="session")
def bunny_problem(bunny):
    p = simsr.UpsamplingProblem(bunny["lr"], bunny["hr"])
    p.ensure_neighborhoods(20)
    return p


@pytest.fixture
def rng():
    return np.random.default_rng(20261129)


def rss_bytes():
    with open("/proc/self/statm") as f:
        return int(f.read().split()[1]) * 4096


def assert_no_memory_growth(call, calls=1000, rss_limit=100_000):
    """`call()` warmed up, then run `calls` times: no Python object left behind (tracemalloc, which
    sees NumPy's buffers) and the process (C++ allocations included) grown by less than rss_limit."""
    for _ in range(20):
        call()
    gc.collect()
    rss0 = rss_bytes()
    tracemalloc.start()
    t0 = tracemalloc.get_traced_memory()[0]
    for _ in range(calls):
        call()
    gc.collect()
    grown = tracemalloc.get_traced_memory()[0] - t0
    tracemalloc.stop()
    assert grown < 4096, f"{calls} warm calls left {grown} traced bytes behind"
    assert rss_bytes() - rss0 < rss_limit, f"{calls} warm calls grew the process by {rss_bytes() - rss0} bytes"
