#!/usr/bin/env bash
# Hostile checkpoints: each bad restart ends every rank with exit code 2 and one message that
# names the file and what is wrong; none crashes or hangs (`timeout` is the hang detector).
#   hostile_checkpoints.sh EFDEM_BINARY MPIEXEC [MPIEXEC_PREFLAGS...]
set -uo pipefail
efdem=$1; mpiexec=$2; shift 2
here=$(cd "$(dirname "$0")" && pwd)
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
scene="$here/tiny_scene.cfg"
common=(mode=direct run.duration=2 output.directory="$work")
"$mpiexec" -n 2 "$@" "$efdem" "$scene" "${common[@]}" output.prefix=good checkpoint.interval=4 \
  > "$work/good.log" 2>&1 || { cat "$work/good.log"; echo "FAIL: could not write a checkpoint"; exit 1; }
good="$work/good_ckpt_00000004.h5"
[ -f "$good" ] || { ls "$work"; echo "FAIL: no checkpoint"; exit 1; }
failures=0

# expect NAME FILE PATTERN [extra arguments]: exit code 2 and PATTERN (and the file) in the output
expect() {
  local name=$1 file=$2 pattern=$3; shift 3
  timeout 120 "$mpiexec" -n 2 "${mpi_flags[@]}" "$efdem" "$scene" "${common[@]}" output.prefix=hostile \
    restart="$file" "$@" > "$work/$name.log" 2>&1
  local code=$?
  if [ $code -eq 2 ] && grep -q -- "$pattern" "$work/$name.log" && grep -qF -- "$file" "$work/$name.log" \
     && ! grep -qi "signal\|segmentation\|core dumped" "$work/$name.log"; then
    echo "PASS: $name -> exit 2: $(grep -m1 -- "$pattern" "$work/$name.log")"
  else
    echo "FAIL: $name -> exit $code, expected 2 and '$pattern':"; cat "$work/$name.log"; failures=$((failures + 1))
  fi
}
mpi_flags=("$@")

mutate() {  # mutate COPY PYTHON-CODE (h5py file `f`)
  cp "$good" "$1"
  /usr/bin/python3 -c "import h5py, numpy as np
with h5py.File('$1', 'r+') as f:
    $2"
}
poke() {  # poke COPY DATASET: overwrite 8 bytes of a contiguous dataset in place (no HDF5 API)
  cp "$good" "$1"
  /usr/bin/python3 - "$1" "$2" <<'PY'
import sys, h5py
path, name = sys.argv[1], sys.argv[2]
with h5py.File(path, "r") as f:
    offset = f[name].id.get_offset()
with open(path, "r+b") as raw:
    raw.seek(offset + 16)
    raw.write(b"\x13\x37\x13\x37\x13\x37\x13\x37")
PY
}

expect missing "$work/no_such_checkpoint.h5" "file not found"
# Not a file: each says what the path is instead of "not found" (a FIFO would block the open).
expect directory "$work" "checkpoint is a directory, not a file"
mkfifo "$work/fifo.h5"
expect fifo "$work/fifo.h5" "checkpoint is a FIFO (named pipe), not a file"
ln -s "$work/loop_b.h5" "$work/loop_a.h5"; ln -s "$work/loop_a.h5" "$work/loop_b.h5"
expect symlink_loop "$work/loop_a.h5" "checkpoint is a symbolic link that loops"
ln -s "$work/gone.h5" "$work/dangling.h5"
expect dangling "$work/dangling.h5" "is a symbolic link to '$work/gone.h5', which does not exist"
head -c 5000 "$good" > "$work/truncated.h5"
expect truncated "$work/truncated.h5" "truncated or corrupted"
echo "not an HDF5 file" > "$work/text.h5"
expect not_hdf5 "$work/text.h5" "truncated or corrupted"
poke "$work/corrupt_particles.h5" /realizations/x
expect corrupted_particles "$work/corrupt_particles.h5" "checksum of realization 0 does not match"
poke "$work/corrupt_header.h5" /output/.h5
expect corrupted_header "$work/corrupt_header.h5" "checksum of its root-level state does not match"
mutate "$work/version.h5" "f.attrs['format_version'] = np.int64(99)"
expect wrong_version "$work/version.h5" "format version 99"
mutate "$work/incomplete.h5" "del f.attrs['complete']"
expect incomplete "$work/incomplete.h5" "incomplete"
expect wrong_scene "$good" "different physics: pair_contact.kn = 300000 (checkpoint: 2e5)" pair_contact.kn=300000
expect wrong_count "$good" "holds 2 realizations but this run has 4" ensemble.realizations_per_rank=2
expect other_bed "$good" "checkpoint does not fit the scene: realization 0: the checkpoint has 256 particles, the scene builds 200" \
  "bed.count=100 100" restart.allow_physics_change=true
# The run file's grid never changes on a restart, not even with allow_physics_change (its rows
# so far were sampled on it: another interval ended "incomplete", other quantiles in exit 3).
expect other_interval "$good" "observe.interval = 0.5 (checkpoint: 0.25)" observe.interval=0.5 \
  restart.allow_physics_change=true
expect other_quantiles "$good" "observe.quantiles = 9 (checkpoint: 19)" observe.quantiles=9 \
  restart.allow_physics_change=true
# A run.duration that ends at or before the checkpoint (t = 1) has nothing to run; it used to end
# with exit 0, status "incomplete", and the run's files set back to the checkpoint.
expect too_short "$good" "run.duration = 1, but the run had already simulated 1 time units" run.duration=1
timeout 120 "$mpiexec" -n 2 "$@" "$efdem" --check "$scene" "${common[@]}" output.prefix=hostile \
  restart="$good" run.duration=0.5 > "$work/check_short.log" 2>&1
code=$?
[ $code -eq 2 ] && grep -q "run.duration = 0.5, but the run had already simulated" "$work/check_short.log" \
  && echo "PASS: --check refuses a run.duration that ends before the checkpoint" \
  || { cat "$work/check_short.log"; echo "FAIL: --check, short duration: exit $code"; failures=$((failures + 1)); }

# The same physics change is accepted when asked for.
timeout 120 "$mpiexec" -n 2 "$@" "$efdem" "$scene" "${common[@]}" output.prefix=allowed restart="$good" \
  pair_contact.kn=300000 restart.allow_physics_change=true > "$work/allowed.log" 2>&1 \
  && grep -q "changed physics" "$work/allowed.log" \
  && echo "PASS: restart.allow_physics_change=true accepts the change with a warning" \
  || { cat "$work/allowed.log"; echo "FAIL: allowed physics change"; failures=$((failures + 1)); }

[ $failures -eq 0 ] || { echo "$failures hostile-checkpoint case(s) failed"; exit 1; }
