#!/usr/bin/env bash
# Stop signals end a run at its next safe point with a checkpoint (docs/reliability.md, "Stop
# signals"). Several trials per mode (direct, cpi with fixed DT, adaptive cpi with rejections),
# 2 ranks x 2 realizations, each stopped at a random moment (seeded: the same moments every
# time) in one of the ways a cluster stops a job:
#
#   ranks        SIGTERM to every rank (what srun/Slurm does at the time limit or scancel)
#   one-rank     SIGTERM to rank 1 only (the ensemble agrees on it at the next sample)
#   mpirun-usr1  SIGUSR1 to mpirun, which forwards it (sbatch --signal=B:USR1@T with a trap)
#   everything   SIGTERM to every rank and SIGUSR1 to mpirun at once (one request, delivered
#                twice: must not count as the "second signal" that ends at once)
#
# Each trial must end with exit code 4, the one-line "stopped by ..." message naming the
# checkpoint and the restart= command, and the restarted run's output must equal the
# uninterrupted run's bit for bit (HDF5 via compare_runs.py; CSV byte for byte; the wall time is in the sidecar).
# A second signal some seconds after the first ends the job at once (exit 128 + 15).
# The time from the signal to the end of the job is printed (docs/reliability.md has the
# figures); `timeout` is a hang detector, not a speed requirement.
#   signal_stop.sh EFDEM_BINARY MPIEXEC [MPIEXEC_PREFLAGS...]
source "$(dirname "$0")/lib.sh" "$@"
scene="$here/tiny_scene.cfg"
RANDOM=19  # the moments are random but the same in every run of the test
failures=0
fail() { echo "FAIL: $*"; failures=$((failures + 1)); }

same_output() {  # same_output PREFIX_A PREFIX_B
  /usr/bin/python3 "$here/compare_runs.py" "$work/$1.h5" "$work/$2.h5" || return 1
  for csv in _mean_icdf.csv _cpi_steps.csv; do
    [ -f "$work/$1$csv" ] || continue
    cmp -s "$work/$1$csv" "$work/$2$csv" \
      || { echo "$2$csv differs from $1$csv"; return 1; }
  done
}

# The job's processes: it runs in a session of its own (setsid); mpirun is the session leader.
ranks_of() { ps -o pid=,comm= -s "$1" | awk '$2 == "efdem" {print $1}'; }

deliver() {  # deliver HOW SESSION
  case $1 in
    ranks) kill -TERM $(ranks_of "$2") ;;
    one-rank) kill -TERM $(ranks_of "$2" | sed -n 2p) ;;
    mpirun-usr1) kill -USR1 "$2" ;;
    everything) kill -TERM $(ranks_of "$2"); kill -USR1 "$2" ;;
  esac
}

# mode, scene overrides, how the trials stop the run
for spec in "direct|mode=direct run.duration=8|ranks one-rank" \
            "cpi|mode=cpi run.duration=12|mpirun-usr1 everything" \
            "adaptive|mode=cpi cpi.projection=adaptive cpi.integrator=adams_bashforth2 cpi.tolerance=0.06 cpi.dt_min=0.5 run.duration=24|ranks one-rank"; do
  IFS='|' read -r mode overrides hows <<< "$spec"
  read -r -a extra <<< "$overrides"
  common=("${extra[@]}" output.directory="$work" ensemble.realizations_per_rank=2)
  start=$(date +%s.%N)
  timeout 300 "$mpiexec" -n 2 "${launcher[@]}" "$efdem" "$scene" "${common[@]}" output.prefix=$mode-ref > "$work/$mode-ref.log" 2>&1 \
    || { cat "$work/$mode-ref.log"; fail "$mode: the uninterrupted run failed"; continue; }
  length=$(echo "$(date +%s.%N) - $start" | bc)
  trial=0
  for how in $hows; do
    trial=$((trial + 1)); p=$mode-$trial
    # A moment between 15 % and 85 % of the uninterrupted run's wall time (MPI start-up included).
    r=$RANDOM  # (in this shell: $RANDOM inside $(...) would not advance)
    delay=$(echo "scale=2; $length * $((15 + r % 71)) / 100" | bc)
    setsid "$mpiexec" -n 2 "${launcher[@]}" "$efdem" "$scene" "${common[@]}" output.prefix=$p > "$work/$p.log" 2>&1 &
    job=$!
    sleep "$delay"
    sent=$(date +%s.%N)
    deliver "$how" "$job"
    wait $job; code=$?
    took=$(echo "$(date +%s.%N) - $sent" | bc)
    line=$(grep "^efdem: stopped by SIG[A-Z0-9]*: checkpoint .*; continue with: .* restart=" "$work/$p.log")
    echo "$mode trial $trial ($how at ${delay} s of ${length} s): exit $code, ended ${took} s after the signal"
    if [ $code -eq 0 ] && grep -q "^completed" "$work/$p.log"; then
      echo "  (the run ended before the signal arrived: nothing to test)"; continue
    fi
    [ $code -eq 4 ] || { grep -v "^t = " "$work/$p.log"; fail "$p: exit code $code, expected 4"; continue; }
    [ -n "$line" ] || { grep -v "^t = " "$work/$p.log"; fail "$p: no 'stopped by ...' line"; continue; }
    ckpt=${line##*restart=}
    [ -f "$ckpt" ] || { fail "$p: the checkpoint $ckpt named in the message is missing"; continue; }
    timeout 300 "$mpiexec" -n 2 "${launcher[@]}" "$efdem" "$scene" "${common[@]}" output.prefix=$p restart="$ckpt" \
      > "$work/$p-restart.log" 2>&1 || { cat "$work/$p-restart.log"; fail "$p: the restart failed"; continue; }
    if same_output $mode-ref $p; then
      echo "PASS: $p stopped at $(grep -o 'checkpoint [^ ]* (t = [0-9.e+-]*)' <<< "$line"), restarted, equals the uninterrupted run"
    else
      fail "$p: the restarted run differs from the uninterrupted one"
    fi
  done
done

# Ctrl-C (SIGINT) to mpirun, with Open MPI's default grace. Open MPI 4.1 answers it by waiting
# odls_base_sigkill_timeout (1 s), sending SIGTERM to the ranks, waiting the same again and
# killing them: a run that waited for the end of its sample (here about 2-5 s of wall time, 10
# time units of 256 spheres, two realizations per rank) was killed without a checkpoint. The ranks
# now look for the signal every 100 DEM steps and give the sample up: direct goes back to its
# start, cpi to its resume point. mpirun still exits 1 (it ended the job), so the run file says
# what happened; the restart must complete the run exactly as the uninterrupted one did.
if "$mpiexec" --version 2>/dev/null | grep -qE "Open MPI|OpenRTE"; then
  for spec in "direct|mode=direct run.duration=40" \
              "cpi|mode=cpi cpi.warmup=10 cpi.healing=10 cpi.window=30 cpi.dt=40 run.duration=90"; do
    IFS='|' read -r mode overrides <<< "$spec"
    read -r -a extra <<< "$overrides"
    p=ctrl-c-$mode
    ctrl=("${extra[@]}" observe.interval=10 output.directory="$work" ensemble.realizations_per_rank=2)
    timeout 300 "$mpiexec" -n 2 "${launcher[@]}" "$efdem" "$scene" "${ctrl[@]}" output.prefix=$p-ref \
      > "$work/$p-ref.log" 2>&1 || { cat "$work/$p-ref.log"; fail "$p: the uninterrupted run"; continue; }
    env -u OMPI_MCA_odls_base_sigkill_timeout setsid "$mpiexec" -n 2 "${launcher[@]}" "$efdem" "$scene" \
      "${ctrl[@]}" output.prefix=$p > "$work/$p.log" 2>&1 &
    job=$!
    # After the first sample (the first progress line), 1 s into the second.
    for _ in $(seq 1200); do grep -q "^t = " "$work/$p.log" && break; sleep 0.05; done
    sleep 1
    sent=$(date +%s.%N); kill -INT "$job"; wait "$job"; code=$?
    took=$(echo "$(date +%s.%N) - $sent" | bc)
    status=$(/usr/bin/python3 -c "import h5py, sys; print(h5py.File(sys.argv[1], 'r').attrs['end_status'])" "$work/$p.h5")
    ckpt=$(sed -n 's/^interrupted: SIGTERM at t = [0-9.]*; checkpoint \([^ ]*\) .*/\1/p' <<< "$status")
    if [[ $status == "interrupted: SIGTERM at t = "* ]] && [ -f "$ckpt" ]; then
      timeout 300 "$mpiexec" -n 2 "${launcher[@]}" "$efdem" "$scene" "${ctrl[@]}" output.prefix=$p restart="$ckpt" \
        > "$work/$p-restart.log" 2>&1 || { cat "$work/$p-restart.log"; fail "$p: the restart"; continue; }
      if same_output $p-ref $p; then
        echo "PASS: $mode: Ctrl-C to mpirun inside a sample, default grace (mpirun exit $code, ${took} s): $status; the restart equals the uninterrupted run"
      else
        fail "$p: the restart differs from the uninterrupted run"
      fi
    else
      grep -v "^t = " "$work/$p.log"; fail "$p: Ctrl-C to mpirun: exit $code, status '$status'"
    fi
  done
fi

# A stop during set-up: settling used to run to its end before the signal was looked at. Now
# every rank looks after each half time unit of settling: exit 4 at once, one line, no files.
setsid "$mpiexec" -n 2 "${launcher[@]}" "$efdem" "$scene" mode=direct run.duration=8 bed.settle=true \
  bed.settle.max_time=5000 bed.settle.ke_threshold=1e-12 output.directory="$work/settling" > "$work/settling.log" 2>&1 &
job=$!
sleep 3
sent=$(date +%s.%N); kill -TERM $(ranks_of $job); wait $job; code=$?
took=$(echo "$(date +%s.%N) - $sent" | bc)
if [ $code -eq 4 ] && grep -q "^efdem: stopped by SIGTERM during set-up, while settling realization 0 (.* stage, t = .*): the run had not started, so there is nothing to checkpoint" "$work/settling.log" \
   && [ ! -e "$work/settling/efdem.h5" ]; then
  echo "PASS: a stop while settling ended the job ${took} s after the signal (exit 4, nothing written)"
else
  cat "$work/settling.log"; fail "stop during settling: exit $code after ${took} s"
fi

# A second signal, after the first has had time to be taken as a stop request, ends at once.
setsid "$mpiexec" -n 2 "${launcher[@]}" "$efdem" "$scene" mode=direct run.duration=1000 output.directory="$work" \
  output.prefix=twice debug.checkpoint_delay=30 checkpoint.interval=1 > "$work/twice.log" 2>&1 &
job=$!
# Wait for the first checkpoint write (held open by debug.checkpoint_delay), then signal twice.
for _ in $(seq 600); do compgen -G "$work/twice_ckpt_*.tmp" > /dev/null && break; sleep 0.05; done
kill -TERM $(ranks_of $job); sleep 2.5; kill -TERM $(ranks_of $job)
wait $job; code=$?
if [ $code -ne 0 ] && [ $code -ne 4 ] && grep -q "second stop signal: ending at once" "$work/twice.log"; then
  echo "PASS: a second signal ended the job at once (exit $code)"
else
  grep -v "^t = " "$work/twice.log"; fail "second signal: exit $code"
fi

[ $failures -eq 0 ] || { echo "$failures failure(s)"; exit 1; }
echo "PASS: every stopped run checkpointed and restarted bit for bit"
