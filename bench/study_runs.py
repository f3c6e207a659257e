"""What the resumable studies in bench/ share: one efdem run per folder, skipped when its run file
says "completed"; an incomplete one continues from its newest checkpoint (every run writes them:
a direct run every 100 samples, a CPI run after every coarse step; a restart is bit for bit the
uninterrupted run, mpi:restart_equality), or starts again when it has none. When efdem refuses
the checkpoint (another version, other keys) the study stops there and changes nothing: hours
of a run are not thrown away for a key a newer efdem added. EFDEM_STUDY_ON_REFUSAL=restart
moves the refused attempt aside (NAME.refused-<time>/) and starts the run again.

Settled beds are reused: the first run of a bed (scene, ranks and the keys that shape the bed:
seed, species, box, contacts, bed.*) keeps its settled beds (bed.write) in FOLDER/beds/<key>/,
and every later run of that bed starts from them (bed.read), which gives the same run bit for
bit without settling again (mpi:bed_reuse). run_case(..., beds=False) settles every run."""
import datetime as dt_
import glob
import hashlib
import os
import re
import shutil
import subprocess
import time

import h5py


def text(v):
    return v.decode() if isinstance(v, bytes) else str(v)


def run_file(folder, name):
    return os.path.join(folder, name, name + ".h5")


def completed(folder, name):
    try:
        with h5py.File(run_file(folder, name), "r") as f:
            return text(f.attrs.get("end_status", "")).startswith("completed")
    except (OSError, KeyError):
        return False


def newest_checkpoint(folder, name):
    """The newest checkpoint an earlier, incomplete attempt of FOLDER/NAME left, or None."""
    found = sorted(glob.glob(os.path.join(folder, name, f"{name}_ckpt_*.h5")))
    return found[-1] if found else None


# The keys whose values shape a settled bed (besides the scene file and the rank count): the seed,
# the time step, the box, the species and the settling's physics and protocol.
BED_KEYS = re.compile(r"^(seed|dt|effects|ensemble\.realizations_per_rank|domain\.|species\.|bed\.|"
                      r"pair_contact\.|wall_contact\.|gravity\.|neighbor\.)")


def realizations_per_rank(scene, overrides):
    if "ensemble.realizations_per_rank" in overrides:
        return int(overrides["ensemble.realizations_per_rank"])
    with open(scene) as f:
        for line in f:
            m = re.match(r"\s*ensemble\.realizations_per_rank\s*=\s*(\d+)", line)
            if m:
                return int(m.group(1))
    return 1


def bed_overrides(np_, scene, folder, overrides):
    """bed.write (the first run of its bed) or bed.read (the beds are there) for a run of SCENE
    on NP ranks with OVERRIDES: the beds of FOLDER/beds/<key>/, key from the scene's text, NP and
    the overrides that shape a bed (BED_KEYS)."""
    if "bed.write" in overrides or "bed.read" in overrides:
        return {}
    h = hashlib.sha256()
    with open(scene, "rb") as f:
        h.update(f.read())
    h.update(f"np={np_}\n".encode())
    for k in sorted(overrides):
        if BED_KEYS.match(k):
            h.update(f"{k}={overrides[k]}\n".encode())
    name = os.path.join(os.path.abspath(folder), "beds", h.hexdigest()[:16], "bed.data")
    r = np_ * realizations_per_rank(scene, overrides)
    stem = name[:-len(".data")]
    if all(os.path.exists(f"{stem}_r{k:04d}.data") for k in range(r)):
        return {"bed.read": name}
    # Some but not all of the files: a writer killed while writing; replace them. (A new run's
    # folder is empty, so output.overwrite deletes nothing else.)
    return {"bed.write": name, "output.overwrite": "true"}


def refusal(log):
    """The error line efdem wrote to LOG when it refused a checkpoint (the last one), or a pointer
    to the log."""
    try:
        with open(log, errors="replace") as f:
            errors = [line.strip() for line in f if "error" in line.lower()]
        return errors[-1] if errors else f"see {log}"
    except OSError:
        return f"see {log}"


def run_case(efdem, np_, scene, folder, name, mode, overrides, label=None, beds=True):
    """mpirun -np NP efdem SCENE mode=MODE output.* KEY=VALUE... into FOLDER/NAME/ (command.txt,
    NAME.log, NAME.h5), continued from the newest checkpoint of an earlier attempt when there is
    one. With `beds`, from the settled beds an earlier run of the same bed kept (bed_overrides).
    Returns whether it completed."""
    label = label or name
    d = os.path.join(folder, name)
    overrides = dict(overrides)
    if beds:
        overrides.update(bed_overrides(np_, scene, folder, overrides))
    overrides.setdefault("checkpoint.interval", 100 if mode == "direct" else 1)
    cmd = ["mpirun", "-np", str(np_), "--oversubscribe", efdem, scene, f"mode={mode}",
           f"output.directory={os.path.abspath(d)}", f"output.prefix={name}"] + \
        [f"{k}={v}" for k, v in overrides.items()]
    env = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1")
    t0 = time.time()
    checkpoint = newest_checkpoint(folder, name) if os.path.isdir(d) else None
    code = None
    if checkpoint:
        print(f"  {label}: continued from {os.path.basename(checkpoint)} "
              f"{dt_.datetime.now(dt_.timezone.utc):%H:%M:%S} UTC", flush=True)
        with open(os.path.join(d, name + ".log"), "a") as log:
            code = subprocess.call(cmd + [f"restart={checkpoint}"], stdout=log, stderr=subprocess.STDOUT,
                                   env=env)
        if code == 2:  # efdem refused the checkpoint (another version, other keys)
            reason = refusal(os.path.join(d, name + ".log"))
            if os.environ.get("EFDEM_STUDY_ON_REFUSAL", "stop") != "restart":
                print(f"  {label}: efdem refused {os.path.basename(checkpoint)}: {reason}\n"
                      f"  {label}: nothing was changed in {d}; fix the cause and run again to "
                      f"continue, or run with EFDEM_STUDY_ON_REFUSAL=restart to keep this attempt "
                      f"in {name}.refused-<time>/ and start the run again", flush=True)
                return False
            aside = f"{d}.refused-{dt_.datetime.now(dt_.timezone.utc):%Y%m%dT%H%M%S}"
            os.rename(d, aside)
            print(f"  {label}: efdem refused the checkpoint ({reason}); that attempt is kept in "
                  f"{aside}; started again", flush=True)
            code = None
    if code is None:
        if os.path.isdir(d):
            shutil.rmtree(d)  # an incomplete run without any checkpoint: start it again
        os.makedirs(d)
        with open(os.path.join(d, "command.txt"), "w") as f:
            f.write(" ".join(cmd) + "\n")
        print(f"  {label}: started {dt_.datetime.now(dt_.timezone.utc):%H:%M:%S} UTC", flush=True)
        with open(os.path.join(d, name + ".log"), "w") as log:
            code = subprocess.call(cmd, stdout=log, stderr=subprocess.STDOUT, env=env)
    ok = code == 0 and completed(folder, name)
    print(f"  {label}: {'ok' if ok else f'FAILED ({code})'} in {time.time() - t0:.0f} s", flush=True)
    return ok


def ensure(efdem, np_, scene, folder, name, mode, overrides, dest, label=None):
    """The archive DEST of the run NAME: skipped when it is there, else the run made in FOLDER (or
    continued, run_case) and archived. Returns whether DEST holds the completed run."""
    label = label or name
    if archived(dest):
        print(f"  {label}: done before, skipped", flush=True)
        return True
    if completed(folder, name) or run_case(efdem, np_, scene, folder, name, mode, overrides, label=label):
        archive(folder, name, dest)
        return True
    return False


# What a study keeps of a run, in the run file's own layout: the groups its analysis reads and the
# root attributes, one file per run under bench/results/ (not committed: study run files stay out of
# git; the analysis, the plots and the commands that regenerate them are). A study skips a run
# whose archive is there. They are compact (below): 0.3-1.2 MB for a demo-bed ensemble of
# R = 4-8 over 600-1,000 units, where the run file is 5 MB and more.
ARCHIVED_GROUPS = ("samples", "cpi", "realization", "p", "bed", "steady")


# HDF5 dimension-scale bookkeeping (object references into the source file); the axes' names
# stay in DIMENSION_LABELS.
DIMENSION_SCALE_ATTRIBUTES = ("DIMENSION_LIST", "REFERENCE_LIST", "CLASS", "NAME")


def _copy_compact(src, out):
    """Every dataset of `src` (an h5py group) into `out`, gzip-compressed; arrays of two or more
    dimensions of float64 (members' ICDFs, profiles) as float32: 7 significant digits, 1e-5 d_p at
    50 d_p, far below any difference a study reads (the noise floors are 0.01-0.5 d_p). Time
    axes and other 1-D series stay float64. Dataset attributes (units, descriptions) are kept."""
    def visit(name, obj):
        if not isinstance(obj, h5py.Dataset):
            return
        data = obj[()]
        kw = {}
        if getattr(data, "ndim", 0) >= 2 and data.dtype == "float64":
            data = data.astype("float32")
        if getattr(data, "ndim", 0) >= 1 and data.size > 64 and data.dtype.kind in "fiu":
            kw = dict(compression="gzip", compression_opts=6, shuffle=True)
        ds = out.create_dataset(name, data=data, **kw)
        for key, value in obj.attrs.items():
            if key not in DIMENSION_SCALE_ATTRIBUTES:  # references into the run file: not kept
                ds.attrs[key] = value
    src.visititems(visit)


def _copy_kept(src, out, names):
    """The root attributes and the objects `names` of `src` into `out`: groups compact
    (_copy_compact), root datasets (the /p and /realization axes) as they are."""
    for key, value in src.attrs.items():
        out.attrs[key] = value
    for name in names:
        if name not in src:
            continue
        if isinstance(src[name], h5py.Dataset):
            out.create_dataset(name, data=src[name][()])
            continue
        _copy_compact(src[name], out.require_group(name))
        for key, value in src[name].attrs.items():
            out[name].attrs[key] = value


def archive(folder, name, dest):
    """Copy the kept part of FOLDER/NAME/NAME.h5 to DEST (an .h5 path), compact, with the command."""
    os.makedirs(os.path.dirname(dest), exist_ok=True)
    tmp = dest + ".part"
    with h5py.File(run_file(folder, name), "r") as src, h5py.File(tmp, "w") as out:
        _copy_kept(src, out, ARCHIVED_GROUPS)
        with open(os.path.join(folder, name, "command.txt")) as f:
            out.attrs["study_command"] = f.read().strip()
    os.replace(tmp, dest)  # a half-written archive is never mistaken for a result


def compact(path):
    """Rewrite an archive written before archives were compact (the same content)."""
    tmp = path + ".part"
    with h5py.File(path, "r") as src, h5py.File(tmp, "w") as out:
        _copy_kept(src, out, list(src.keys()))
    os.replace(tmp, path)


def archived(dest):
    """Whether DEST holds the archive of a completed run."""
    try:
        with h5py.File(dest, "r") as f:
            return text(f.attrs.get("end_status", "")).startswith("completed")
    except (OSError, KeyError):
        return False
