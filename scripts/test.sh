#!/usr/bin/env bash
# The README's test command: sets up a fresh Debian 12 machine (apt-get, only what is missing),
# builds efdem with -Werror and runs the default test tier (ctest labels unit, physics, mpi,
# regression). Slow and validation tiers are separate: scripts/run_slow_tests.sh,
# scripts/run_validation.sh.
#
#   bash scripts/test.sh                 # default tier
#   EFDEM_SANITIZE=1 bash scripts/test.sh   # the same tier under ASan + UBSan (build-asan/)
set -euo pipefail
src=$(cd "$(dirname "$0")/.." && pwd)
bash "$src/scripts/install_deps.sh"

if [ "${EFDEM_SANITIZE:-0}" = "1" ]; then
  export EFDEM_BUILD_DIR=${EFDEM_BUILD_DIR:-$src/build-asan}
  export EFDEM_CMAKE_ARGS="${EFDEM_CMAKE_ARGS:-} -DEFDEM_SANITIZE=ON"
  # Open MPI's own allocations are reported as leaks; leaks are not what this tier checks.
  export ASAN_OPTIONS=${ASAN_OPTIONS:-detect_leaks=0}
fi
export EFDEM_BUILD_DIR=${EFDEM_BUILD_DIR:-$src/build}
bash "$src/scripts/build.sh"

# mpirun refuses to run as root unless told; CI runs as root.
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
cd "$EFDEM_BUILD_DIR"
ctest --output-on-failure -j "${EFDEM_TEST_JOBS:-2}" -L 'unit|physics|mpi|regression'
