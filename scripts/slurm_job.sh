#!/usr/bin/env bash
# The body of efdem's Slurm batch scripts (examples/*/run.slurm): runs a scene with srun, and
# survives the time limit by checkpoint, signal and requeue.
#
#   bash scripts/slurm_job.sh SCENE [KEY=VALUE...]
#
# * If the run's newest checkpoint exists (and its run is not complete), continues from it
#   (restart=...); otherwise starts the run. A complete run is not run again.
# * The batch script asks Slurm for a warning signal, `#SBATCH --signal=B:USR1@600`: ten minutes
#   before the time limit Slurm sends SIGUSR1 to the batch shell, which forwards it to the job
#   step; srun delivers it to every rank; efdem stops at its next sample, writes a checkpoint and
#   exits 4. This script then requeues the job (`#SBATCH --requeue`), which continues from that
#   checkpoint when it runs again. Choose the margin (600 s) larger than one sample's DEM time
#   plus a checkpoint write on your bed (seconds for 12,500 spheres).
#   A requeued job waits in the queue as pending with `Reason=BeginTime` for about two minutes
#   (Slurm holds a requeued job for slurm.conf's AuthInfo cred_expire, default 120 s, before it
#   may start again): that is normal, not a hold to release.
# * `checkpoint.interval=N` in the arguments bounds what a node failure (no warning signal)
#   loses.
# * srun must start the ranks with the MPI plugin that efdem's MPI speaks: Debian's Open MPI
#   (and most Open MPI builds) needs PMIx, so the job asks `srun --mpi=list` and launches with
#   `srun --mpi=pmix`; where the cluster has no PMIx plugin it stops at once with a message.
#   EFDEM_SRUN_MPI=NAME chooses another plugin (e.g. pmi2 for an MPI built for it;
#   EFDEM_SRUN_MPI=default leaves srun's own default).
# * Whether a run is complete is read from its CSV sidecar (PREFIX_csv_meta.json, parsed as JSON:
#   an end status that starts with "completed", e.g. "completed (no projective jump: ...)").
# Exit code: efdem's (0 completed, 2 input error or no usable MPI plugin, 3 runtime failure,
# 4 stopped and requeued).
set -uo pipefail
here=$(cd "$(dirname "$0")" && pwd)
EFDEM=${EFDEM:-$here/../build/mpi_driver/efdem}
[ $# -ge 1 ] || { echo "usage: slurm_job.sh SCENE [KEY=VALUE...]" >&2; exit 2; }
scene=$1; shift

# Where the run writes, as efdem resolves it (--check fails fast on a bad scene, before any
# compute time is spent).
# (output.overwrite=true only here, so that --check reports the paths of an existing run too.)
report=$("$EFDEM" --check --ranks="${SLURM_NTASKS:-1}" "$scene" "$@" output.overwrite=true 2>&1) || { echo "$report" >&2; exit 2; }
run_file=$(sed -n 's/^run file: //p' <<< "$report")
checkpoints=$(sed -n 's/^checkpoints: //p' <<< "$report")
outdir=$(dirname "$run_file"); prefix=$(basename "$run_file" .h5); ckdir=$(dirname "$checkpoints")

# The run's end status from its CSV sidecar (empty: no sidecar yet, or not readable).
end_status() {
  "${PYTHON:-python3}" -c 'import json, sys; print(json.load(open(sys.argv[1]))["end_status"])' \
    "$1" 2>/dev/null
}
if [ -n "$run_file" ] && [[ $(end_status "$outdir/${prefix}_csv_meta.json") == completed* ]]; then
  echo "slurm_job: $outdir/$prefix is complete ($(end_status "$outdir/${prefix}_csv_meta.json")); nothing to do"
  exit 0
fi
restart=()
if [ -n "$run_file" ]; then
  newest=$(ls -1 "$ckdir/${prefix}"_ckpt_????????.h5 2>/dev/null | tail -n 1)
  [ -n "$newest" ] && restart=("restart=$newest") && echo "slurm_job: continuing from $newest"
fi
if [ ${#restart[@]} -eq 0 ]; then
  # A new run: refused (with the message) where an earlier run left files under this prefix.
  "$EFDEM" --check --ranks="${SLURM_NTASKS:-1}" "$scene" "$@" > /dev/null || exit $?
fi

# The MPI plugin for srun (see above).
plugin=${EFDEM_SRUN_MPI:-}
if [ -z "$plugin" ]; then
  plugins=$(srun --mpi=list 2>&1)
  if grep -qE '(^|[^[:alnum:]_])pmix' <<< "$plugins"; then
    plugin=pmix
  else
    echo "slurm_job: this cluster's srun offers no PMIx plugin (srun --mpi=list: $(tr -s '\n\t' '  ' <<< "$plugins")); efdem built with Open MPI starts its ranks only under srun --mpi=pmix (without it every rank fails in MPI_Init). Ask the administrators for Slurm's PMIx plugin, or set EFDEM_SRUN_MPI to a plugin your MPI supports (EFDEM_SRUN_MPI=default: srun's own default)." >&2
    exit 2
  fi
fi
srun_mpi=()
[ "$plugin" != default ] && srun_mpi=(--mpi="$plugin")

step=
trap 'echo "slurm_job: time limit near (SIGUSR1): asking efdem to checkpoint and stop"; [ -n "$step" ] && kill -USR1 "$step"' USR1
srun "${srun_mpi[@]}" "$EFDEM" "$scene" "$@" "${restart[@]}" &
step=$!
# `wait` returns early when the trapped signal arrives: wait until the step has really ended.
while true; do
  wait "$step"; code=$?
  kill -0 "$step" 2>/dev/null || break
done
if [ $code -eq 4 ]; then
  echo "slurm_job: efdem stopped with a checkpoint; requeueing job ${SLURM_JOB_ID:-?}"
  scontrol requeue "${SLURM_JOB_ID:-}" || echo "slurm_job: requeue failed; resubmit the job to continue"
elif [ $code -eq 0 ] && [ -n "$run_file" ] && [ -f "$run_file" ]; then
  /usr/bin/python3 "$here/plot_icdf.py" "$run_file" -o "$outdir/${prefix}_icdf.png" || true
fi
exit $code
