#!/usr/bin/env bash
# The README's main job: set up (apt-get, only what is missing), build, run a direct and a CPI
# ensemble of examples/demo_small on 2 ranks (R = 4, independent seeds), and plot both. About ten
# minutes on 2 cores.
set -euo pipefail
src=$(cd "$(dirname "$0")/.." && pwd)
bash "$src/scripts/install_deps.sh"
build=${EFDEM_BUILD_DIR:-$src/build}
cmake -S "$src" -B "$build" -DCMAKE_BUILD_TYPE=Release > "$build.configure.log" 2>&1 \
  || { cat "$build.configure.log"; exit 1; }
cmake --build "$build" -j "$(nproc)" --target efdem

export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
scene=$src/examples/demo_small/scene.cfg
out=$src/runs/demo_small
mkdir -p "$out"
# Two independent ensembles (their own seeds): a CPI run that shared the direct run's seeds would
# follow it for a while after every jump and look better than it is.
echo "== direct ensemble (2 ranks x 2 realizations, seed 1) =="
mpirun -np 2 --oversubscribe "$build/mpi_driver/efdem" "$scene" mode=direct seed=1 output.prefix=direct output.overwrite=true
echo "== adaptive coarse projective integration (2 ranks x 2 realizations, seed 2) =="
mpirun -np 2 --oversubscribe "$build/mpi_driver/efdem" "$scene" mode=cpi seed=2 output.prefix=cpi output.overwrite=true
/usr/bin/python3 "$src/scripts/plot_icdf.py" "$out/direct.h5" "$out/cpi.h5" -o "$out/icdf.png" \
  --title "demo_small: light-particle heights, direct vs adaptive CPI (R = 4, independent seeds)"
# The two compared at the same times, and the cost, each number labelled (scripts/demo_summary.py).
/usr/bin/python3 "$src/scripts/demo_summary.py" "$out/direct.h5" "$out/cpi.h5"
# What the bed does meanwhile (observe.bed in the scene): pressure drop, height, mixing index, phi(z).
/usr/bin/python3 "$src/scripts/plot_bed.py" "$out/direct.h5" "$out/cpi.h5" -o "$out/bed.png"
echo "plots: $out/icdf.png, $out/bed.png"
