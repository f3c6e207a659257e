#!/usr/bin/env bash
# The clients tier: efdem's output read by what a user reads it with. VTK frames and series
# through VTK's own XML readers (python3-vtk9, what ParaView uses), the CSV files and thermo
# logs through plain pandas.read_csv (python3-pandas), every group of the run file through
# xarray with netCDF4 and h5netcdf, and docs/output.md's Python examples run on a real run's
# files. Installs those packages when they are
# missing (scripts/install_deps.sh with EFDEM_WITH_CLIENTS=1), builds like scripts/build.sh,
# then runs `ctest -L clients`.
#
#   bash scripts/run_client_tests.sh
set -euo pipefail
src=$(cd "$(dirname "$0")/.." && pwd)
EFDEM_WITH_CLIENTS=1 bash "$src/scripts/install_deps.sh"
export EFDEM_BUILD_DIR=${EFDEM_BUILD_DIR:-$src/build}
bash "$src/scripts/build.sh"
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
cd "$EFDEM_BUILD_DIR"
ctest --output-on-failure -L clients
