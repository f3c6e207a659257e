#!/usr/bin/env bash
# Output is never lost, and a run file says how its run ended (docs/reliability.md, "Output").
#  0. The run's log PREFIX_log.txt echoes the scene and holds everything the root printed.
#  1. A second run with the prefix of an earlier one is refused (exit 2, naming the file) and
#     leaves every file of the earlier run byte for byte as it was; --check refuses it too.
#  2. output.overwrite = true deletes all of the earlier run's files first: no stale VTK frame
#     of the earlier run stays beside the new run's output.
#  3. --check reports an output directory that cannot be written, a restart= file that is
#     missing, and a run file given as restart= (saying it is a run file).
#  4. end_status in the run file: "running" from the start (what a killed run leaves),
#     "completed", "interrupted: SIGTERM ..." (stop signal), "failed: realization 1 ...".
#   output_guard.sh EFDEM_BINARY MPIEXEC [MPIEXEC_PREFLAGS...]
source "$(dirname "$0")/lib.sh" "$@"
scene="$here/tiny_scene.cfg"
failures=0
fail() { echo "FAIL: $*"; failures=$((failures + 1)); }
efd() { timeout 300 "$mpiexec" -n 1 "${launcher[@]}" "$@"; }
status_of() { /usr/bin/python3 -c "import h5py, sys; print(h5py.File(sys.argv[1], 'r').attrs['end_status'])" "$1"; }

out="$work/out"
efd "$efdem" "$scene" mode=direct run.duration=2 output.vtk_interval=0.5 output.directory="$out" \
  > "$work/first.log" 2>&1 || { cat "$work/first.log"; fail "the first run failed"; }
before=$(cd "$out" && sha256sum * | sort)
[ "$(ls "$out"/*.vtp | wc -l)" -eq 5 ] || fail "expected 5 VTK frames from the first run"

# 0. The run's log, PREFIX_log.txt: the scene as read and the overrides, then every line the root
#    printed, from the header (printed before the beds were built) to the closing line.
log_ok=1
grep -q "^----- scene $scene, as read -----$" "$out/efdem_log.txt" && grep -q "^effects = gravity" "$out/efdem_log.txt" \
  && grep -q "^----- command-line overrides: mode=direct run.duration=2 .*output.directory=$out -----$" "$out/efdem_log.txt" \
  && grep -q "^efdem .*: direct run of $scene on 1 rank x 1 per rank = 1 realization" "$out/efdem_log.txt" \
  && [ "$(grep -v '^-----' "$out/efdem_log.txt" | tail -n 1)" = "$(tail -n 1 "$work/first.log")" ] || log_ok=0
[ $log_ok -eq 1 ] && echo "PASS: the run's log holds the scene, the overrides and every line it printed" \
  || { cat "$out/efdem_log.txt"; fail "the run's log efdem_log.txt"; }

#    Its name is not PREFIX.log, where these tests (and batch scripts) send the job's output.
[ -s "$work/first.log" ] && ! grep -q "^----- scene" "$work/first.log" || fail "the job's own output file"

# 1. Refused, nothing touched (the log included); --check says the same.
efd "$efdem" "$scene" mode=direct run.duration=1 seed=5 output.directory="$out" > "$work/again.log" 2>&1
code=$?
if [ $code -eq 2 ] && grep -q "key 'output.prefix': names an earlier run: $out/efdem.h5 exists" "$work/again.log" \
   && [ "$(cd "$out" && sha256sum * | sort)" = "$before" ]; then
  echo "PASS: a second run with the same prefix is refused (exit 2) and the first run's files are unchanged"
else
  cat "$work/again.log"; fail "second run with the same prefix: exit $code"
fi
efd "$efdem" --check "$scene" mode=direct output.directory="$out" > "$work/check-again.log" 2>&1
code=$?
[ $code -eq 2 ] && grep -q "names an earlier run" "$work/check-again.log" \
  && echo "PASS: --check refuses the same prefix" || { cat "$work/check-again.log"; fail "--check: exit $code"; }

# 2. overwrite = true: a run without VTK output leaves no frame of the earlier one behind.
efd "$efdem" "$scene" mode=direct run.duration=1 seed=5 output.directory="$out" output.overwrite=true \
  > "$work/overwrite.log" 2>&1
code=$?
seed=$(/usr/bin/python3 -c "import h5py; print(h5py.File('$out/efdem.h5', 'r').attrs['seed'])")
if [ $code -eq 0 ] && [ -z "$(ls "$out" | grep -E '\.(vtp|pvd)$')" ] && [ "$seed" = "5" ] \
   && grep -q "deleted the 10 file(s) of the earlier run" "$work/overwrite.log" \
   && [ "$(grep -c '^----- scene' "$out/efdem_log.txt")" -eq 1 ] && grep -q "overrides: .*seed=5" "$out/efdem_log.txt"; then
  echo "PASS: output.overwrite = true replaced the earlier run (all 10 of its files, 5 VTK frames, the CSV sidecar and the log among them, were deleted first; the log is the new run's alone)"
else
  grep -v "^t = " "$work/overwrite.log"; ls "$out"; fail "overwrite: exit $code, seed $seed"
fi

# 3. --check findings.
touch "$work/plain_file"
efd "$efdem" --check "$scene" output.directory="$work/plain_file/sub" > "$work/dir.log" 2>&1
code=$?
[ $code -eq 2 ] && grep -q "key 'output.directory' = .*cannot be written to: '$work/plain_file' exists and is not a directory" "$work/dir.log" \
  && echo "PASS: --check refuses an output directory that cannot be created" || { cat "$work/dir.log"; fail "dir: exit $code"; }
efd "$efdem" --check "$scene" mode=direct output.directory="$work/new" restart="$work/none.h5" > "$work/missing.log" 2>&1
code=$?
[ $code -eq 2 ] && grep -q "$work/none.h5: checkpoint file not found" "$work/missing.log" \
  && echo "PASS: --check refuses a missing restart= file" || { cat "$work/missing.log"; fail "missing: exit $code"; }
efd "$efdem" --check "$scene" mode=direct output.directory="$work/new" restart="$out/efdem.h5" > "$work/runfile.log" 2>&1
code=$?
[ $code -eq 2 ] && grep -q "restart= names an efdem run file (the record of a run), not a checkpoint" "$work/runfile.log" \
  && echo "PASS: --check says a run file given as restart= is a run file" || { cat "$work/runfile.log"; fail "run file: exit $code"; }
[ ! -e "$work/new" ] || fail "--check created the output directory"

# A restart writes its VTK frames and thermo logs beside the continued run's, not over them.
efd "$efdem" "$scene" mode=direct run.duration=2 output.vtk_interval=0.5 output.thermo_interval=0.5 \
  checkpoint.interval=4 checkpoint.keep=10 output.directory="$work/cont" > "$work/cont.log" 2>&1 \
  || { cat "$work/cont.log"; fail "the run to continue failed"; }
kept=$(cd "$work/cont" && sha256sum efdem_r0000* | sort)
efd "$efdem" "$scene" mode=direct run.duration=2 output.vtk_interval=0.5 output.thermo_interval=0.5 \
  output.directory="$work/cont" restart="$work/cont/efdem_ckpt_00000004.h5" > "$work/cont2.log" 2>&1
code=$?
if [ $code -eq 0 ] && [ "$(cd "$work/cont" && sha256sum efdem_r0000* | grep -v _cont | sort)" = "$kept" ] \
   && [ -f "$work/cont/efdem_r0000_cont00000004_000000.vtp" ] && [ -f "$work/cont/efdem_r0000_cont00000004_thermo.csv" ]; then
  echo "PASS: a restart's VTK frames and thermo log are new files (_cont00000004); the continued run's are unchanged"
else
  grep -v "^t = " "$work/cont2.log"; ls "$work/cont"; fail "restart output files (exit $code)"
fi

# 5. A restart writes only into the run its checkpoint came from (it used to truncate and rewrite
#    any run named by its output.prefix, exit 0). "other" is a completed run of another seed.
efd "$efdem" "$scene" mode=direct run.duration=1 seed=9 output.directory="$work/cont" output.prefix=other \
  > "$work/other.log" 2>&1 || { cat "$work/other.log"; fail "the other run failed"; }
other_before=$(cd "$work/cont" && sha256sum other* | sort)
for target in "output.prefix=other" "output.prefix=other output.directory=$work/cont/"; do
  # shellcheck disable=SC2086
  timeout 300 "$mpiexec" -n 2 "${launcher[@]}" "$efdem" "$scene" mode=direct run.duration=2 \
    output.directory="$work/cont" $target restart="$work/cont/efdem_ckpt_00000004.h5" > "$work/into_other.log" 2>&1
  code=$?
  if [ $code -eq 2 ] && grep -q "key 'output.prefix' = 'other': restart=$work/cont/efdem_ckpt_00000004.h5 would write into another run: $work/cont/other.h5 belongs to run_id [0-9a-f]\{32\}, .*, seed 9, .*; the checkpoint continues run_id [0-9a-f]\{32\}, .*seed 11" "$work/into_other.log" \
     && [ "$(cd "$work/cont" && sha256sum other* | sort)" = "$other_before" ]; then
    echo "PASS: a restart into another run ($target, 2 ranks) is refused (exit 2, naming both runs); that run's files are unchanged"
  else
    cat "$work/into_other.log"; fail "restart into another run ($target): exit $code"
  fi
done
efd "$efdem" --check "$scene" mode=direct run.duration=2 output.directory="$work/cont" output.prefix=other \
  restart="$work/cont/efdem_ckpt_00000004.h5" > "$work/check_other.log" 2>&1
code=$?
[ $code -eq 2 ] && grep -q "would write into another run" "$work/check_other.log" \
  && echo "PASS: --check refuses a restart into another run" || { cat "$work/check_other.log"; fail "--check, restart into another run: exit $code"; }
# Files of a run without its run file: whose they are cannot be told, so they are not touched.
mkdir -p "$work/orphan"; cp "$work/cont/other_mean_icdf.csv" "$work/orphan/efdem_mean_icdf.csv"
efd "$efdem" "$scene" mode=direct run.duration=2 output.directory="$work/orphan" \
  restart="$work/cont/efdem_ckpt_00000004.h5" > "$work/orphan.log" 2>&1
code=$?
[ $code -eq 2 ] && grep -q "efdem_mean_icdf.csv exists without a run file beside it" "$work/orphan.log" \
  && cmp -s "$work/orphan/efdem_mean_icdf.csv" "$work/cont/other_mean_icdf.csv" \
  && echo "PASS: a restart into files of a run without a run file is refused" || { cat "$work/orphan.log"; fail "orphan files: exit $code"; }

# A run file cut short (a job killed while writing it) beside its own checkpoint: the restart
# is this run's, and puts the run file back from the checkpoint.
efd "$efdem" "$scene" mode=direct run.duration=2 checkpoint.interval=4 output.directory="$work/cut" > "$work/cut.log" 2>&1 \
  || { cat "$work/cut.log"; fail "the run to cut failed"; }
head -c 3000 "$work/cut/efdem.h5" > "$work/cut.h5" && mv "$work/cut.h5" "$work/cut/efdem.h5"
efd "$efdem" "$scene" mode=direct run.duration=2 output.directory="$work/cut" restart="$work/cut/efdem_ckpt_00000004.h5" \
  > "$work/cut-restart.log" 2>&1
code=$?
[ $code -eq 0 ] && [ "$(status_of "$work/cut/efdem.h5")" = "completed" ] \
  && echo "PASS: a restart beside its own checkpoint goes on when the run file was cut short (the file is put back)" \
  || { cat "$work/cut-restart.log"; fail "restart over a cut run file: exit $code"; }

# 6. One run at a time under a prefix: of two restarts into one run, the second is refused (exit 2)
#    while the first runs (it used to fail with exit 3 inside HDF5), and the first is unharmed.
setsid "$mpiexec" -n 1 "${launcher[@]}" "$efdem" "$scene" mode=direct run.duration=1000 \
  output.directory="$work/cont" restart="$work/cont/efdem_ckpt_00000004.h5" > "$work/first_restart.log" 2>&1 &
job=$!
for _ in $(seq 1200); do grep -q "^t = " "$work/first_restart.log" && break; sleep 0.05; done
efd "$efdem" "$scene" mode=direct run.duration=1000 output.directory="$work/cont" \
  restart="$work/cont/efdem_ckpt_00000004.h5" > "$work/second_restart.log" 2>&1
code=$?
if [ $code -eq 2 ] && grep -q "another efdem run is writing under this prefix now (pid [0-9]* on .* holds the lock $work/cont/efdem.lock)" "$work/second_restart.log"; then
  echo "PASS: a second restart into a running run is refused (exit 2, naming the lock's holder)"
else
  cat "$work/second_restart.log"; fail "second restart: exit $code"
fi
kill -TERM $(ps -o pid=,comm= -s $job | awk '$2 == "efdem" {print $1}'); wait $job; code=$?
[ $code -eq 4 ] && [ ! -e "$work/cont/efdem.lock" ] \
  && echo "PASS: the first restart went on and stopped normally (exit 4); its lock file is gone" \
  || { grep -v "^t = " "$work/first_restart.log"; fail "the first restart: exit $code"; }

# 7. The restart command printed after a stop is quoted for a POSIX shell: pasted, it passes an
#    override with a space and $(...) exactly (efdem's own quotes kept), and runs nothing.
odd="$work/with space/\$(touch $work/pasted_ran)"
setsid "$mpiexec" -n 1 "${launcher[@]}" "$efdem" "$scene" mode=direct run.duration=1000 \
  "output.directory=\"$odd\"" > "$work/odd.log" 2>&1 &
job=$!
for _ in $(seq 1200); do grep -q "^t = " "$work/odd.log" && break; sleep 0.05; done
kill -TERM $(ps -o pid=,comm= -s $job | awk '$2 == "efdem" {print $1}'); wait $job
line=$(grep -o "continue with: .*" "$work/odd.log"); line=${line#continue with: }
args=$(mpirun() { printf '%s\n' "$@"; }; eval "$line")
if [ -n "$line" ] && grep -qxF "output.directory=\"$odd\"" <<< "$args" && [ ! -e "$work/pasted_ran" ] \
   && grep -qxF "restart=$odd/$(cd "$odd" && ls efdem_ckpt_*.h5 | tail -1)" <<< "$args"; then
  echo "PASS: the printed restart command keeps 'output.directory=\"$odd\"' one word and runs nothing"
else
  echo "line: $line"; echo "args: $args"; fail "the printed restart command"
fi

# 4. end_status marks.
[ "$(status_of "$out/efdem.h5")" = "completed" ] && echo "PASS: end_status completed" || fail "end_status of a completed run"
setsid "$mpiexec" -n 2 "${launcher[@]}" "$efdem" "$scene" mode=direct run.duration=1000 output.directory="$work/killed" > "$work/killed.log" 2>&1 &
job=$!
for _ in $(seq 600); do [ -s "$work/killed/efdem_mean_icdf.csv" ] && break; sleep 0.05; done
sleep 1; kill -9 $(ps -o pid= -s $job); wait $job 2>/dev/null
[ "$(status_of "$work/killed/efdem.h5")" = "running" ] && echo "PASS: a killed run's file says end_status running" \
  || fail "end_status of a killed run: $(status_of "$work/killed/efdem.h5")"
setsid "$mpiexec" -n 2 "${launcher[@]}" "$efdem" "$scene" mode=direct run.duration=1000 output.directory="$work/stopped" > "$work/stopped.log" 2>&1 &
job=$!
for _ in $(seq 600); do [ -s "$work/stopped/efdem_mean_icdf.csv" ] && break; sleep 0.05; done
kill -TERM $(ps -o pid=,comm= -s $job | awk '$2 == "efdem" {print $1}'); wait $job
s=$(status_of "$work/stopped/efdem.h5")
[[ $s == "interrupted: SIGTERM at t = "*"; checkpoint $work/stopped/efdem_ckpt_"* ]] \
  && echo "PASS: a stopped run's file says: $s" || fail "end_status of a stopped run: $s"
timeout 300 "$mpiexec" -n 2 "${launcher[@]}" "$efdem" "$scene" mode=direct debug.fail_realization=1 debug.fail_time=0.5 \
  output.directory="$work/failed" > "$work/failed.log" 2>&1
s=$(status_of "$work/failed/efdem.h5")
[[ $s == "failed: realization 1 at t = "*": injected failure (debug.fail_realization)" ]] \
  && echo "PASS: a failed run's file says: $s" || fail "end_status of a failed run: $s"

[ $failures -eq 0 ] || { echo "$failures failure(s)"; exit 1; }
echo "PASS: output guard and end-status marks"
