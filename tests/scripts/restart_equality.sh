#!/usr/bin/env bash
# A restarted run's output equals the uninterrupted run's bit for bit, in direct and cpi mode
# (ICDF, compact and rank observables; adaptive Adams-Bashforth 2 with a rejection before
# the checkpoint, whose controller state is in it; adaptive forward Euler from pooled slopes,
# whose slope pool, evidence-sized healing and window, trajectory budget (cpi.accuracy) and, with
# cpi.lift = own, each realization's own slope deviation and, with cpi.finish = steady, the drift
# test's pool are in it), restarted on 1, 2 and 4 ranks from a checkpoint written by 4
# realizations on 2 ranks; and a run from settled beds ("settled"), whose restart builds its beds
# without settling them (the checkpoint replaces every particle state); and a cpi run restarted
# from a checkpoint written inside its warm-up ("warmup": a job shorter than its warm-up used to
# start it again from the beginning at every requeue), also inside the drift loop of a warm-up
# until steady, whose checkpoint holds the samples its next drift test reads ("warmsteady").
# Compared: the run HDF5 file (compare_runs.py) and the CSV files (byte for byte: the wall time is in the sidecar, not compared).
# A restarted run's wall_seconds counts the run it resumed (resumed_wall_seconds, from the checkpoint).
#   restart_equality.sh EFDEM_BINARY MPIEXEC [MPIEXEC_PREFLAGS...]
set -euo pipefail
efdem=$1; mpiexec=$2; shift 2
here=$(cd "$(dirname "$0")" && pwd)
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
scene="$here/tiny_scene.cfg"

run() {  # run NP LOG ARGS...
  local np=$1 log=$2; shift 2
  timeout 300 "$mpiexec" -n "$np" "$@" > "$log" 2>&1 || { echo "FAIL: run failed ($log):"; cat "$log"; exit 1; }
}

same_output() {  # same_output PREFIX_A PREFIX_B
  /usr/bin/python3 "$here/compare_runs.py" "$work/$1.h5" "$work/$2.h5"
  for csv in _mean_icdf.csv _cpi_steps.csv; do
    [ -f "$work/$1$csv" ] || continue
    cmp -s "$work/$1$csv" "$work/$2$csv" \
      || { echo "FAIL: $2$csv differs from $1$csv"; exit 1; }
  done
}

# name, checkpoint.interval (coarse steps / samples), checkpoint to restart from, rank counts,
# scene overrides. cpi-compact: the compact fit's warm start is part of the state; ranks: the
# rank observable's reference bed (fixed at the first sample) is.
for spec in "direct 4 00000008 1,2,4 mode=direct" "cpi 1 00000001 1,2,4 mode=cpi" \
            "compact 1 00000002 4 mode=cpi,cpi.observable=compact,run.duration=8" \
            "ranks 1 00000002 2 mode=cpi,cpi.observable=ranks,cpi.lift=members,run.duration=8" \
            "adaptive 2 00000004 1,2,4 mode=cpi,cpi.projection=adaptive,cpi.integrator=adams_bashforth2,cpi.tolerance=0.06,cpi.dt_min=0.5,run.duration=24" \
            "pooled 2 00000004 2 mode=cpi,cpi.projection=adaptive,cpi.slope=pooled,cpi.pool=3,cpi.healing_auto=true,cpi.window_auto=true,cpi.lift=own,cpi.accuracy=4,cpi.finish=steady,cpi.dt_min=0.5,run.duration=24" \
            "warmup 1 00000000 1,2 mode=cpi,cpi.warmup=4,run.duration=12" \
            "warmsteady 1 00000000 1,2 mode=cpi,cpi.projection=adaptive,cpi.tolerance=0.06,cpi.dt_min=0.5,cpi.warmup=1.5,run.duration=12" \
            "settled 4 00000008 2 mode=direct,bed.settle=true,bed.settle.ke_threshold=1e-3,bed.settle.max_time=20"; do
  read -r mode every from nps overrides <<< "$spec"
  IFS=, read -r -a extra <<< "$overrides"
  common=("${extra[@]}" output.directory="$work")
  run 2 "$work/$mode-ref.log" "$@" "$efdem" "$scene" "${common[@]}" ensemble.realizations_per_rank=2 output.prefix=$mode-ref
  run 2 "$work/$mode-ck.log" "$@" "$efdem" "$scene" "${common[@]}" ensemble.realizations_per_rank=2 \
    output.prefix=$mode-ck checkpoint.interval=$every checkpoint.keep=10
  same_output $mode-ref $mode-ck   # checkpointing itself changes nothing
  if [ "$mode" = settled ] && ! grep -q "settling realization" "$work/$mode-ref.log"; then
    echo "FAIL: the settled reference run printed no settling line"; exit 1
  fi
  ckpt="$work/$mode-ck_ckpt_$from.h5"
  [ -f "$ckpt" ] || { echo "FAIL: no checkpoint $ckpt"; ls "$work"; exit 1; }
  if [ "$mode" = warmup ]; then  # written inside the warm-up (pieces of one burst, 1.5): at t = 3
    /usr/bin/python3 -c "
import h5py, sys
f = h5py.File(sys.argv[1], 'r')
assert f['/driver/warmup_done'][0] == 3.0 and f['/driver/integers'][4] == 0, 'not 3 units into the warm-up'
assert abs(f['/realizations/time'][0] - 3.0) < 1e-9" "$ckpt" || { echo "FAIL: $ckpt is not inside the warm-up"; exit 1; }
  fi
  if [ "$mode" = warmsteady ]; then  # the warm-up until steady ran on in windows of 1 to t = 7.5
    /usr/bin/python3 -c "
import h5py, sys
f = h5py.File(sys.argv[1], 'r')
assert f['/driver/warmup_done'][0] == 6.5 and f['/driver/integers'][4] == 0, 'not 6.5 units into the warm-up'
t = f['/driver/warmup_tail/t'][()]
assert abs(t[0] - 5.0) < 1e-9 and abs(t[-1] - 6.5) < 1e-9, t  # the samples of the last burst length
assert f['/driver/warmup_tail/expansion'].shape == (len(t), 4)" "$ckpt" \
      || { echo "FAIL: $ckpt is not inside the drift loop of the warm-up"; exit 1; }
  fi
  if [ "$mode" = pooled ]; then  # the budget is in the checkpoint, and jumps follow the restart
    /usr/bin/python3 -c "import h5py, sys; h5py.File(sys.argv[1], 'r')['/driver/integrator/budget/sigma']" "$ckpt" \
      || { echo "FAIL: no trajectory budget in $ckpt"; exit 1; }
    /usr/bin/python3 -c "import h5py, sys; assert len(h5py.File(sys.argv[1], 'r')['/driver/drift']) > 2" "$ckpt" \
      || { echo "FAIL: no drift test pool (cpi.finish = steady) in $ckpt"; exit 1; }
    after=$(sed -n '/checkpoint .*_ckpt_'"$from"'/,$p' "$work/$mode-ck.log" | grep -c ", projected," || true)
    [ "$after" -ge 1 ] || { echo "FAIL: no jump after the checkpoint in $mode-ck.log"; exit 1; }
  fi
  for np in ${nps//,/ }; do
    k=$((4 / np))
    run $np "$work/$mode-np$np.log" "$@" "$efdem" "$scene" "${common[@]}" ensemble.realizations_per_rank=$k \
      output.prefix=$mode-np$np restart="$ckpt"
    grep -q "restarted from" "$work/$mode-np$np.log" || { echo "FAIL: no restart in $mode-np$np.log"; exit 1; }
    # A restart takes every particle state from the checkpoint: its beds are not settled again.
    if grep -q "^efdem: settling\|settling realization" "$work/$mode-np$np.log"; then
      echo "FAIL: the restart $mode-np$np settled its beds again"; exit 1
    fi
    same_output $mode-ref $mode-np$np
    # The restarted run's loop wall time counts the process it resumed from, up to the checkpoint
    # (as its DEM time does); the uninterrupted run resumed from none.
    /usr/bin/python3 -c "
import h5py, json, math, sys
ck = float(h5py.File(sys.argv[1], 'r')['/driver/wall_seconds'][0])
a, ref = h5py.File(sys.argv[2], 'r').attrs, h5py.File(sys.argv[3], 'r').attrs
assert ref['resumed_wall_seconds'] == 0.0, ref['resumed_wall_seconds']
assert ck > 0 and a['resumed_wall_seconds'] == ck, (a['resumed_wall_seconds'], ck)
assert a['wall_seconds'] > ck, (a['wall_seconds'], ck)
meta = json.load(open(sys.argv[4]))  # the sidecar writes 10 significant digits
assert math.isclose(meta['resumed_wall_seconds'], ck, rel_tol=1e-9), meta
assert math.isclose(meta['wall_seconds'], a['wall_seconds'], rel_tol=1e-9), meta" \
      "$ckpt" "$work/$mode-np$np.h5" "$work/$mode-ref.h5" "$work/$mode-np${np}_csv_meta.json" \
      || { echo "FAIL: $mode-np$np's wall time does not count the run it resumed"; exit 1; }
    echo "PASS: $mode restarted from $(basename "$ckpt") (2 ranks x 2) on $np ranks x $k equals the uninterrupted run"
  done
done
