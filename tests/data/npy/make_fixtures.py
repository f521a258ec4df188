"""Regenerates the .npy/.npz fixtures of tests/io/test_{npy,npz}.cpp (run with /usr/bin/python3).
Contents are simple closed forms so the C++ tests state the expected values directly."""
import os
import numpy as np

here = os.path.dirname(os.path.abspath(__file__))
def p(name): return os.path.join(here, name)

base = np.arange(12).reshape(3, 4)
np.save(p("f8_c.npy"), base * 0.5)                                 # value = k/2, k in C order
np.save(p("f8_f.npy"), np.asfortranarray(base * 0.5))
np.save(p("f8_be.npy"), (base * 0.5).astype(">f8"))
np.save(p("f4_le.npy"), (base * 0.25).astype("<f4"))
np.save(p("i4_be_f.npy"), np.asfortranarray((base - 6).astype(">i4")))
np.save(p("i2_3d_f.npy"), np.asfortranarray(np.arange(24, dtype="<i2").reshape(2, 3, 4) - 12))
ints = {"i1": [-128, 127, 0, -1], "i2": [-32768, 32767, 0, -1], "i4": [-2**31, 2**31 - 1, 0, -1],
        "i8": [-2**63, 2**63 - 1, 0, -1], "u1": [0, 255, 1, 2], "u2": [0, 65535, 1, 2],
        "u4": [0, 2**32 - 1, 1, 2], "u8": [0, 2**64 - 1, 1, 2]}
for k, v in ints.items():
    np.save(p(f"{k}.npy"), np.array(v, dtype=k))
np.save(p("u8_be.npy"), np.array(ints["u8"], dtype=">u8"))
np.save(p("b1.npy"), np.array([[True, False], [False, True]]))
np.save(p("scalar_0d.npy"), np.array(3.25))
np.save(p("empty_0x3.npy"), np.zeros((0, 3), dtype="<i8"))
np.save(p("unicode.npy"), np.array(["a", "héllo", "日本語", "😀", ""]))
np.save(p("unicode_be_2d.npy"), np.array([["ab", "c"], ["", "xyz"]]).astype(">U3"))
for ver in [(2, 0), (3, 0)]:
    with open(p(f"v{ver[0]}.npy"), "wb") as f:
        np.lib.format.write_array(f, (base * 0.5).astype("<f8"), version=ver)
frames = np.arange(2 * 5 * 3, dtype=np.float64).reshape(2, 5, 3) / 8.0
np.savez(p("stored.npz"), frames=frames, names=np.array(["jawOpen", "smile"]), scalar=np.array(7, dtype=np.int64))
np.savez_compressed(p("compressed.npz"), frames=frames, names=np.array(["jawOpen", "smile"]),
                    scalar=np.array(7, dtype=np.int64), empty=np.zeros((0,), dtype="<f4"))
