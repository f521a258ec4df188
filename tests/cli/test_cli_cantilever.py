#!/usr/bin/env python3
"""The `cantilever` example: one JSON line with the documented keys, values consistent with each
other and with Euler–Bernoulli's formula computed here, refinement lowering the error, the BCC
embedded variant and every linear solver, and bad input mapped to exit codes (64 usage, 5 argument).

    /usr/bin/python3 tests/cli/test_cli_cantilever.py CANTILEVER_EXE

Exit 0: all checks passed; 1: a check failed."""
import json
import os
import subprocess
import sys
import tempfile

from checks import check, finish

EXE = sys.argv[1]


def run(*args):
    p = subprocess.run([EXE, *args], capture_output=True, text=True, timeout=300)
    return p.returncode, p.stdout, p.stderr


def result(*args):
    rc, out, err = run(*args)
    check(rc == 0, f"cantilever {' '.join(args)} exits 0 (got {rc}: {err.strip()})")
    lines = out.strip().splitlines()
    check(len(lines) == 1, f"one JSON line (got {len(lines)})")
    return json.loads(lines[0])


# Euler–Bernoulli for the defaults: q L^4 / (8 E I), q = rho g W H, I = W H^3 / 12.
L, W, H, E, rho, g = 1.0, 0.1, 0.1, 1e8, 1000.0, 9.81
eb = rho * g * W * H * L**4 / (8 * E * W * H**3 / 12)

coarse = result("--cells", "2")
for key in ("tip_deflection", "euler_bernoulli", "relative_error", "discretization", "cells_through_height",
            "vertices", "tets", "newton_iterations", "solver", "seconds"):
    check(key in coarse, f"key {key} present")
check(abs(coarse["euler_bernoulli"] - eb) <= 1e-12 * eb, f"euler_bernoulli {coarse['euler_bernoulli']} == {eb}")
check(abs(coarse["relative_error"] - abs(coarse["tip_deflection"] - eb) / eb) < 1e-12, "relative_error = |tip − EB| / EB")
check(coarse["tets"] == 6 * 20 * 2 * 2 and coarse["vertices"] == 21 * 3 * 3, "conforming mesh size 20×2×2 cells")
check(0 < coarse["tip_deflection"] < eb, "the coarse beam sags, stiffer than beam theory (locking)")

finer = result("--cells", "4", "--solver", "pcg-block-jacobi", "--omp")
check(finer["relative_error"] < coarse["relative_error"] / 2, f"refinement: {coarse['relative_error']} → {finer['relative_error']}")
same = result("--cells", "4", "--solver", "pcg-jacobi")
check(abs(same["tip_deflection"] - finer["tip_deflection"]) < 1e-6 * eb, "PCG-Jacobi and PCG-block-Jacobi agree")
mg = result("--cells", "4", "--solver", "pcg-multigrid", "--omp")
check(abs(mg["tip_deflection"] - finer["tip_deflection"]) < 1e-6 * eb and mg["solver"] == "pcg-multigrid", "PCG-multigrid agrees")
# The accuracy claim (the doctest suite checks convergence on 2, 4, 6 cells; this fine mesh, ~2 s
# here at -O3, would cost minutes under the sanitizers): within 3 % of beam theory at 10 cells.
fine = result("--cells", "10", "--solver", "pcg-block-jacobi", "--omp")
check(fine["relative_error"] < 0.03 and fine["tets"] == 6 * 100 * 10 * 10, f"10 cells through the height: error {fine['relative_error']} < 3 %")

vtu = os.path.join(tempfile.mkdtemp(), "beam.vtu")
embedded = result("--cells", "2", "--embedded", "--vtu", vtu)
with open(vtu, "rb") as f:
    text = f.read()
check(b'Name="displacement"' in text and b'Name="volume_ratio"' in text, "--vtu writes displacement and volume ratio")
check(f'NumberOfPoints="{embedded["vertices"]}"'.encode() in text and f'NumberOfCells="{embedded["tets"]}"'.encode() in text,
      "--vtu holds the solved mesh")
check(embedded["discretization"] == "embedded_bcc" and embedded["tets"] > coarse["tets"], "BCC lattice: more tets than the 6-tet split")
check(0 < embedded["tip_deflection"] < eb, "embedded beam sags")

# Twice the gravity, twice the deflection (small load: linear regime), beam theory too.
heavy = result("--cells", "2", "--gravity", str(2 * g))
check(abs(heavy["euler_bernoulli"] - 2 * eb) < 1e-12 * eb, "EB is linear in the load")
check(abs(heavy["tip_deflection"] / coarse["tip_deflection"] - 2) < 0.01, "the solution is linear in the load at small load")

rc, out, err = run("--cells", "0")
check(rc == 64 and out == "", f"--cells 0 is a usage error (rc {rc})")
rc, out, err = run("--cells", "3", "--width", "0.05")
check(rc == 5 and "multiple of the cell size" in err, f"a width not a multiple of h: exit 5 naming the problem (rc {rc}: {err.strip()})")
rc, out, err = run("--solver", "lu")
check(rc == 64, f"unknown solver is a usage error (rc {rc})")
rc, out, err = run("--young", "-1")
check(rc == 5 and "cantilever:" in err, f"negative Young's modulus: exit 5 (rc {rc}: {err.strip()})")

finish()
