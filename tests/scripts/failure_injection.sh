#!/usr/bin/env bash
# A failure on one rank ends the whole job promptly with the rank and realization named and
# exit code 3; no rank hangs in a collective. Realization 1 (on rank 1 of 2) fails at t = 0.5.
# `timeout` is the hang detector (not a speed requirement): a hang would hit it, a prompt abort
# takes seconds.
#   failure_injection.sh EFDEM_BINARY MPIEXEC [MPIEXEC_PREFLAGS...]
set -uo pipefail
efdem=$1; mpiexec=$2; shift 2
here=$(cd "$(dirname "$0")" && pwd)
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
start=$(date +%s)
timeout 300 "$mpiexec" -n 2 "$@" "$efdem" "$here/tiny_scene.cfg" mode=direct debug.fail_realization=1 \
  debug.fail_time=0.5 output.directory="$work" > "$work/out.log" 2>&1
code=$?
elapsed=$(( $(date +%s) - start ))
cat "$work/out.log"
echo "exit code $code after ${elapsed} s"
[ $code -ne 124 ] || { echo "FAIL: the job hung (killed by the timeout)"; exit 1; }
[ $code -eq 3 ] || { echo "FAIL: expected exit code 3 (runtime failure), got $code"; exit 1; }
grep -q "\[rank 1 of 2\] error: realization 1: injected failure" "$work/out.log" \
  || { echo "FAIL: the message does not name rank 1 and realization 1"; exit 1; }
echo "PASS: the job ended with the failing rank and realization named"
