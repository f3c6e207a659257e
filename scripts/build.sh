#!/usr/bin/env bash
# Configures and builds efdem in a build directory (default: build/ in the source tree).
#
#   bash scripts/build.sh                          # Release build with tests, -Werror
#   EFDEM_BUILD_DIR=build-asan EFDEM_CMAKE_ARGS="-DEFDEM_SANITIZE=ON" bash scripts/build.sh
set -euo pipefail
src=$(cd "$(dirname "$0")/.." && pwd)
build=${EFDEM_BUILD_DIR:-$src/build}
jobs=${EFDEM_JOBS:-$(nproc)}
# shellcheck disable=SC2086
cmake -S "$src" -B "$build" -DCMAKE_BUILD_TYPE="${EFDEM_BUILD_TYPE:-Release}" \
      -DEFDEM_WERROR=ON -DEFDEM_BUILD_TESTS=ON \
      "-DMPIEXEC_PREFLAGS=--oversubscribe" ${EFDEM_CMAKE_ARGS:-} > "$build.configure.log" 2>&1 \
  || { cat "$build.configure.log"; exit 1; }
cmake --build "$build" -j "$jobs"
