#!/usr/bin/env bash
# Installs efdem's build and run dependencies from Debian 12 packages, only those missing.
# Idempotent: when everything is present it only runs dpkg-query (well under a second).
#
#   bash scripts/install_deps.sh            # build + test + plotting dependencies
#   EFDEM_WITH_LAMMPS=1 bash scripts/install_deps.sh   # also the LAMMPS peer for bench/
#   EFDEM_WITH_CLIENTS=1 bash scripts/install_deps.sh  # also VTK, pandas, xarray (netCDF4, h5netcdf) for the clients tier
set -euo pipefail

packages=(
  build-essential cmake clang-format
  libopenmpi-dev openmpi-bin
  libeigen3-dev
  libhdf5-openmpi-dev zlib1g-dev
  libfmt-dev
  catch2
  python3-matplotlib python3-h5py python3-numpy python3-scipy
)
if [ "${EFDEM_WITH_LAMMPS:-0}" = "1" ]; then
  packages+=(lammps)
fi
if [ "${EFDEM_WITH_CLIENTS:-0}" = "1" ]; then
  packages+=(python3-vtk9 python3-pandas python3-xarray python3-netcdf4 python3-h5netcdf)
fi

missing=()
for p in "${packages[@]}"; do
  status=$(dpkg-query -W -f='${db:Status-Status}' "$p" 2>/dev/null || true)
  [ "$status" = "installed" ] || missing+=("$p")
done

if [ ${#missing[@]} -eq 0 ]; then
  echo "install_deps: all ${#packages[@]} packages present"
  exit 0
fi

echo "install_deps: installing ${missing[*]}"
if [ "$(id -u)" -eq 0 ]; then
  SUDO=()
elif command -v sudo > /dev/null; then
  SUDO=(sudo)
else
  echo "install_deps: missing packages (${missing[*]}) and not root; install them with apt-get" >&2
  exit 1
fi
export DEBIAN_FRONTEND=noninteractive
"${SUDO[@]}" apt-get update -qq
"${SUDO[@]}" apt-get install -y -qq --no-install-recommends "${missing[@]}"
