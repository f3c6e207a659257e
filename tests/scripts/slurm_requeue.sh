#!/usr/bin/env bash
# scripts/slurm_job.sh, the body of the examples' Slurm batch scripts, without Slurm: `srun` and
# `scontrol` are stand-ins on PATH (srun = mpirun -n 2, scontrol records its arguments).
# 1. The job gets SIGUSR1 as from `#SBATCH --signal=B:USR1@T`: it forwards it, efdem
#    checkpoints and exits 4, and the job asks to be requeued.
# 2. The requeued job continues from the newest checkpoint and completes; its output equals an
#    uninterrupted run's bit for bit.
# 3. A third start finds the run complete and does nothing.
# 4. The job checks a scene for the ranks it will launch (SLURM_NTASKS), e.g. adaptive CPI.
# 5. The launcher check and --ranks.
# 6. An example's run.slurm submitted from another folder finds its example; srun gets the PMIx
#    plugin (or the job stops with a message where there is none; EFDEM_SRUN_MPI overrides); a
#    completed run whose status carries a reason is not started again; a direct job with a
#    checkpoint every sample logs no more checkpoint lines than progress lines.
#   slurm_requeue.sh EFDEM_BINARY MPIEXEC [MPIEXEC_PREFLAGS...]
source "$(dirname "$0")/lib.sh" "$@"
mkdir "$work/bin"
# srun: --mpi=list prints $SRUN_PLUGINS (default: Slurm 22.05's list with PMIx); otherwise it
# records its arguments and runs the rest (without --mpi=...) with mpirun -n 2.
cat > "$work/bin/srun" <<EOF
#!/bin/bash
if [ "\$1" = --mpi=list ]; then printf 'MPI plugin types are...\n%s\n' "\${SRUN_PLUGINS:-\$(printf '\tnone\n\tpmi2\n\tpmix\nspecific pmix plugin versions available: pmix_v3')}"; exit 0; fi
echo "\$@" >> $(printf %q "$work/srun.log")
args=("\$@"); [[ \${args[0]} == --mpi=* ]] && args=("\${args[@]:1}")
exec $(printf %q "$mpiexec") -n 2 ${launcher[*]} "\${args[@]}"
EOF
# scontrol: `show job ID` names the batch script $SUBMITTED (as Slurm's Command= does); the rest
# (requeue) is recorded.
cat > "$work/bin/scontrol" <<EOF
#!/bin/bash
if [ "\$1" = show ]; then echo "JobId=\$3 JobName=x"; echo "   Command=\${SUBMITTED:-}"; exit 0; fi
echo "\$@" >> $(printf %q "$work/scontrol.log")
EOF
chmod +x "$work/bin/srun" "$work/bin/scontrol"
export PATH="$work/bin:$PATH" EFDEM="$efdem" SLURM_JOB_ID=4242
job="$here/../../scripts/slurm_job.sh"
args=(mode=cpi run.duration=16 ensemble.realizations_per_rank=2 checkpoint.interval=100)

timeout 300 "$mpiexec" -n 2 "${launcher[@]}" "$efdem" "$here/tiny_scene.cfg" "${args[@]}" output.directory="$work/ref" \
  > "$work/ref.log" 2>&1 || { cat "$work/ref.log"; echo "FAIL: reference run"; exit 1; }

bash "$job" "$here/tiny_scene.cfg" "${args[@]}" output.directory="$work/job" > "$work/job1.log" 2>&1 &
pid=$!
for _ in $(seq 600); do grep -q "^coarse step 2:" "$work/job1.log" 2>/dev/null && break; sleep 0.05; done
kill -USR1 $pid   # what Slurm sends to the batch shell before the time limit
wait $pid; code=$?
grep -v "^t = " "$work/job1.log" | grep -v "^ \|^---\|^$\|Primary\|non-zero\|mpirun det\|the job" 
[ $code -eq 4 ] || { echo "FAIL: the stopped job exited $code, expected 4"; exit 1; }
grep -q "^requeue 4242$" "$work/scontrol.log" || { echo "FAIL: the job did not requeue itself"; exit 1; }
echo "PASS: SIGUSR1 to the job: efdem checkpointed, exit 4, the job requeued itself"

bash "$job" "$here/tiny_scene.cfg" "${args[@]}" output.directory="$work/job" > "$work/job2.log" 2>&1
code=$?
grep -q "^slurm_job: continuing from $work/job/efdem_ckpt_" "$work/job2.log" \
  || { cat "$work/job2.log"; echo "FAIL: the requeued job did not continue from the checkpoint"; exit 1; }
[ $code -eq 0 ] || { cat "$work/job2.log"; echo "FAIL: the requeued job exited $code"; exit 1; }
/usr/bin/python3 "$here/compare_runs.py" "$work/ref/efdem.h5" "$work/job/efdem.h5" \
  || { echo "FAIL: the requeued run differs from the uninterrupted one"; exit 1; }
echo "PASS: the requeued job continued from the checkpoint and equals the uninterrupted run"

bash "$job" "$here/tiny_scene.cfg" "${args[@]}" output.directory="$work/job" > "$work/job3.log" 2>&1 \
  && grep -q "is complete (completed); nothing to do" "$work/job3.log" \
  || { cat "$work/job3.log"; echo "FAIL: a complete run was started again"; exit 1; }
echo "PASS: a complete run is not started again"

# 4. A scene that needs the job's ranks (adaptive CPI, one realization per rank): the job checks it
#    serially, before srun, as for SLURM_NTASKS ranks; refused (exit 2, the key named) for one rank.
adaptive=(mode=cpi cpi.projection=adaptive cpi.tolerance=0.1 cpi.dt_min=1 cpi.dt_max=4 run.duration=12
          ensemble.realizations_per_rank=1 output.directory="$work/adaptive")
SLURM_NTASKS=2 bash "$job" "$here/tiny_scene.cfg" "${adaptive[@]}" > "$work/job4.log" 2>&1 \
  || { cat "$work/job4.log"; echo "FAIL: an adaptive scene on 2 ranks did not pass the job's check and run"; exit 1; }
grep -q "^completed" "$work/job4.log" || { cat "$work/job4.log"; echo "FAIL: the adaptive job did not complete"; exit 1; }
SLURM_NTASKS=1 bash "$job" "$here/tiny_scene.cfg" "${adaptive[@]}" output.prefix=one > "$work/job5.log" 2>&1
code=$?
[ $code -eq 2 ] && grep -q "cpi.projection" "$work/job5.log" && grep -q "this run has 1" "$work/job5.log" \
  || { cat "$work/job5.log"; echo "FAIL: an adaptive scene on 1 rank: exit $code, expected 2 naming cpi.projection"; exit 1; }
echo "PASS: the job checks the scene for the ranks it will launch (2: runs; 1: refused, exit 2)"

# 5. The launcher check: a batch shell has SLURM_NTASKS (the job's size), a serial --check there is
#    fine; a process that srun started as one of 2 (SLURM_STEP_NUM_TASKS=2) but whose MPI sees one
#    is a launcher from another MPI: refused with a message that says so.
SLURM_NTASKS=8 "$efdem" --check --ranks=8 "$here/tiny_scene.cfg" > "$work/check8.log" 2>&1 \
  || { cat "$work/check8.log"; echo "FAIL: a serial --check in a batch shell (SLURM_NTASKS=8) was refused"; exit 1; }
SLURM_STEP_NUM_TASKS=2 "$efdem" --check "$here/tiny_scene.cfg" > "$work/mismatch.log" 2>&1
code=$?
[ $code -ne 0 ] && grep -q "different MPI" "$work/mismatch.log" \
  || { cat "$work/mismatch.log"; echo "FAIL: a launcher mismatch (SLURM_STEP_NUM_TASKS=2, one MPI rank): exit $code"; exit 1; }
"$efdem" --ranks=2 "$here/tiny_scene.cfg" > "$work/ranks.log" 2>&1
code=$?
[ $code -eq 2 ] && grep -q -- "--ranks=N only goes with --check" "$work/ranks.log" \
  || { cat "$work/ranks.log"; echo "FAIL: --ranks without --check: exit $code, expected 2"; exit 1; }
echo "PASS: launcher check (SLURM_NTASKS in the batch shell is not a mismatch; an srun task's is); --ranks only with --check"

# 6. examples/paper_fig2a/run.slurm from the test's own folder (not the example's), its efdem a
#    wrapper that shrinks the bed (and writes here) and asks for a tolerance no jump can meet, so
#    that the status is "completed (no projective jump: ...)".
example="$here/../../examples/paper_fig2a"
cat > "$work/bin/efdem-small" <<EOF
#!/bin/bash
exec $(printf %q "$efdem") "\$@" "bed.count=64 64" domain.lx=4.28 domain.ly=4.28 domain.lid=60 \
  bed.settle=false run.duration=6 observe.interval=0.5 cpi.healing=1 cpi.window=1.5 cpi.dt=2 \
  cpi.projection=adaptive cpi.tolerance=1e-6 cpi.dt_min=0.5 \
  output.directory=$(printf %q "$work/fig2a")
EOF
chmod +x "$work/bin/efdem-small"
mkdir "$work/elsewhere"
submit() {  # submit LOG [VAR=VALUE...]: the batch script as Slurm would start it, from elsewhere
  local log=$1; shift
  (cd "$work/elsewhere" && env SLURM_NTASKS=2 SLURM_SUBMIT_DIR="$work/elsewhere" SUBMITTED="$(cd "$example" && pwd)/run.slurm" \
     EFDEM="$work/bin/efdem-small" "$@" bash "$example/run.slurm") > "$log" 2>&1
}
: > "$work/srun.log"
submit "$work/fig2a-1.log"; code=$?
[ $code -eq 0 ] && grep -q "^completed (no projective jump" "$work/fig2a-1.log" \
  || { cat "$work/fig2a-1.log"; echo "FAIL: run.slurm from another folder: exit $code"; exit 1; }
grep -q -- "^--mpi=pmix " "$work/srun.log" || { cat "$work/srun.log"; echo "FAIL: srun was not given --mpi=pmix"; exit 1; }
echo "PASS: run.slurm submitted from another folder ran its example, srun --mpi=pmix"
submit "$work/fig2a-2.log"; code=$?
[ $code -eq 0 ] && grep -q "is complete (completed (no projective jump" "$work/fig2a-2.log" && [ "$(wc -l < "$work/srun.log")" -eq 1 ] \
  || { cat "$work/fig2a-2.log"; echo "FAIL: a completed run with a reason in its status: exit $code, or started again"; exit 1; }
echo "PASS: a run completed with a reason in its status is not started again"
rm -rf "$work/fig2a"
submit "$work/fig2a-3.log" SRUN_PLUGINS="$(printf '\tnone\n\tpmi2\n\tcray_shasta')"; code=$?
[ $code -eq 2 ] && grep -q "srun offers no PMIx plugin (srun --mpi=list: .*pmi2.*EFDEM_SRUN_MPI" "$work/fig2a-3.log" \
  && [ "$(wc -l < "$work/srun.log")" -eq 1 ] \
  || { cat "$work/fig2a-3.log"; echo "FAIL: no PMIx plugin: exit $code, expected 2 with a message and no srun"; exit 1; }
submit "$work/fig2a-4.log" SRUN_PLUGINS="$(printf '\tnone\n\tpmi2')" EFDEM_SRUN_MPI=pmi2; code=$?
[ $code -eq 0 ] && tail -n 1 "$work/srun.log" | grep -q -- "^--mpi=pmi2 " \
  || { cat "$work/fig2a-4.log" "$work/srun.log"; echo "FAIL: EFDEM_SRUN_MPI=pmi2: exit $code"; exit 1; }
echo "PASS: without a PMIx plugin the job stops at once with a message (exit 2); EFDEM_SRUN_MPI=pmi2 chooses another"

# A direct job with a checkpoint after every sample (0.25 time units of 256 spheres): the
# checkpoints are named on the progress lines, so the log has no more of them than progress lines.
SLURM_NTASKS=2 bash "$job" "$here/tiny_scene.cfg" mode=direct run.duration=20 checkpoint.interval=1 \
  ensemble.realizations_per_rank=2 output.directory="$work/chatty" > "$work/chatty.log" 2>&1 \
  || { cat "$work/chatty.log"; echo "FAIL: the direct job"; exit 1; }
progress=$(grep -c "^t = " "$work/chatty.log"); mentions=$(grep -c "checkpoint" "$work/chatty.log")
[ "$progress" -ge 1 ] && [ "$mentions" -le "$progress" ] && ! grep -q "^checkpoint" "$work/chatty.log" \
  || { cat "$work/chatty.log"; echo "FAIL: $mentions lines name a checkpoint against $progress progress lines"; exit 1; }
echo "PASS: 80 checkpoints, $mentions log lines that name one, $progress progress lines"
