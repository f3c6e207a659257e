#!/usr/bin/env bash
# Issue 18's DEM check on the demo bed (1,000 spheres, U_s = 0.41, R = 4 on 2 ranks):
#   direct.h5  a direct ensemble with its own seeds over 300 time units, whose time average
#              after complete demixing is the reference steady ICDF;
#   newton.h5  mode = steady (Newton-GMRES, CRN derivatives) from a 60-unit warm-up;
#   newton_gaps.h5  the same in gap coordinates (steady.coordinates = gaps), at most 500 of DEM time;
#   anderson.h5  steady.solver = anderson (no derivatives: Anderson-accelerated fixed point on
#              Phi_tau, which contracts the slow mode by mu ~ 0.42 per tau = 20), at most 400 of
#              DEM time: the robust option against which Newton is compared;
#   newton_gaps_h1_tau10.h5  gap coordinates with a larger difference step (1 in log gap) and a
#              shorter tau (10: less divergence of the CRN paths), the next try for resolvable
#              derivatives;
#   branch.h5  mode = continuation in U_s from 0.2 to 0.6 (steps of 0.1, tau = 10), with the
#              leading eigenvalue at every point (recorded point by point: a run cut short
#              keeps the points it reached).
# Resumable: a run whose run file says it ended is skipped; every ended run file is also copied
# to bench/results/steady_study/ (committed), and a run whose copy is there is not made again (a
# fresh clone continues). Compare with
#   /usr/bin/python3 bench/steady_compare.py bench/results/steady_study [--run anderson]
#   bash bench/steady_study.sh [OUT_DIR]      (default runs/steady_study; needs build/)
set -euo pipefail
src=$(cd "$(dirname "$0")/.." && pwd)
out=${1:-$src/runs/steady_study}
efdem=${EFDEM:-$src/build/mpi_driver/efdem}
scene=$src/examples/demo_small/scene.cfg
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
mkdir -p "$out"
kept=$src/bench/results/steady_study
mkdir -p "$kept"
ended() {  # FILE: the run file exists and is not 'running'
  [ -f "$1" ] && /usr/bin/python3 -c "import h5py,sys; s=h5py.File(sys.argv[1])['/'].attrs['end_status']; sys.exit(0 if not str(s).startswith('running') else 1)" "$1"
}
run() {  # NAME overrides...
  local name=$1; shift
  if ended "$kept/$name.h5"; then echo "skip $name (kept in bench/results/steady_study)"; return; fi
  if ! ended "$out/$name.h5"; then
    echo "run $name: $*"
    mpirun -n 2 --oversubscribe "$efdem" "$scene" output.directory="$out" output.prefix="$name" output.overwrite=true \
      ensemble.realizations_per_rank=2 "$@" > "$out/$name.log" 2>&1 || echo "$name exited $?"
  fi
  if ended "$out/$name.h5"; then cp "$out/$name.h5" "$kept/$name.h5.part" && mv "$kept/$name.h5.part" "$kept/$name.h5"; fi
}
run direct mode=direct seed=101 run.duration=300
run newton mode=steady seed=1 run.duration=0 steady.warmup=60 steady.tau=20 steady.max_krylov=6 \
  steady.max_iterations=4 steady.eigenvalues=2 steady.eigenvalue_products=6
run newton_gaps mode=steady seed=1 run.duration=500 steady.coordinates=gaps steady.warmup=60 steady.tau=20 \
  steady.max_krylov=6 steady.max_iterations=3 steady.eigenvalues=2 steady.eigenvalue_products=4
run anderson mode=steady seed=1 run.duration=400 steady.solver=anderson steady.warmup=60 steady.tau=20 \
  steady.max_iterations=16 steady.eigenvalues=0
run newton_gaps_h1_tau10 mode=steady seed=1 run.duration=400 steady.coordinates=gaps steady.difference_step=1 \
  steady.warmup=60 steady.tau=10 steady.max_krylov=6 steady.max_iterations=3 steady.eigenvalues=2 \
  steady.eigenvalue_products=4
run branch mode=continuation seed=7 run.duration=0 gas_drag.superficial_velocity=0.2 \
  continuation.parameter=gas_drag.superficial_velocity continuation.end=0.6 continuation.step=0.1 \
  continuation.max_points=6 steady.warmup=40 steady.tau=10 steady.max_krylov=4 steady.max_iterations=3 \
  steady.eigenvalues=1 steady.eigenvalue_products=3
