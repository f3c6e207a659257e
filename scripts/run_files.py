"""Reading efdem run files (<prefix>.h5, mpi_driver/output/hdf5_recorder.hpp) in the plot and
summary scripts, with a message instead of a traceback when a file is not what they need.

    import run_files
    try:
        f = run_files.open_run(path, ["samples/time", "samples/mean_icdf"])
    except run_files.UsageError as e:
        run_files.fail("plot_icdf", e)          # prints "plot_icdf: <message>", exits 2
    mean = run_files.get(f, "samples/mean_icdf")[:]

Names are those of run-file format 3; get() and name() find a dataset of format 1 or 2 under
its older name (format 3 renamed /samples/mean and /bed/mean, names of xarray Dataset methods).

Exit code 2 is efdem's for an input error; the scripts use it for a bad file or argument.
"""
import os
import sys

EXIT_USAGE = 2


class UsageError(Exception):
    """A file or argument the script cannot use; the message names it and what is wrong."""


def fail(script, error):
    print(f"{script}: error: {error}", file=sys.stderr)
    sys.exit(EXIT_USAGE)


def text(value):
    return value.decode() if isinstance(value, bytes) else str(value)


# Format 3's name of a dataset or group -> its name in formats 1 and 2.
RENAMED_IN_FORMAT_3 = {"samples/mean_icdf": "samples/mean", "bed/ensemble_mean": "bed/mean"}


def name(f, path):
    """The path in open run file `f` (any format) of the dataset or group that format 3 calls
    `path` (no leading /): `path` itself, or its older name where only that is there."""
    path = path.lstrip("/")
    if path in f:
        return path
    for new, old in RENAMED_IN_FORMAT_3.items():
        if path == new or path.startswith(new + "/"):
            older = old + path[len(new):]
            if older in f:
                return older
    return path


def get(f, path):
    """f[path] by its format-3 name, in a run file of any format (KeyError if neither is there)."""
    return f[name(f, path)]


def open_run(path, datasets=()):
    """Opens `path` read-only as an efdem run file (h5py.File) that holds `datasets` with at least
    one row each; UsageError otherwise."""
    import h5py

    if not os.path.exists(path):
        raise UsageError(f"{path}: no such file (an efdem run writes <output.directory>/<output.prefix>.h5)")
    if os.path.isdir(path):
        raise UsageError(f"{path}: is a directory, not an efdem run file (<prefix>.h5)")
    try:
        f = h5py.File(path, "r")
    except OSError as e:
        raise UsageError(f"{path}: not an HDF5 file, so not an efdem run file ({e})") from None
    if "mode" not in f.attrs or "format_version" not in f.attrs:
        f.close()
        raise UsageError(f"{path}: an HDF5 file but not an efdem run file (no 'mode' and 'format_version' "
                         "attributes; a checkpoint, *_ckpt_*.h5, is not a run file either)")
    for wanted in datasets:
        found = name(f, wanted)
        if found not in f or len(f[found]) == 0:
            status = text(f.attrs.get("end_status", "?"))
            f.close()
            raise UsageError(f"{path}: the run file has no {'/' + wanted if found not in f else 'rows in /' + found} "
                             f"(end_status '{status}': a run that ended before its first sample?)")
    return f


def realizations_per_sample(f):
    """The realizations in the ensemble means at each sample of open run file `f`:
    /samples/realizations_used (R less those a failure dropped), or the `realizations` attribute
    for every sample in files without it."""
    n = len(f["samples/time"])
    if "samples/realizations_used" in f:
        return f["samples/realizations_used"][:n].astype(float)
    import numpy as np

    return np.full(n, float(f.attrs.get("realizations", 1)))
