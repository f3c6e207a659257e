#!/usr/bin/env bash
# Settled beds kept and reused (bed.write, bed.read; docs/scene_reference.md "bed"):
#  1. bed.write writes one LAMMPS data file per realization (NAME_rNNNN.data) after settling;
#  2. a run with bed.read = NAME skips settling, says where its beds came from, and its run file
#     equals the writing run's bit for bit (same seed: the same initial states, the same run);
#  3. a bed.write onto existing files, a bed that does not fit (bed.count) and a realization
#     without its file are refused with exit 2 (and by --check), naming the key and the file;
#  4. a shared bed with bed.read.velocity_rms: the realizations start from the same positions,
#     part at once, and the run passes the watchdog;
#  5. a restart of a run from kept beds reads no bed file (bed.read may change on restart) and
#     equals the uninterrupted run.
#   bed_reuse.sh EFDEM_BINARY MPIEXEC [MPIEXEC_PREFLAGS...]
source "$(dirname "$0")/lib.sh" "$@"
scene="$here/tiny_scene.cfg"
failures=0
fail() { echo "FAIL: $*"; failures=$((failures + 1)); }
efd() { local np=$1; shift; timeout 300 "$mpiexec" -n "$np" "${launcher[@]}" "$@"; }
# The tiny scene, settled quickly (as restart_equality's "settled" case), 2 ranks x 1.
common=(mode=direct run.duration=3 bed.settle=true bed.settle.ke_threshold=1e-3
        bed.settle.max_time=20 output.directory="$work")
beds="$work/beds/tiny.data"

# 1. The writing run.
efd 2 "$efdem" "$scene" "${common[@]}" output.prefix=a bed.write="$beds" > "$work/a.log" 2>&1 \
  || { cat "$work/a.log"; fail "the run with bed.write failed"; }
[ -f "$work/beds/tiny_r0000.data" ] && [ -f "$work/beds/tiny_r0001.data" ] \
  && grep -q "settling realization" "$work/a.log" && grep -q "bed.write: the beds of the 2 realization(s) are in" "$work/a.log" \
  && grep -q "^Atom Type Labels" "$work/beds/tiny_r0001.data" && grep -q "^256 atoms" "$work/beds/tiny_r0001.data" \
  && echo "PASS: bed.write wrote one bed per realization after settling" \
  || { ls "$work/beds"; cat "$work/a.log"; fail "bed.write's files or log line"; }

# 2. The run from the kept beds: no settling, the same run.
efd 2 "$efdem" "$scene" "${common[@]}" output.prefix=b bed.read="$beds" > "$work/b.log" 2>&1 \
  || { cat "$work/b.log"; fail "the run with bed.read failed"; }
if grep -q "settling realization" "$work/b.log"; then fail "the run with bed.read settled"; fi
grep -q "bed: starting from the settled bed of realization 0, $work/beds/tiny_r0000.data (bed.read; not settled)" "$work/b.log" \
  || { cat "$work/b.log"; fail "the run with bed.read does not say where its bed came from"; }
grep -q "bed: starting from the settled bed" "$work/b_log.txt" || fail "the run's log does not say where its bed came from"
/usr/bin/python3 "$here/compare_runs.py" "$work/a.h5" "$work/b.h5" \
  && echo "PASS: the run from the kept beds equals the run that settled them" \
  || fail "the run from the kept beds differs from the run that settled them"

# 3. Refusals, exit 2, by the run and by --check.
expect_exit 2 "$work/again.log" efd 2 "$efdem" "$scene" "${common[@]}" output.prefix=c bed.write="$beds"
grep -q "key 'bed.write' = '$beds': would write over $work/beds/tiny_r0000.data, which exists" "$work/again.log" \
  || { cat "$work/again.log"; fail "bed.write onto existing beds: message"; }
[ -f "$work/beds/tiny_r0000.data" ] && [ ! -e "$work/c.h5" ] || fail "the refused run wrote something"
expect_exit 2 "$work/count.log" "$efdem" --check "$scene" "${common[@]}" output.prefix=d bed.read="$beds" "bed.count=130 126"
grep -q "key 'bed.read' = '$beds': $work/beds/tiny_r0000.data holds 128 light, 128 heavy, but bed.count = 130 126" "$work/count.log" \
  || { cat "$work/count.log"; fail "--check with a bed of other counts: message"; }
expect_exit 2 "$work/missing.log" efd 2 "$efdem" "$scene" "${common[@]}" output.prefix=e bed.read="$beds" ensemble.realizations_per_rank=2
grep -q "key 'bed.read' = '$beds': has no bed for realization 2: $work/beds/tiny_r0002.data does not exist" "$work/missing.log" \
  || { cat "$work/missing.log"; fail "a realization without its bed: message"; }
expect_exit 2 "$work/missing_check.log" "$efdem" --check "$scene" "${common[@]}" output.prefix=e bed.read="$beds" ensemble.realizations_per_rank=3
grep -q "key 'bed.read' = '$beds': has no bed for realization 2: $work/beds/tiny_r0002.data does not exist" "$work/missing_check.log" \
  || { cat "$work/missing_check.log"; fail "--check of a realization without its bed: message"; }
expect_exit 2 "$work/box.log" "$efdem" --check "$scene" "${common[@]}" output.prefix=f bed.read="$beds" domain.lx=4.5
grep -q "$work/beds/tiny_r0000.data.*domain.lx = 4.5" "$work/box.log" || { cat "$work/box.log"; fail "another box: message"; }
[ $failures -eq 0 ] && echo "PASS: bed.write onto existing beds, other counts, a missing realization, another box: exit 2"

# 4. One shared bed: without bed.read.velocity_rms its realizations are one (the same run twice);
#    with it, each its own, parting at once.
for rms in 0 0.05; do
  efd 2 "$efdem" "$scene" "${common[@]}" output.prefix=g$rms bed.read="$work/beds/tiny_r0000.data" \
    bed.read.shared=true bed.read.velocity_rms=$rms > "$work/g$rms.log" 2>&1 || { cat "$work/g$rms.log"; fail "the shared-bed run failed"; }
done
/usr/bin/python3 - "$work/g0.h5" "$work/g0.05.h5" <<'PY' || fail "the shared-bed run's realizations"
import sys, h5py, numpy as np
same = h5py.File(sys.argv[1], "r")["samples/icdf"][()]   # sample, realization, node
own = h5py.File(sys.argv[2], "r")["samples/icdf"][()]
assert np.array_equal(same[:, 0], same[:, 1]), "one shared bed without velocities: the realizations differ"
assert not np.array_equal(own[0, 0], own[0, 1]), "with bed.read.velocity_rms the realizations did not part"
print("PASS: a shared bed: one run without bed.read.velocity_rms, parted realizations with it")
PY

# 5. A restart of the run from kept beds reads no bed file.
efd 2 "$efdem" "$scene" "${common[@]}" output.prefix=h bed.read="$beds" checkpoint.interval=2 checkpoint.keep=10 \
  > "$work/h.log" 2>&1 || { cat "$work/h.log"; fail "the checkpointing run failed"; }
ckpt="$work/h_ckpt_00000002.h5"
# Continued under a fresh prefix, with a bed.read that names no file.
efd 2 "$efdem" "$scene" "${common[@]}" output.prefix=h2 bed.read="$work/nonexistent.data" restart="$ckpt" \
  > "$work/h2.log" 2>&1 || { cat "$work/h2.log"; fail "the restart without the bed files failed"; }
/usr/bin/python3 "$here/compare_runs.py" "$work/b.h5" "$work/h2.h5" \
  && echo "PASS: a restart reads no bed file and continues the run exactly" || fail "the restarted run differs"

[ $failures -eq 0 ] || { echo "$failures failure(s)"; exit 1; }
echo "bed_reuse: all passed"
