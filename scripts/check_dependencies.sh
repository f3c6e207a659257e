#!/usr/bin/env bash
# Checks the dependency rule of ARCHITECTURE.md on the #include lines of the sources:
#
#   core                 -> (nothing of efdem; no MPI, no HDF5)
#   dem                  -> core                    (no MPI)
#   coarse (generic)     -> core                    (no DEM, no MPI)
#   coarse/dem_adapters  -> coarse, dem, core       (no MPI)
#   mpi_driver           -> everything
#
# The CMake targets enforce the same rule at link time (target_link_libraries); this script
# catches an #include that slips through a transitive include path.
#
# Usage: check_dependencies.sh SOURCE_DIR     exit 0 if the rule holds, 1 with the violations
#        check_dependencies.sh --self-test    plants violations in a scratch tree; must catch each
set -euo pipefail

check_tree() {
    local root=$1 status=0
    # forbid FOLDER PATTERN DESCRIPTION [EXCLUDE_SUBDIR]
    forbid() {
        local folder=$1 pattern=$2 what=$3 exclude=${4:-}
        [ -d "$root/$folder" ] || return 0
        local hits
        hits=$(grep -rnE --include='*.hpp' --include='*.cpp' --include='*.h' \
                 "^[[:space:]]*#[[:space:]]*include[[:space:]]*[<\"]($pattern)" "$root/$folder" \
                 | { if [ -n "$exclude" ]; then grep -v "^$root/$folder/$exclude/" || true; else cat; fi; } \
                 || true)
        if [ -n "$hits" ]; then
            echo "dependency rule violated: $folder must not include $what:"
            echo "$hits" | sed "s|^$root/|  |"
            status=1
        fi
    }
    forbid core 'dem/|coarse/|mpi_driver/|mpi\.h|hdf5\.h' "dem/, coarse/, mpi_driver/, MPI or HDF5"
    forbid dem 'coarse/|mpi_driver/|mpi\.h' "coarse/, mpi_driver/ or MPI"
    forbid coarse 'dem/|mpi_driver/|mpi\.h' "dem/, mpi_driver/ or MPI (only coarse/dem_adapters may see dem/)" dem_adapters
    forbid coarse/dem_adapters 'mpi_driver/|mpi\.h' "mpi_driver/ or MPI"
    return $status
}

if [ "${1:-}" = "--self-test" ]; then
    scratch=$(mktemp -d)
    trap 'rm -rf "$scratch"' EXIT
    mkdir -p "$scratch"/{core,dem,coarse/dem_adapters,mpi_driver}
    echo '#include "core/vec3.hpp"' > "$scratch/dem/ok.cpp"
    echo '#include "dem/particles.hpp"' > "$scratch/coarse/dem_adapters/ok.cpp"
    echo '#include <mpi.h>' > "$scratch/mpi_driver/ok.cpp"
    check_tree "$scratch" > /dev/null || { echo "self-test: a clean tree was flagged"; exit 1; }
    for bad in "dem/a.cpp:#include <mpi.h>" "dem/b.hpp:#include \"coarse/demixing/quantiles.hpp\"" \
               "coarse/c.cpp:#include \"dem/system.hpp\"" "coarse/d.hpp:  #  include <mpi.h>" \
               "core/e.cpp:#include \"dem/particles.hpp\"" "coarse/dem_adapters/f.cpp:#include <mpi.h>"; do
        file=${bad%%:*}; line=${bad#*:}
        echo "$line" > "$scratch/$file"
        if check_tree "$scratch" > /dev/null; then
            echo "self-test: violation not detected: $file: $line"; exit 1
        fi
        rm "$scratch/$file"
    done
    echo "self-test passed: every planted violation was detected"
    exit 0
fi

check_tree "${1:?usage: check_dependencies.sh SOURCE_DIR | --self-test}"
echo "dependency rule holds"
