#!/usr/bin/env bash
# A short CPI run of examples/demo_small (fewer particles, shorter times, no settling) writes an
# HDF5 file that check_run_file.py reads back and checks (shapes, monotone ICDFs, times; units,
# descriptions and dimension scales on every dataset; the bed quantities of observe.bed).
#   demo_small_output.sh EFDEM_BINARY MPIEXEC [MPIEXEC_PREFLAGS...]
set -euo pipefail
efdem=$1; mpiexec=$2; shift 2
here=$(cd "$(dirname "$0")" && pwd)
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
"$mpiexec" -n 2 "$@" "$efdem" "$here/../../examples/demo_small/scene.cfg" mode=cpi bed.count="200 200" \
  bed.settle=false run.duration=8 cpi.warmup=1 cpi.healing=1 cpi.window=2 cpi.dt=2 \
  observe.bed=true output.directory="$work" output.prefix=demo > "$work/log" 2>&1 || { cat "$work/log"; exit 1; }
/usr/bin/python3 "$here/check_run_file.py" "$work/demo.h5" --mode cpi --realizations 4 --min-samples 8 \
  --bed --particles 400 --area 56.25
test -s "$work/demo_mean_icdf.csv" && test -s "$work/demo_cpi_steps.csv"
