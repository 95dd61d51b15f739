"""Exact comparison of two trajectories: every dataset of one is in the other with the same
shape and the same bits (NaN where the other has NaN).  Prints the first difference."""
import sys

import h5py
import numpy as np


def datasets(f):
    out = {}
    f.visititems(lambda name, obj: out.__setitem__(name, obj[()]) if isinstance(obj, h5py.Dataset) else None)
    return out


def differences(path_a, path_b):
    with h5py.File(path_a, "r") as fa, h5py.File(path_b, "r") as fb:
        a, b = datasets(fa), datasets(fb)
    diffs = [f"only in one file: {n}" for n in sorted(set(a) ^ set(b))]
    for name in sorted(set(a) & set(b)):
        x, y = np.asarray(a[name]), np.asarray(b[name])
        if x.dtype.kind == "f" and x.shape == y.shape:
            same = np.array_equal(x.view(np.uint8), y.view(np.uint8))
        else:
            same = x.shape == y.shape and np.array_equal(x, y)
        if not same:
            diffs.append(f"differs: {name}")
    return diffs, len(set(a) & set(b))


if __name__ == "__main__":
    d, n = differences(sys.argv[1], sys.argv[2])
    print(f"{n} datasets compared; {len(d)} differences", *d[:10], sep="\n")
    sys.exit(1 if d else 0)
