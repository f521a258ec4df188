#!/usr/bin/env python3
"""Compares two frame files of one performance (simsr datagen --scenario face: DIR/<name>.npz) array by array.

Arrays that are bitwise equal say so; the frame arrays (lowres, highres: F x V x 3) that differ are
summarised by each frame's largest vertex distance: how many frames differ, from which frame, the
largest distance and, after the first differing frame, the largest and the median of the frames'
largest distances. Used for the README's MPI figures (a chunked 2-rank run against one process):

    /usr/bin/python3 scripts/compare_frames.py RANKS/amazement.npz ONE/amazement.npz
"""
import sys

import numpy as np


def main(a_path, b_path):
    a, b = np.load(a_path), np.load(b_path)
    if "chunk_first_frames" in a.files:
        print(f"{a_path}: chunks start at frames {a['chunk_first_frames'].tolist()}, overlap {int(a['chunk_overlap'])}")
    for k in sorted(set(a.files) & set(b.files)):
        x, y = a[k], b[k]
        if x.shape == y.shape and x.tobytes() == y.tobytes():
            print(f"{k}: bitwise equal {x.shape}")
            continue
        if x.shape != y.shape or x.dtype.kind != "f" or x.ndim != 3:
            print(f"{k}: DIFFERENT {x.shape} vs {y.shape}")
            continue
        d = np.linalg.norm(x - y, axis=2).max(axis=1)  # each frame's largest vertex distance
        differing = np.nonzero(d)[0]
        first = int(differing[0])
        rest = d[first + 1:]
        after = (f"; after it: largest {rest.max() * 1e6:.3g} um, median frame {np.median(rest) * 1e6:.3g} um"
                 if rest.size else "")
        print(f"{k}: {differing.size} of {d.size} frames differ, from frame {first}; "
              f"largest {d.max() * 1e6:.3g} um at frame {int(d.argmax())}{after}")
    for name, only in ((a_path, set(a.files) - set(b.files)), (b_path, set(b.files) - set(a.files))):
        if only:
            print(f"only in {name}: {sorted(only)}")


if __name__ == "__main__":
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    main(sys.argv[1], sys.argv[2])
