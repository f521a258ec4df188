#!/usr/bin/env python3
"""examples/swaps: one JSON line per swap, each swap's two results checked against what the
choice implies: Embedded reproduces the affine motion exactly and IDW does not; both materials
sag the beam by a plausible amount (a few mm to cm for these moduli) and not by the same; the two
activations give different finite outputs; exec::seq and exec::omp give the same neighbourhoods.

    /usr/bin/python3 tests/cli/test_example_swaps.py SWAPS"""
import json
import math
import subprocess
import sys

from checks import check, finish

p = subprocess.run([sys.argv[1]], capture_output=True, text=True)
check(p.returncode == 0, f"swaps: exit {p.returncode}: {p.stderr[-2000:]}")
lines = {j["swap"]: j for j in (json.loads(l) for l in p.stdout.splitlines() if l.strip())}
check(sorted(lines) == ["interpolator", "layer", "material", "policy"], f"four swaps: {sorted(lines)}")
if len(lines) == 4:
    i = lines["interpolator"]
    check(i["embedded_mean_error"] < 1e-12 < i["idw_mean_error"], f"Embedded exact on an affine motion, IDW not: {i}")
    m = lines["material"]
    check(1e-4 < m["neo_hookean_tip_sag_m"] < 0.2 and 1e-4 < m["mooney_rivlin_tip_sag_m"] < 0.2, f"plausible sags: {m}")
    check(abs(m["neo_hookean_tip_sag_m"] - m["mooney_rivlin_tip_sag_m"]) > 1e-6, f"two materials, two sags: {m}")
    l = lines["layer"]
    check(all(math.isfinite(l[k]) and l[k] > 0 for k in ("leaky_relu_output_norm", "sine_output_norm")), f"finite outputs: {l}")
    check(abs(l["leaky_relu_output_norm"] - l["sine_output_norm"]) > 1e-6, f"two activations, two outputs: {l}")
    check(lines["policy"]["same_neighbourhoods"] is True, "exec::seq and exec::omp: the same neighbourhoods")
finish()
