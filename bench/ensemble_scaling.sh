#!/usr/bin/env bash
# Ensemble scaling of efdem (issue 7):
#  (a) ensemble throughput at P = 1 and 2 ranks, one realization of the paper's bed per rank
#      (the reference bed of tests/data with randomly permuted colours, U_s = 0.19), and the
#      efficiency against P = 1;
#  (b) the root's cost per coarse step (restriction + lift: gathers, averages, all R colour
#      assignments, scatter) for R = 1 ... 64 realizations of 12,500 particles (oversubscribed),
#      fitted as a + b R and extrapolated to R = 1024, against the wall time of a paper-size
#      burst (20 time units = 2e5 steps of 12,500 particles at the throughput measured in (a)).
#
#   bash bench/ensemble_scaling.sh            (about 5 minutes on 2 cores)
set -euo pipefail
src=$(cd "$(dirname "$0")/.." && pwd)
build=${EFDEM_BUILD_DIR:-$src/build}
bash "$src/scripts/install_deps.sh" > /dev/null
cmake -S "$src" -B "$build" -DCMAKE_BUILD_TYPE=Release > /dev/null
cmake --build "$build" -j 2 --target efdem efdem_root_cost_benchmark > /dev/null
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
echo "# $(date -u +%Y-%m-%dT%H:%MZ) $(lscpu | sed -n 's/^Model name: *//p') ($(nproc) cores)"
echo "## (a) ensemble throughput, one 12,500-particle realization per rank, 1e4 steps each"
for np in 1 2; do
  mpirun -np $np --oversubscribe "$build/mpi_driver/efdem" "$src/bench/scenes/reference_bed.cfg" output.directory="$work" \
    output.prefix=p$np > "$work/p$np.log" 2>&1
done
/usr/bin/python3 - "$work" <<'PY' | tee "$work/throughput"
import sys, h5py
w = sys.argv[1]
rate = {}
for np_ in (1, 2):
    f = h5py.File(f"{w}/p{np_}.h5", "r")
    rate[np_] = f.attrs["particle_steps"] / f.attrs["wall_seconds"]
    print(f"P = {np_}: {rate[np_]:.3e} particle-steps/s ({rate[np_] / np_:.3e} per rank)")
print(f"efficiency P = 2 vs 1: {rate[2] / (2 * rate[1]):.2f}")
print(f"per_core {rate[1]:.6e}")
PY
per_core=$(awk '/^per_core/ {print $2}' "$work/throughput")
echo "## (b) root cost per coarse step, N = 12,500 per realization"
: > "$work/root"
for R in 1 2 4 8 16 32 64; do
  np=$(( R < 16 ? R : 16 )); k=$(( R / np ))
  mpirun -np $np --oversubscribe "$build/bench/efdem_root_cost_benchmark" 12500 $k 5 | tee -a "$work/root"
done
/usr/bin/python3 - "$work/root" "$per_core" <<'PY'
import sys
import numpy as np
rows = [dict(kv.split("=") for kv in line.split()) for line in open(sys.argv[1])]
R = np.array([float(r["R"]) for r in rows])
cost = np.array([float(r["restrict_seconds"]) + float(r["lift_seconds"]) for r in rows])
b, a = np.polyfit(R, cost, 1)
burst = 2e5 * 12500 / float(sys.argv[2])
at = a + b * 1024
print(f"fit: root cost per coarse step = {a:.4f} s + {b * 1e3:.3f} ms x R")
print(f"R = 1024: {at:.2f} s per coarse step; a paper-size burst (20 time units) takes {burst:.0f} s "
      f"per realization at the measured per-core speed: root cost = {100 * at / burst:.2f} % of a burst (target <= 1 %)")
PY
