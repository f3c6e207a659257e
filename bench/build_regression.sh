#!/usr/bin/env bash
# Did a change (a refactoring, a new build option) slow efdem down? Runs two builds' benchmarks
# interleaved, round by round, so that both see the same machine load, and prints each round and
# the ratios of the medians (new / reference; > 1: new is faster):
#  * the DEM step throughput, efdem_dem_benchmark on the reference bed (12,500 packed spheres,
#    tests/data), 500 + 3000 steps;
#  * the root's cost per coarse step, efdem_root_cost_benchmark at R = 8 realizations of 12,500
#    particles on 4 ranks (restriction and lifting wall times, median of 5 steps).
# Wall times on a shared machine: read the ratio, not the absolute figures, and say which CPU.
#
#   bash bench/build_regression.sh REF_BUILD_DIR NEW_BUILD_DIR [ROUNDS=3]
set -euo pipefail
ref=$(realpath "$1"); new=$(realpath "$2"); rounds=${3:-3}
src=$(cd "$(dirname "$0")/.." && pwd)
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
data="$src/tests/data/packed_bed_12500.data.gz"
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
echo "# $(date -u +%Y-%m-%dT%H:%MZ) $(lscpu | sed -n 's/^Model name: *//p') ($(nproc) cores), load $(cut -d' ' -f1-3 /proc/loadavg)"
for round in $(seq "$rounds"); do
    for which in ref new; do
        build=$ref; [ $which = new ] && build=$new
        dem=$("$build/bench/efdem_dem_benchmark" "$data" steps=3000 warmup=500 \
              | sed -n 's/.*particle_steps_per_s=\([^ ]*\).*/\1/p')
        root=$(mpirun -np 4 --oversubscribe "$build/bench/efdem_root_cost_benchmark" 12500 2 5)
        echo "round $round $which dem_particle_steps_per_s=$dem $root" | tee -a "$work/rows"
    done
done
/usr/bin/python3 - "$work/rows" <<'PY'
import sys, statistics as st
rows = [dict(kv.split("=") for kv in line.split()[3:]) | {"which": line.split()[2]} for line in open(sys.argv[1])]
def med(which, key):
    return st.median(float(r[key]) for r in rows if r["which"] == which)
for key, better in (("dem_particle_steps_per_s", "higher"), ("restrict_seconds", "lower"), ("lift_seconds", "lower")):
    a, b = med("ref", key), med("new", key)
    speed = b / a if better == "higher" else a / b
    print(f"{key}: reference {a:.4g}, new {b:.4g} (medians); new is {speed:.3f} x as fast")
PY
