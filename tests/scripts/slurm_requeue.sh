#!/usr/bin/env bash
# scripts/slurm_job.sh, the body of the examples' Slurm batch scripts, without Slurm: `srun` and
# `scontrol` are stand-ins on PATH (srun = mpirun -n 2, scontrol records its arguments).
# 1. The job gets SIGUSR1 as from `#SBATCH --signal=B:USR1@T`: it forwards it, efdem
#    checkpoints and exits 4, and the job asks to be requeued.
# 2. The requeued job continues from the newest checkpoint and completes; its output equals an
#    uninterrupted run's bit for bit.
# 3. A third start finds the run complete and does nothing.
#   slurm_requeue.sh EFDEM_BINARY MPIEXEC [MPIEXEC_PREFLAGS...]
source "$(dirname "$0")/lib.sh" "$@"
mkdir "$work/bin"
printf '#!/bin/bash\nexec %q -n 2 %s "$@"\n' "$mpiexec" "${launcher[*]}" > "$work/bin/srun"
printf '#!/bin/bash\necho "$@" >> %q\n' "$work/scontrol.log" > "$work/bin/scontrol"
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
  && grep -q "is complete; nothing to do" "$work/job3.log" \
  || { cat "$work/job3.log"; echo "FAIL: a complete run was started again"; exit 1; }
echo "PASS: a complete run is not started again"
