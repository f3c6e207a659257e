#!/usr/bin/env bash
# The README's main job: set up (apt-get, only what is missing), build, run a direct and a CPI
# ensemble of examples/demo_small on 2 ranks (R = 4, independent seeds) over the same 180 time
# units, and plot and summarise both. The runs and plots take 8 minutes on 2 cores (README).
#
# For tests (tests/scripts/demo_commands.sh), not for users: EFDEM_DEMO_SETUP=0 skips the install
# and the build (EFDEM_BUILD_DIR names the build), EFDEM_DEMO_OUT the output folder and
# EFDEM_DEMO_OVERRIDES (key=value,key=value) shortens both runs alike.
set -euo pipefail
src=$(cd "$(dirname "$0")/.." && pwd)
build=${EFDEM_BUILD_DIR:-$src/build}
if [ "${EFDEM_DEMO_SETUP:-1}" != 0 ]; then
  bash "$src/scripts/install_deps.sh"
  cmake -S "$src" -B "$build" -DCMAKE_BUILD_TYPE=Release > "$build.configure.log" 2>&1 \
    || { cat "$build.configure.log"; exit 1; }
  cmake --build "$build" -j "$(nproc)" --target efdem
fi

export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
scene=$src/examples/demo_small/scene.cfg
out=${EFDEM_DEMO_OUT:-$src/runs/demo_small}
IFS=, read -r -a extra <<< "${EFDEM_DEMO_OVERRIDES:-}"
mkdir -p "$out"
efdem() { mpirun -np 2 --oversubscribe "$build/mpi_driver/efdem" "$scene" output.directory="$out" \
  output.overwrite=true "$@" "${extra[@]}"; }
# Two independent ensembles (their own seeds) over the same span (the scene's run.duration): a CPI
# run that shared the direct run's seeds would follow it for a while after every jump and look
# better than it is, and a cost compares only over equal spans.
echo "== direct ensemble (2 ranks x 2 realizations, seed 1) =="
efdem mode=direct seed=1 output.prefix=direct
echo "== adaptive coarse projective integration (2 ranks x 2 realizations, seed 2) =="
efdem mode=cpi seed=2 output.prefix=cpi
/usr/bin/python3 "$src/scripts/plot_icdf.py" "$out/direct.h5" "$out/cpi.h5" -o "$out/icdf.png" \
  --title "demo_small: light-particle heights, direct vs adaptive CPI (R = 4, independent seeds)"
# The two compared at the same times, the noise floor, the jumps and the cost, each number
# labelled (scripts/demo_summary.py).
/usr/bin/python3 "$src/scripts/demo_summary.py" "$out/direct.h5" "$out/cpi.h5"
# What the bed does meanwhile (observe.bed in the scene): pressure drop, height, mixing index, phi(z).
/usr/bin/python3 "$src/scripts/plot_bed.py" "$out/direct.h5" "$out/cpi.h5" -o "$out/bed.png"
echo "plots: $out/icdf.png, $out/bed.png"
