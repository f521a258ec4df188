"""The quasistatic physics from Python: a beam clamped by a bone sags under gravity as the C++
cantilever verification computes (the `cantilever` example, same mesh and material) and near
Euler–Bernoulli; springs to a rigidly moved copy pull a free body exactly there; bones follow their
transforms exactly; materials by name with the library's checks."""
import json
import os
import subprocess

import numpy as np
import pytest

import simsr
from conftest import need


def beam(cells=4):
    """The cantilever verification's conforming beam: 1 x 0.1 x 0.1 m, `cells` cells through the height."""
    h = 0.1 / cells
    return simsr.box_tet_mesh(round(1 / h), cells, cells, [0, 0, 0], [1.0, 0.1, 0.1])


def test_cantilever_matches_the_cpp_verification():
    mesh = beam()
    body = simsr.ElasticBody(mesh, material="neo_hookean", young=1e8, poisson=0.0, density=1000, gravity=(0, 0, -9.81))
    wall = np.flatnonzero(mesh.V[:, 0] <= 1e-9)
    body.add_bone("wall", wall)
    x, report = body.solve()
    assert report["converged"] and report["iterations"] >= 1
    np.testing.assert_array_equal(x[wall], mesh.V[wall])  # Dirichlet: the wall stays put
    tip = mesh.V[:, 0] >= 1 - 1e-9
    deflection = -(x[tip, 2] - mesh.V[tip, 2]).mean()
    q, inertia = 1000 * 9.81 * 0.1 * 0.1, 0.1 * 0.1 ** 3 / 12
    euler_bernoulli = q / (8 * 1e8 * inertia)
    assert 0.1 < (euler_bernoulli - deflection) / euler_bernoulli < 0.2  # 4 linear tets through the height: stiffer than the beam
    exe = os.environ.get("SIMSR_CANTILEVER", "")
    need(exe and os.access(exe, os.X_OK), "the cantilever example (SIMSR_CANTILEVER)")
    r = subprocess.run([exe, "--cells", "4"], capture_output=True, text=True, check=True)
    cpp = json.loads(r.stdout)
    assert deflection == pytest.approx(cpp["tip_deflection"], rel=1e-6)
    assert body.elastic_energy(x) > 0


def test_springs_pull_a_free_body_to_a_rigid_copy(rng):
    mesh = simsr.box_tet_mesh(2, 2, 2)
    R = np.linalg.qr(rng.normal(size=(3, 3)))[0]
    R *= np.sign(np.linalg.det(R))
    target = mesh.V @ R.T + [0.3, -0.2, 0.5]
    for material in simsr.material_names():
        body = simsr.ElasticBody(mesh, material=material, gravity=(0, 0, 0), relative_tolerance=1e-12)
        body.set_springs(np.arange(mesh.num_vertices), target, np.full(mesh.num_vertices, 1e4))
        x, report = body.solve(policy="seq")
        assert report["converged"]
        np.testing.assert_allclose(x, target, atol=1e-10)
        assert body.elastic_energy(x) == pytest.approx(0, abs=1e-9)


def test_bones_follow_their_transforms():
    mesh = simsr.box_tet_mesh(4, 1, 1, [0, 0, 0], [2, 0.5, 0.5])
    body = simsr.ElasticBody(mesh, material="corotated", young=1e6, poisson=0.3, gravity=(0, 0, 0))
    left, right = np.flatnonzero(mesh.V[:, 0] < 1e-9), np.flatnonzero(mesh.V[:, 0] > 2 - 1e-9)
    body.add_bone("left", left)
    body.add_bone("right", right)
    body.set_bone_hinge("right", [2, 0.25, 0.25], [0, 1, 0], 0.2)
    x, report = body.solve()
    assert report["converged"]
    c, s = np.cos(0.2), np.sin(0.2)
    Ry = np.array([[c, 0, s], [0, 1, 0], [-s, 0, c]])
    np.testing.assert_allclose(x[right], (mesh.V[right] - [2, 0.25, 0.25]) @ Ry.T + [2, 0.25, 0.25], atol=1e-14)
    np.testing.assert_array_equal(x[left], mesh.V[left])
    body.set_bone_transform("right", t=[0.1, 0, 0])
    x2, _ = body.solve(x)  # warm start from the last solution
    np.testing.assert_allclose(x2[right], mesh.V[right] + [0.1, 0, 0], atol=1e-14)
    # the free vertices in between moved: the bar is stretched by 5 %
    middle = np.flatnonzero(np.abs(mesh.V[:, 0] - 1) < 1e-9)
    assert (x2[middle, 0] - mesh.V[middle, 0]).mean() == pytest.approx(0.05, rel=0.2)


def test_errors():
    mesh = simsr.box_tet_mesh(1, 1, 1)
    with pytest.raises(simsr.ArgumentError, match="unknown material 'stvk' \\(known: neo_hookean, corotated, mooney_rivlin\\)"):
        simsr.ElasticBody(mesh, material="stvk")
    with pytest.raises(simsr.ArgumentError, match="Poisson"):
        simsr.ElasticBody(mesh, poisson=0.5)
    body = simsr.ElasticBody(mesh)
    body.add_bone("a", [0, 1])
    with pytest.raises(simsr.MeshError) as e:
        body.add_bone("b", [1, 2])
    assert e.value.element == 1 and "attached to both bone 'a' and bone 'b'" in str(e.value)
    with pytest.raises(simsr.ShapeError):
        body.solve(np.zeros((3, 3)))
    with pytest.raises(simsr.ShapeError):
        body.set_springs([0, 1], np.zeros((3, 3)), np.ones(2))
    T = mesh.T.copy()
    T[0, [0, 1]] = T[0, [1, 0]]
    with pytest.raises(simsr.Error):  # an inverted rest tet
        simsr.ElasticBody(simsr.TetMesh(mesh.V, T))
