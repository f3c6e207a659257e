#!/usr/bin/python3
"""Derive a checkpoint of format 1 or 2 from one of format 3 (written by efdem before format 4).

How the formats differ (git log -p mpi_driver/checkpoint/checkpoint_format.*):
  1 -> 2 (5d1f29c): /driver/integrator (doubles) and /driver/integrator_text added, hashed after
         the driver's scalars;
  2 -> 3 (08d31d4, b577807): /driver/integers gained a fifth value (warmed_up), /driver/active
         and /driver/failures were added, and all three are hashed after the integrator.
Nothing else in a file depends on the version. So a format-3 checkpoint written after the
warm-up, with every realization active and no failure (what formats 1 and 2 could not express),
becomes format 2 by dropping those three additions, and format 1 by also dropping the
integrator's state — which must then be empty (a single-step integrator's: format 1 predates the
multistep integrator). The header checksum is recomputed by the rules of the target format
(CheckpointHeader::checksum); the script first checks that those rules reproduce the format-3
file's own checksum.

  derive_old_checkpoint.py FORMAT3.h5 VERSION OUT.h5
"""
import shutil
import struct
import sys

import h5py
import numpy as np

FNV_OFFSET = 0xcbf29ce484222325
FNV_PRIME = 0x100000001b3
MASK = (1 << 64) - 1


def fnv1a(data: bytes, h: int) -> int:
    for b in data:
        h = ((h ^ b) * FNV_PRIME) & MASK
    return h


def value(fmt: str, v, h: int) -> int:
    return fnv1a(struct.pack("<" + fmt, v), h)


def text(s: bytes, h: int) -> int:
    return fnv1a(s, value("Q", len(s), h))


def array(a: np.ndarray, h: int) -> int:
    a = np.ascontiguousarray(a)
    n = a.shape[0] if a.ndim else 0
    h = value("Q", n, h)
    return h if a.size == 0 else fnv1a(a.tobytes(), h)


def as_bytes(dataset) -> bytes:
    v = dataset[()]
    return v if isinstance(v, bytes) else v.encode()


def checksum(f: h5py.File, version: int) -> int:
    """CheckpointHeader::checksum() for formats 1 to 3."""
    a = f.attrs
    reals = f["/driver/reals"][()]
    ints = f["/driver/integers"][()]
    h = value("q", version, FNV_OFFSET)
    h = text(a["mode"].encode() if isinstance(a["mode"], str) else bytes(a["mode"]), h)
    h = value("q", int(a["realizations"]), h)
    h = value("q", int(a["sequence"]), h)
    h = text(as_bytes(f["/scene"]), h)
    h = text(as_bytes(f["/parameters"]), h)
    for d in reals[1:5]:
        h = value("d", float(d), h)
    h = value("q", int(ints[0]), h)
    lifting = f["/driver/lifting"][()].astype("<i8")
    h = array(lifting.reshape(-1, 4), h)  # RandomStream::State = 4 x uint64, bit-cast
    h = array(f["/driver/observable"][()].astype("<f8"), h)
    h = array(f["/driver/recorded"][()].astype("<f8"), h)
    h = value("d", float(reals[0]), h)
    for k in (1, 2, 3):
        h = value("q", int(ints[k]), h)
    if version >= 2:
        h = array(f["/driver/integrator"][()].astype("<f8"), h)
        h = text(as_bytes(f["/driver/integrator_text"]), h)
    if version >= 3:
        h = value("q", int(ints[4]), h)
        h = array(f["/driver/active"][()].astype("<i8"), h)
        h = value("q", int(f["/driver/failures"][()][0]), h)
    for name in sorted(f["/output"].keys()):
        h = text(name.encode(), h)
        h = text(f["/output/" + name][()].tobytes(), h)
    return h


def stored(h: int) -> int:
    return struct.unpack("<q", struct.pack("<Q", h))[0]


def main() -> int:
    source, version, out = sys.argv[1], int(sys.argv[2]), sys.argv[3]
    if version not in (1, 2):
        sys.exit("VERSION must be 1 or 2")
    with h5py.File(source, "r") as f:
        if int(f.attrs["format_version"]) != 3:
            sys.exit(f"{source}: not a format-3 checkpoint")
        if stored(checksum(f, 3)) != int(f.attrs["header_checksum"]):
            sys.exit(f"{source}: the format-3 rules do not reproduce its checksum")
        ints = f["/driver/integers"][()]
        if ints[4] != 1 or not (f["/driver/active"][()] == 1).all() or f["/driver/failures"][()][0]:
            sys.exit(f"{source}: before the warm-up, or with a dropped realization: formats 1 "
                     "and 2 cannot hold it")
        if version == 1 and (f["/driver/integrator"].shape[0] or as_bytes(f["/driver/integrator_text"])):
            sys.exit(f"{source}: has an integrator state; format 1 had none")
    shutil.copyfile(source, out)
    with h5py.File(out, "r+") as f:
        ints = f["/driver/integers"][()]
        del f["/driver/integers"], f["/driver/active"], f["/driver/failures"]
        f.create_dataset("/driver/integers", data=ints[:4].astype("<i8"))
        if version == 1:
            del f["/driver/integrator"], f["/driver/integrator_text"]
        f.attrs.modify("format_version", np.int64(version))
        f.attrs.modify("header_checksum", np.int64(stored(checksum(f, version))))
    return 0


if __name__ == "__main__":
    sys.exit(main())
