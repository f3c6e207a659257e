#!/usr/bin/env bash
# Issue 18's DEM check on the demo bed (1,000 spheres, U_s = 0.41, R = 4 on 2 ranks), most
# informative first:
#   newton.h5  mode = steady (Newton-GMRES, CRN derivatives) from a 60-unit warm-up, tau = 20,
#              difference step h = 2 d_p: what CRN leaves of the noise after tau = 20 of chaotic
#              paths is up to sqrt(2) x the noise of Phi (|SE| ~ 0.35 d_p on this bed), so J v
#              carries an error of ~0.5/h; h = 0.5 (2026-12-02, results in
#              bench/results/steady_study_2026-12-02.txt) made it as large as J_F v itself
#              (|J_F v| >= 1 - mu ~ 0.6), h = 2 makes it ~0.25 of it;
#   direct.h5  a direct ensemble with its own seeds over 300 time units, whose time average
#              after complete demixing is the reference steady ICDF;
#   branch.h5  mode = continuation in U_s from 0.6 down towards 0.2, four points 0.1 apart
#              (tau = 10, h = 2; from the vigorously fluidized end, after a warm-up of 100: a
#              Newton step costs ~1 + 3 + 1 evaluations, direct simulation gets the first guess
#              closer for less), with the leading eigenvalue at every point (recorded point by
#              point: a run cut short keeps the points it reached);
#   branch_low.h5  the continuation's low end, U_s 0.4 -> 0.2 (minimum fluidization of the mixture
#              ~0.16-0.18): four points 0.067 apart, tau = 20 (the slow mode nears mu = 1 there,
#              and F = (mu - 1)(X - X*) shrinks against the noise: a longer tau keeps 1 - mu
#              away from 0), from a warm-up of 200 at 0.4 (which overlaps branch.h5's 0.388) and
#              up to 5 Newton steps a point: a first try (2026-12-03, warm-up 100, 3 steps) ended
#              with the first point at |F| = 1.53 against a threshold of 0.63 after 440 units,
#              the line search taking 1/8, 1/2, 1/4 of noisy GMRES steps; the corrector's
#              predictor fallback (continuation.predictor_fallback) on (2026-12-03: four points
#              in 1,260 units, 25 min; every corrector started from the last point);
#   stability_020.h5  the low end's last point again, for its stability: mode = steady at U_s = 0.2
#              with R = 8 and 6 Arnoldi products (the branch's 2 products at R = 4 left the
#              leading mu at -0.58 with an upper end of 1.33), warm-up 200, tau = 20
#              (2026-12-03: Newton's line search failed at its first step; mu_1 = 0.949 +- 0.17:
#              nearly neutral, 1 - mu below the products' noise; exit 3 is the result);
#   anderson.h5  steady.solver = anderson (no derivatives: Anderson-accelerated fixed point on
#              Phi_tau, which contracts the slow mode by mu ~ 0.42 per tau = 20), at most 120 of
#              DEM time: the cheap option against which Newton is compared.
# Resumable: a run whose run file says it ended is skipped; every ended run file is also copied
# to bench/results/steady_study/ (committed), and a run whose copy is there is not made again (a
# fresh clone continues). Compare with
#   /usr/bin/python3 bench/steady_compare.py bench/results/steady_study [--run anderson]
#   /usr/bin/python3 scripts/plot_steady.py bench/results/steady_study/branch.h5 \
#       bench/results/steady_study/branch_low.h5 -o docs/steady_branch.png
#   bash bench/steady_study.sh [OUT_DIR [RUN...]]   (default runs/steady_study, every run; needs build/)
set -euo pipefail
src=$(cd "$(dirname "$0")/.." && pwd)
out=${1:-$src/runs/steady_study}
only=" ${*:2} "
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
  if [ "$only" != "  " ] && [[ "$only" != *" $name "* ]]; then return; fi
  if ended "$kept/$name.h5"; then echo "skip $name (kept in bench/results/steady_study)"; return; fi
  if ! ended "$out/$name.h5"; then
    echo "run $name: $*"
    local r=(ensemble.realizations_per_rank=2)  # R = 4 unless the run asks for more
    [[ " $* " == *" ensemble.realizations_per_rank="* ]] && r=()
    mpirun -n 2 --oversubscribe "$efdem" "$scene" output.directory="$out" output.prefix="$name" output.overwrite=true \
      "${r[@]}" "$@" > "$out/$name.log" 2>&1 || echo "$name exited $?"
  fi
  if ended "$out/$name.h5"; then cp "$out/$name.h5" "$kept/$name.h5.part" && mv "$kept/$name.h5.part" "$kept/$name.h5"; fi
}
run newton mode=steady seed=1 run.duration=0 steady.warmup=60 steady.tau=20 steady.difference_step=2 \
  steady.max_krylov=4 steady.max_iterations=6 steady.eigenvalues=2 steady.eigenvalue_products=4
run direct mode=direct seed=101 run.duration=300
run branch mode=continuation seed=7 run.duration=0 gas_drag.superficial_velocity=0.6 \
  continuation.parameter=gas_drag.superficial_velocity continuation.end=0.2 continuation.step=0.1 \
  continuation.max_points=4 steady.warmup=100 steady.tau=10 steady.difference_step=2 steady.max_krylov=3 \
  steady.max_iterations=3 steady.eigenvalues=1 steady.eigenvalue_products=2
run branch_low mode=continuation seed=17 run.duration=0 gas_drag.superficial_velocity=0.4 \
  continuation.parameter=gas_drag.superficial_velocity continuation.end=0.2 continuation.step=0.0667 \
  continuation.max_points=4 steady.warmup=200 steady.tau=20 steady.difference_step=2 steady.max_krylov=3 \
  steady.max_iterations=5 steady.eigenvalues=1 steady.eigenvalue_products=2
run stability_020 mode=steady seed=29 run.duration=0 gas_drag.superficial_velocity=0.2 ensemble.realizations_per_rank=4 \
  steady.warmup=200 steady.tau=20 steady.difference_step=2 steady.max_krylov=3 steady.max_iterations=4 \
  steady.eigenvalues=2 steady.eigenvalue_products=6
run anderson mode=steady seed=1 run.duration=120 steady.solver=anderson steady.warmup=60 steady.tau=20 \
  steady.max_iterations=8 steady.eigenvalues=0
