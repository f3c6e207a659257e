#!/usr/bin/env bash
# The README demo's CPI run (examples/demo_small, U_s = 0.19, R = 4 on 2 ranks, 180 units) with
# each colour-lift relabelling (cpi.relabel_nodes = matched | random) and several CPI seeds,
# each against the demo's direct ensemble (seed 1): DEM-time speed-up, jumps, and the error
# against the noise floor, as scripts/demo_summary.py prints them (docs/accuracy_vs_cost.md,
# "Which particles define the nodes"). Resumable: a run whose log says it completed is skipped
# (an interrupted one is run again from the start, output.overwrite).
#
#   bash bench/demo_relabel.sh [build dir] [seed...]     (default: build, seeds 2 3 4)
#
# RULES (default "matched random") limits the rules; TAG is appended to each CPI run's name, so a
# later efdem's runs stand beside an earlier one's (TAG=_counts: after the count plan changed);
# KEYS adds scene keys to each CPI run (KEYS="cpi.relabel_velocity=species" TAG=_velocity).
set -euo pipefail
src=$(cd "$(dirname "$0")/.." && pwd)
build=${1:-$src/build}
[ $# -gt 0 ] && shift
[ $# -gt 0 ] || set -- 2 3 4
seeds=("$@")
out=$src/runs/demo_relabel
mkdir -p "$out"
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
scene=$src/examples/demo_small/scene.cfg
efdem() { mpirun -np 2 --oversubscribe "$build/mpi_driver/efdem" "$scene" output.directory="$out" \
  output.overwrite=true "$@" > /dev/null 2>&1; }
done_run() { grep -qs "^completed" "$out/$1_log.txt"; }
done_run direct || efdem mode=direct seed=1 output.prefix=direct
rules=${RULES:-matched random}
tag=${TAG:-}
for seed in "${seeds[@]}"; do
  for relabel in $rules; do
    name=cpi_${relabel}${tag}_s$seed
    # shellcheck disable=SC2086 # KEYS: words, one key=value each
    done_run "$name" || efdem mode=cpi seed="$seed" cpi.relabel_nodes=$relabel ${KEYS:-} output.prefix="$name"
  done
done
for seed in "${seeds[@]}"; do
  for relabel in $rules; do
    name=cpi_${relabel}${tag}_s$seed
    echo "== $name =="
    /usr/bin/python3 "$src/scripts/demo_summary.py" "$out/direct.h5" "$out/$name.h5" \
      | grep -E "floor of this comparison|DEM-time speed-up|jump kept|mean DT kept"
    /usr/bin/python3 -c "
import h5py, numpy as np, sys
f = h5py.File(sys.argv[1], 'r')
e = f['cpi/lift_error'][()]
print('  lift errors [d_p]:', ' '.join(f'{x:.3f}' for x in e[np.isfinite(e)]),
      '| labels changed per lift:', ' '.join(str(int(c)) for c in f['cpi/lift_changed'][()].sum(axis=1) if c))
" "$out/$name.h5"
  done
done
