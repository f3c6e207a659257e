#!/usr/bin/env bash
# The README's main job, scripts/demo.sh, as it is (its own commands, in its order), shortened:
# no install or build (EFDEM_DEMO_SETUP=0, this build), a smaller bed and a short run for both
# ensembles alike (EFDEM_DEMO_OVERRIDES), output in a scratch folder. Asserted: the script exits 0
# (so its two runs simulate equal spans: scripts/demo_summary.py refuses unequal ones, exit 2,
# tests/scripts/plot_scripts.sh); the summary labels every number it prints: the projective
# jumps kept and rejected, the RMS difference, the noise floor of the comparison and CPI's
# multiple of it, the DEM-time speed-up and the wall-time ratio; both plots exist.
#   demo_commands.sh EFDEM_BINARY MPIEXEC [MPIEXEC_PREFLAGS...]
source "$(dirname "$0")/lib.sh" "$@"
src=$(cd "$here/../.." && pwd)
# demo.sh calls the mpirun on PATH; use the one ctest was configured with.
mpirun() { "$mpiexec" "$@"; }
export -f mpirun
export mpiexec
EFDEM_DEMO_SETUP=0 EFDEM_BUILD_DIR=$(cd "$(dirname "$efdem")/.." && pwd) EFDEM_DEMO_OUT="$work/out" \
  EFDEM_DEMO_OVERRIDES="bed.count=100 100,run.duration=8,cpi.warmup=1,cpi.healing=1,cpi.window=4" \
  timeout 600 bash "$src/scripts/demo.sh" > "$work/demo.log" 2>&1 \
  || { cat "$work/demo.log"; echo "FAIL: scripts/demo.sh (shortened) failed"; exit 1; }
failures=0
for label in "projective jump(s) kept" "rejected (a rejected jump's burst is paid for)" \
             "RMS difference of the ensemble means (CPI - direct)" "noise floor of this comparison" \
             "x the floor" "DEM-time speed-up of CPI (simulated / DEM time)" "wall-time ratio direct / CPI"; do
  grep -qF -- "$label" "$work/demo.log" && echo "PASS: the summary says '$label'" \
    || { echo "FAIL: the summary lacks '$label'"; failures=$((failures + 1)); }
done
for png in icdf.png bed.png; do
  [ -s "$work/out/$png" ] && echo "PASS: $png written" || { echo "FAIL: no $png"; failures=$((failures + 1)); }
done
[ $failures -eq 0 ] || { cat "$work/demo.log"; exit 1; }
