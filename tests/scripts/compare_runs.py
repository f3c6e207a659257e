#!/usr/bin/python3
"""Compare two efdem run files (.h5) bit for bit: every dataset under /samples and /cpi, the
p-grid and the scene text must be identical (NaN equal to NaN). Attributes that describe how a
run was executed rather than what it computed (ranks, realizations_per_rank, date, wall time,
overrides) are not compared.

    /usr/bin/python3 compare_runs.py A.h5 B.h5 [--ignore DATASET...]
        exit 0 if identical, 1 with the differences; --ignore leaves out datasets (by path
        without the leading /), e.g. ones a restart's older checkpoint did not record yet
"""
import sys

import h5py
import numpy as np

SKIP_ATTRS = {"ranks", "realizations_per_rank", "date", "run_id", "wall_seconds", "resumed_wall_seconds", "settling_wall_seconds", "total_wall_seconds",
              "restrict_seconds", "lift_seconds",
              "overrides", "git_hash", "build"}


def datasets(f):
    out = {}
    f.visititems(lambda name, obj: out.__setitem__(name, obj[()]) if isinstance(obj, h5py.Dataset) else None)
    return out


def same(a, b):
    if isinstance(a, np.ndarray) and a.dtype.kind == "f":
        return a.shape == b.shape and np.array_equal(a, b, equal_nan=True)
    return np.array_equal(a, b) if isinstance(a, np.ndarray) else a == b


def main(a_path, b_path, ignore=()):
    problems = []
    with h5py.File(a_path, "r") as a, h5py.File(b_path, "r") as b:
        da, db = datasets(a), datasets(b)
        for name in ignore:
            da.pop(name, None)
            db.pop(name, None)
        for name in sorted(set(da) | set(db)):
            if name not in da or name not in db:
                problems.append(f"{name}: only in {'B' if name not in da else 'A'}")
            elif name != "parameters" and not same(da[name], db[name]):
                x, y = np.asarray(da[name]), np.asarray(db[name])
                detail = ""
                if x.shape == y.shape and x.dtype.kind == "f":
                    diff = np.nanmax(np.abs(x - y))
                    detail = f" (max |difference| {diff:.3g})"
                problems.append(f"{name}: differs{detail}")
        for key in sorted((set(a.attrs) | set(b.attrs)) - SKIP_ATTRS):
            if key not in a.attrs or key not in b.attrs or not same(a.attrs[key], b.attrs[key]):
                problems.append(f"attribute {key}: {a.attrs.get(key)} != {b.attrs.get(key)}")
        n = len(da.get("samples/time", []))
    if problems:
        print(f"compare_runs: {a_path} and {b_path} differ:")
        for p in problems:
            print("  " + p)
        return 1
    print(f"compare_runs: {a_path} and {b_path} are identical ({len(da)} datasets, {n} samples)")
    return 0


if __name__ == "__main__":
    if len(sys.argv) < 3 or (len(sys.argv) > 3 and sys.argv[3] != "--ignore"):
        sys.exit(__doc__)
    sys.exit(main(sys.argv[1], sys.argv[2], sys.argv[4:]))
