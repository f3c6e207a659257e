#!/usr/bin/env bash
# The resumable studies of bench/ (bench/study_runs.py run_case): a run that an earlier attempt
# left incomplete continues from its newest checkpoint, and the result is bit for bit the
# uninterrupted run's (compare_runs.py). The incomplete attempt is made by marking a completed run's file
# 'running' and deleting the checkpoints after the first: what a kill leaves, since a restart
# takes the output files from the checkpoint. A checkpoint efdem refuses (here: not HDF5) stops
# the run and keeps its files; EFDEM_STUDY_ON_REFUSAL=restart keeps them aside and starts again.
#   study_resume.sh EFDEM_BINARY MPIEXEC [MPIEXEC_PREFLAGS...]
source "$(dirname "$0")/lib.sh" "$@"
src=$(cd "$here/../.." && pwd)
cd "$work" || exit 1
/usr/bin/python3 - "$src" "$efdem" "$here/tiny_scene.cfg" "$work" "$here/compare_runs.py" <<'PY' || exit 1
import glob, os, shutil, subprocess, sys
import h5py
src, efdem, scene, work, compare = sys.argv[1:]
sys.path.insert(0, os.path.join(src, "bench"))
import study_runs as sr

over = {"run.duration": 6, "checkpoint.interval": 4, "checkpoint.keep": 100, "seed": 5}
def run():
    return sr.run_case(efdem, 2, scene, work, "d", "direct", over)

def fail(why):
    sys.exit(f"FAIL: {why}")

if not run():
    fail("the first, uninterrupted run did not complete")
ref = os.path.join(work, "ref.h5")
shutil.copy(sr.run_file(work, "d"), ref)
checkpoints = sorted(glob.glob(os.path.join(work, "d", "d_ckpt_*.h5")))
if len(checkpoints) < 2:
    fail(f"expected checkpoints every 4 samples, found {checkpoints}")
for c in checkpoints[1:]:
    os.remove(c)
with h5py.File(sr.run_file(work, "d"), "a") as f:
    f.attrs["end_status"] = "running"
if sr.completed(work, "d"):
    fail("a run file marked 'running' counts as completed")
if not run():
    fail("the run continued from its checkpoint did not complete")
log = open(os.path.join(work, "d", "d.log")).read()
if "restarted from" not in log:
    fail("the second attempt did not restart from the checkpoint")
code = subprocess.call(["/usr/bin/python3", compare, ref, sr.run_file(work, "d")])
if code != 0:
    fail("the continued run differs from the uninterrupted one")
print("PASS: an incomplete study run continues from its checkpoint, bit for bit the uninterrupted run")

# A checkpoint efdem refuses (another version, other keys): the study stops that run and changes
# nothing in its folder (hours of a run are not thrown away for a key a newer efdem added); with
# EFDEM_STUDY_ON_REFUSAL=restart the refused attempt is moved aside, kept whole, and the run starts
# again and completes, equal to the reference.
with h5py.File(sr.run_file(work, "d"), "a") as f:
    f.attrs["end_status"] = "running"
first = sorted(glob.glob(os.path.join(work, "d", "d_ckpt_*.h5")))[-1]
for c in glob.glob(os.path.join(work, "d", "d_ckpt_*.h5")):
    os.remove(c)
open(first, "w").write("not a checkpoint\n")
def snapshot(folder):
    return {n: open(os.path.join(folder, n), "rb").read() for n in sorted(os.listdir(folder))
            if n != "d.log"}
before = snapshot(os.path.join(work, "d"))
if run():
    fail("a run whose checkpoint was refused counted as completed")
if snapshot(os.path.join(work, "d")) != before:
    fail("a refused checkpoint changed the run's folder (a file removed or rewritten)")
print("PASS: a refused checkpoint stops the study run and keeps every file of its attempt")
os.environ["EFDEM_STUDY_ON_REFUSAL"] = "restart"
if not run():
    fail("the run whose checkpoint was refused did not start again and complete")
del os.environ["EFDEM_STUDY_ON_REFUSAL"]
aside = glob.glob(os.path.join(work, "d.refused-*"))
if len(aside) != 1 or snapshot(aside[0]) != before:
    fail(f"the refused attempt was not kept whole beside the new one: {aside}")
if subprocess.call(["/usr/bin/python3", compare, ref, sr.run_file(work, "d")]) != 0:
    fail("the run started again differs from the reference")
print("PASS: on request the refused attempt is kept aside and the study run starts again")

# Settled beds reused: the first run of the bed kept them (bed.write), and the runs after it start
# from them: the attempt started again above, and a run of the same bed in another folder (same
# seed and bed keys), which is the same run.
kept = glob.glob(os.path.join(work, "beds", "*", "bed_r000[01].data"))
if len(kept) != 2:
    fail(f"expected the 2 realizations' beds under {work}/beds, found {kept}")
if "bed.read" not in open(os.path.join(work, "d", "command.txt")).read():
    fail("the run started again did not start from the beds its first attempt kept")
if not sr.run_case(efdem, 2, scene, work, "d2", "direct", dict(over, **{"observe.bed": "false"})):
    fail("the run from the kept beds did not complete")
if "bed: starting from the settled bed" not in open(os.path.join(work, "d2", "d2.log")).read():
    fail("the second run of the bed did not start from the kept beds")
if subprocess.call(["/usr/bin/python3", compare, ref, sr.run_file(work, "d2")]) != 0:
    fail("the run from the kept beds differs from the run that kept them")
if not sr.run_case(efdem, 2, scene, work, "d3", "direct", dict(over, seed=6)):
    fail("a run of another seed did not complete")
if "bed.write" not in open(os.path.join(work, "d3", "command.txt")).read():
    fail("a run of another seed (another bed) did not settle its own")
print("PASS: a study keeps a bed once and starts its later runs of that bed from it")

# The archive a study keeps (one per run, not in git): the kept groups, compact. Time axes and 1-D series are
# exact; members' arrays are float32, within 1e-6 relative of the run file (7 significant digits:
# 1e-5 d_p at 10 d_p, far below any noise floor a study reads).
import numpy as np
dest = os.path.join(work, "archive", "d.h5")
sr.archive(work, "d", dest)
if not sr.archived(dest):
    fail("the archive of a completed run does not count as archived")
with h5py.File(sr.run_file(work, "d"), "r") as a, h5py.File(dest, "r") as b:
    if "study_command" not in b.attrs or b.attrs["end_status"] != a.attrs["end_status"]:
        fail("the archive lost the root attributes or the command")
    for name in ("samples/time", "p", "realization"):
        if not np.array_equal(a[name][()], b[name][()]):
            fail(f"{name} differs in the archive")
    for name in ("samples/icdf", "samples/mean_icdf", "samples/com"):
        x, y = a[name][()], b[name][()]
        if not np.allclose(x, y, rtol=1e-6, atol=1e-6):
            fail(f"{name} differs in the archive by {np.abs(x - y).max()}")
    if b["samples/icdf"].attrs["units"] != a["samples/icdf"].attrs["units"]:
        fail("the archive lost a dataset's units")
    if "DIMENSION_LIST" in b["samples/icdf"].attrs:
        fail("the archive keeps references into the run file")
print("PASS: the archive of a run is its kept groups, compact")
PY
