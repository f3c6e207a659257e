#!/usr/bin/env bash
# Behaviour unchanged across a refactoring: runs the demo scene (examples/demo_small) three
# ways -- direct, cpi with a fixed DT, adaptive cpi -- with a reference efdem and a new one, and
# compares each pair of run files bit for bit (tests/scripts/compare_runs.py: every dataset
# under /samples, /cpi, /bed, the p-grid, the scene; not the wall times, date, git hash) and
# their CSV files byte for byte. Resumable: a run whose .h5 is there is not run again.
#
#   bash scripts/compare_binaries.sh REF_EFDEM NEW_EFDEM [WORKDIR]     exit 0 if all identical
#
# e.g. build the reference in a worktree of the commit before the change:
#   git worktree add ../ref <commit> && (cd ../ref && EFDEM_BUILD_DIR=$PWD/build bash scripts/build.sh)
#   bash scripts/compare_binaries.sh ../ref/build/mpi_driver/efdem build/mpi_driver/efdem
set -euo pipefail
ref=$(realpath "$1"); new=$(realpath "$2")
src=$(cd "$(dirname "$0")/.." && pwd)
work=$(realpath -m "${3:-$src/runs/compare_binaries}")
mkdir -p "$work"
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
scene="$src/examples/demo_small/scene.cfg"
# The demo scene is adaptive; its fixed-DT twin drops the adaptive-only key (the rest as is).
sed -e '/^cpi.tolerance/d' -e 's/^cpi.projection.*/cpi.projection = fixed/' "$scene" > "$work/demo_fixed.cfg"
# name and overrides: shortened from the demo's 100 time units to keep the six runs to minutes;
# each still exercises its path (direct samples and bed records; fixed jumps with lifts;
# adaptive jumps with the controller's records).
runs=("direct mode=direct run.duration=30"
      "fixed mode=cpi cpi.dt=10 run.duration=60"
      "adaptive mode=cpi run.duration=60")
status=0
for spec in "${runs[@]}"; do
    read -r name overrides <<< "$spec"
    for which in ref new; do
        bin=$ref; [ $which = new ] && bin=$new
        sc=$scene; [ $name = fixed ] && sc=$work/demo_fixed.cfg
        [ -f "$work/$which/$name.h5" ] && continue
        mkdir -p "$work/$which"
        # shellcheck disable=SC2086
        mpirun -np 2 --oversubscribe "$bin" "$sc" $overrides output.directory="$work/$which" \
            output.prefix=$name output.overwrite=true > "$work/$which/$name.log" 2>&1 \
            || { echo "FAIL: $which $name (log: $work/$which/$name.log)"; rm -f "$work/$which/$name.h5"; exit 1; }
    done
    /usr/bin/python3 "$src/tests/scripts/compare_runs.py" "$work/ref/$name.h5" "$work/new/$name.h5" || status=1
    for csv in "$work"/ref/"$name"_*.csv; do
        [ -f "$csv" ] || continue
        other="$work/new/$(basename "$csv")"
        if cmp -s "$csv" "$other"; then echo "  $(basename "$csv"): identical"
        else echo "  $(basename "$csv"): DIFFERS"; status=1; fi
    done
done
exit $status
