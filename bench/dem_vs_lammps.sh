#!/usr/bin/env bash
# efdem's DEM engine against LAMMPS on the reference bed (tests/data/packed_bed_12500.data.gz):
# the same model (hooke, one gamma_n = 58.5928, history, mu = 0.1, dt = 1.8e-4, skin 0.1,
# lammps_reference.md), 500 warm-up + 5000 timed steps, runs interleaved so that machine noise
# hits both codes alike. Prints particle-steps/s per run, medians and the ratio efdem/LAMMPS,
# peak memory per particle, the effect of EFDEM_NATIVE, and a 2-rank comparison (efdem: two
# independent realizations, one per rank; LAMMPS: one bed split over 2 ranks, processors 2 1 1).
#
#   bash bench/dem_vs_lammps.sh [repeats=3]
# Needs the Debian package `lammps` (EFDEM_WITH_LAMMPS=1 bash scripts/install_deps.sh).
set -euo pipefail
src=$(cd "$(dirname "$0")/.." && pwd)
repeats=${1:-3}
data=$src/tests/data/packed_bed_12500.data.gz
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1

EFDEM_WITH_LAMMPS=1 bash "$src/scripts/install_deps.sh" > /dev/null
for variant in default native; do
  dir=$src/build-bench-$variant
  flag=OFF; [ $variant = native ] && flag=ON
  cmake -S "$src" -B "$dir" -DCMAKE_BUILD_TYPE=Release -DEFDEM_BUILD_TESTS=OFF -DEFDEM_NATIVE=$flag > "$work/cmake-$variant.log"
  cmake --build "$dir" -j 2 --target efdem_dem_benchmark > "$work/build-$variant.log"
done

lammps() {  # ranks px py pz -> particle-steps/s and MiB per rank
  local np=$1 px=$2 py=$3 pz=$4 log=$work/lammps.log
  mpirun -np "$np" --oversubscribe lmp -in "$src/bench/lammps/in.packed_bed" -var data "$data" -var skin 0.1 \
    -var warmup 500 -var steps 5000 -var px "$px" -var py "$py" -var pz "$pz" -log none -echo none > "$log" 2>&1
  local loop mem
  loop=$(grep "Loop time" "$log" | tail -1 | awk '{print $4}')
  mem=$(grep "Per MPI rank memory" "$log" | tail -1 | awk '{print $(NF-1)}')
  awk -v t="$loop" -v m="$mem" 'BEGIN {printf "%.4e %.1f\n", 12500 * 5000 / t, m}'
}
efdem() {  # variant ranks -> summed particle-steps/s and peak bytes per particle
  local variant=$1 np=$2 out=$work/efdem.out
  mpirun -np "$np" --oversubscribe "$src/build-bench-$variant/bench/efdem_dem_benchmark" "$data" > "$out" 2> /dev/null
  awk '{for (i = 1; i <= NF; i++) {split($i, kv, "="); v[kv[1]] = kv[2]}; s += v["particle_steps_per_s"]; b = v["peak_rss_bytes_per_particle"]}
       END {printf "%.4e %.1f\n", s, b}' "$out"
}
median() { sort -g | awk '{a[NR] = $1} END {print (NR % 2) ? a[(NR + 1) / 2] : (a[NR / 2] + a[NR / 2 + 1]) / 2}'; }

echo "# $(date -u +%Y-%m-%dT%H:%MZ) $(lscpu | sed -n 's/^Model name: *//p') ($(nproc) cores)"
echo "# run  code            ranks  particle-steps/s  memory"
: > "$work/l1"; : > "$work/e1"; : > "$work/n1"; : > "$work/l2"; : > "$work/e2"
for r in $(seq "$repeats"); do
  read -r ps mem < <(lammps 1 1 1 1); echo "$ps" >> "$work/l1"; echo "  $r    lammps          1      $ps        $mem MiB/rank"
  read -r ps mem < <(efdem default 1); echo "$ps" >> "$work/e1"; echo "  $r    efdem           1      $ps        $mem bytes/particle"
  read -r ps mem < <(efdem native 1); echo "$ps" >> "$work/n1"; echo "  $r    efdem (native)  1      $ps        $mem bytes/particle"
  read -r ps mem < <(lammps 2 2 1 1); echo "$ps" >> "$work/l2"; echo "  $r    lammps          2      $ps        $mem MiB/rank"
  read -r ps mem < <(efdem default 2); echo "$ps" >> "$work/e2"; echo "  $r    efdem (2 real.) 2      $ps"
done
l1=$(median < "$work/l1"); e1=$(median < "$work/e1"); n1=$(median < "$work/n1")
l2=$(median < "$work/l2"); e2=$(median < "$work/e2")
awk -v l1="$l1" -v e1="$e1" -v n1="$n1" -v l2="$l2" -v e2="$e2" 'BEGIN {
  printf "medians: LAMMPS %.3e, efdem %.3e, efdem native %.3e particle-steps/s on 1 rank\n", l1, e1, n1
  printf "ratio efdem/LAMMPS, 1 rank: %.2f (native build: %.2f; EFDEM_NATIVE gains %.0f %%)\n", e1 / l1, n1 / l1, 100 * (n1 / e1 - 1)
  printf "2 ranks: LAMMPS %.3e (one bed split 2 1 1), efdem %.3e (two realizations); ratio %.2f\n", l2, e2, e2 / l2
}'
