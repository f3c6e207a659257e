#!/usr/bin/env bash
# Kill test: a run that checkpoints every 4 samples (debug.checkpoint_delay holds every write
# open for a while) is killed with SIGKILL (the whole job: mpirun and its ranks) at several
# moments -- during a checkpoint write (a .tmp exists), and between checkpoints. Each time the
# newest complete checkpoint must restart, and the restarted run must equal the uninterrupted
# one bit for bit. The .tmp left behind must be refused as incomplete (exit 2).
#   restart_kill.sh EFDEM_BINARY MPIEXEC [MPIEXEC_PREFLAGS...]
set -uo pipefail
efdem=$1; mpiexec=$2; shift 2
here=$(cd "$(dirname "$0")" && pwd)
work=$(mktemp -d)
job=
# The job runs in its own session (setsid): mpirun puts each rank in a process group of its
# own, so the whole job is every process of that session, killed by id as a scheduler would.
kill_job() {
  local pids
  pids=$(ps -o pid= -s "$1" 2>/dev/null)
  [ -n "$pids" ] && kill -9 $pids 2>/dev/null
  for _ in $(seq 200); do [ -z "$(ps -o pid= -s "$1" 2>/dev/null)" ] && return 0; sleep 0.05; done
}
trap '[ -n "$job" ] && kill_job "$job"; rm -rf "$work"' EXIT
scene="$here/tiny_scene.cfg"
common=(mode=direct ensemble.realizations_per_rank=2)

"$mpiexec" -n 2 "$@" "$efdem" "$scene" "${common[@]}" output.directory="$work/ref" output.prefix=run \
  > "$work/ref.log" 2>&1 || { cat "$work/ref.log"; echo "FAIL: reference run"; exit 1; }

wait_for() {  # wait_for GLOB SECONDS: until a file matching GLOB exists
  local deadline=$((SECONDS + $2))
  while [ $SECONDS -lt $deadline ]; do
    compgen -G "$1" > /dev/null && return 0
    sleep 0.05
  done
  return 1
}

failures=0
# case: what to wait for before the kill, extra seconds to wait after it
for spec in "during-2nd-write|run_ckpt_00000008.h5.tmp|0" \
            "between-checkpoints|run_ckpt_00000008.h5|0.4" \
            "during-4th-write|run_ckpt_00000016.h5.tmp|0.2"; do
  IFS='|' read -r name glob extra <<< "$spec"
  dir="$work/$name"
  mkdir -p "$dir"
  setsid "$mpiexec" -n 2 "$@" "$efdem" "$scene" "${common[@]}" output.directory="$dir" output.prefix=run \
    checkpoint.interval=4 checkpoint.keep=2 debug.checkpoint_delay=1 > "$dir/killed.log" 2>&1 &
  job=$!
  if ! wait_for "$dir/$glob" 120; then
    echo "FAIL: $name: $glob never appeared"; cat "$dir/killed.log"; failures=$((failures + 1)); continue
  fi
  sleep "$extra"
  kill_job "$job"
  wait "$job" 2>/dev/null
  job=
  newest=$(ls "$dir" | grep -E '^run_ckpt_[0-9]{8}\.h5$' | sort | tail -1)
  echo "$name: killed; left $(ls "$dir" | grep ckpt | tr '\n' ' '); restarting from $newest"
  [ -n "$newest" ] || { echo "FAIL: $name: no complete checkpoint left"; failures=$((failures + 1)); continue; }
  for tmp in "$dir"/*.tmp; do
    [ -e "$tmp" ] || continue
    "$mpiexec" -n 2 "$@" "$efdem" "$scene" "${common[@]}" output.directory="$dir/x" restart="$tmp" > "$dir/tmp.log" 2>&1
    code=$?
    if [ $code -eq 2 ] && grep -q "incomplete" "$dir/tmp.log"; then echo "PASS: $name: the .tmp is refused: $(grep -m1 incomplete "$dir/tmp.log")"
    else echo "FAIL: $name: restart from the .tmp gave exit $code"; cat "$dir/tmp.log"; failures=$((failures + 1)); fi
  done
  "$mpiexec" -n 2 "$@" "$efdem" "$scene" "${common[@]}" output.directory="$dir" output.prefix=run \
    restart="$dir/$newest" > "$dir/restart.log" 2>&1 \
    || { cat "$dir/restart.log"; echo "FAIL: $name: restart failed"; failures=$((failures + 1)); continue; }
  if /usr/bin/python3 "$here/compare_runs.py" "$work/ref/run.h5" "$dir/run.h5" \
     && cmp -s "$work/ref/run_mean_icdf.csv" "$dir/run_mean_icdf.csv"; then
    echo "PASS: $name: restarted from $newest, output equals the uninterrupted run"
  else
    echo "FAIL: $name: restarted output differs"; failures=$((failures + 1))
  fi
done
[ $failures -eq 0 ] || { echo "$failures kill case(s) failed"; exit 1; }
