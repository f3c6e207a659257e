#!/usr/bin/env bash
# R = 4 realizations on 1, 2 and 4 ranks (k = 4, 2, 1 per rank) must give bit-identical
# output, in cpi mode (gathers, means, projections and lifts all included).
#   layout_invariance.sh EFDEM_BINARY MPIEXEC [MPIEXEC_PREFLAGS...]
set -euo pipefail
efdem=$1; mpiexec=$2; shift 2
here=$(cd "$(dirname "$0")" && pwd)
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
for np in 1 2 4; do
  k=$((4 / np))
  "$mpiexec" -n "$np" "$@" "$efdem" "$here/tiny_scene.cfg" mode=cpi ensemble.realizations_per_rank=$k \
    output.directory="$work" output.prefix=np$np > "$work/np$np.log" 2>&1 \
    || { cat "$work/np$np.log"; exit 1; }
done
grep -q "coarse step 2" "$work/np1.log" || { echo "the run made fewer than 2 coarse steps"; cat "$work/np1.log"; exit 1; }
/usr/bin/python3 "$here/compare_runs.py" "$work/np1.h5" "$work/np2.h5"
/usr/bin/python3 "$here/compare_runs.py" "$work/np1.h5" "$work/np4.h5"
