#!/usr/bin/env bash
# Numerical watchdog: an overlap beyond watchdog.max_overlap stops the whole job (exit 3, no
# hang) with the rank, realization, particle tags and time named, and says which checkpoint
# holds the last healthy state; that checkpoint restarts (watchdog.* may change on restart).
# Without checkpointing the message says there is nothing to restart from.
#   watchdog.sh EFDEM_BINARY MPIEXEC [MPIEXEC_PREFLAGS...]
set -uo pipefail
efdem=$1; mpiexec=$2; shift 2
here=$(cd "$(dirname "$0")" && pwd)
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
scene="$here/tiny_scene.cfg"
# Overlaps in the tiny bed reach ~0.001 d after about t = 1: a strict limit trips the watchdog.
strict=(mode=direct output.directory="$work" watchdog.max_overlap=0.001 watchdog.check_every=100)
failures=0

timeout 300 "$mpiexec" -n 2 "$@" "$efdem" "$scene" "${strict[@]}" checkpoint.interval=2 > "$work/ck.log" 2>&1
code=$?
cat "$work/ck.log" | grep -v "^t = "
line=$(grep -E "\[rank [01] of 2\] error: realization [01]: at t = [0-9.]+ \(step [0-9]+\): an overlap of .* particle [0-9]+ with (particle [0-9]+|a wall)" "$work/ck.log")
if [ $code -eq 3 ] && [ -n "$line" ] && grep -q "newest checkpoint, .*_ckpt_[0-9]*\.h5 (t = " <<< "$line"; then
  echo "PASS: the watchdog stopped the job (exit 3) naming rank, realization, particles, time and the last checkpoint"
else
  echo "FAIL: expected exit 3 and the watchdog message, got exit $code"; failures=$((failures + 1))
fi
ckpt=$(grep -o "[^ ]*_ckpt_[0-9]*\.h5" <<< "$line" | head -1)
if [ -n "$ckpt" ] && timeout 300 "$mpiexec" -n 2 "$@" "$efdem" "$scene" mode=direct output.directory="$work" \
     output.prefix=resumed restart="$ckpt" > "$work/resumed.log" 2>&1; then
  echo "PASS: the named checkpoint restarts with the default watchdog"
else
  echo "FAIL: restart from '$ckpt'"; cat "$work/resumed.log"; failures=$((failures + 1))
fi

timeout 300 "$mpiexec" -n 2 "$@" "$efdem" "$scene" "${strict[@]}" output.prefix=off > "$work/off.log" 2>&1
code=$?
if [ $code -eq 3 ] && grep -q "checkpointing is off" "$work/off.log"; then
  echo "PASS: without checkpoints the message says there is nothing to restart from"
else
  echo "FAIL: checkpointing off: exit $code"; cat "$work/off.log"; failures=$((failures + 1))
fi
[ $failures -eq 0 ] || exit 1
