#!/usr/bin/env bash
# The accuracy-vs-cost study (issue 9): builds efdem and runs scripts/accuracy_cost.py.
#   bash bench/accuracy_cost.sh [--quick] [--out DIR]
# --quick: tiny bed, a handful of runs, under 15 minutes on 2 cores; default: the full study
# (about an hour on 2 cores; resumable: completed runs are not repeated). Output: runs/accuracy[_quick]/.
set -euo pipefail
src=$(cd "$(dirname "$0")/.." && pwd)
build=${EFDEM_BUILD_DIR:-$src/build}
bash "$src/scripts/install_deps.sh" > /dev/null
cmake -S "$src" -B "$build" -DCMAKE_BUILD_TYPE=Release > /dev/null
cmake --build "$build" -j 2 --target efdem > /dev/null
out=$src/runs/accuracy
for a in "$@"; do [ "$a" = "--quick" ] && out=$src/runs/accuracy_quick; done
exec /usr/bin/python3 "$src/scripts/accuracy_cost.py" --efdem "$build/mpi_driver/efdem" --out "$out" "$@"
