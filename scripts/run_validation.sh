#!/usr/bin/env bash
# The validation tier: builds efdem (Release), runs the hidden [.validation] physics tests (tens
# of minutes on 2 cores) and plots their output for docs/validation.md.
#
#   bash scripts/run_validation.sh                    # build/ in the source tree
#   EFDEM_BUILD_DIR=/tmp/build bash scripts/run_validation.sh
#   EFDEM_VALIDATION_FILTER='Delta P*' bash scripts/run_validation.sh   # one test case
#
# Data go to $EFDEM_VALIDATION_OUT (default: <build>/validation_out; numbers.txt holds every
# reported number), figures to docs/validation/. Exit code: that of the test run.
set -euo pipefail
src=$(cd "$(dirname "$0")/.." && pwd)
export EFDEM_BUILD_DIR=${EFDEM_BUILD_DIR:-$src/build}
EFDEM_JOBS=${EFDEM_JOBS:-2} bash "$src/scripts/build.sh"
export EFDEM_VALIDATION_OUT=${EFDEM_VALIDATION_OUT:-$EFDEM_BUILD_DIR/validation_out}
rm -rf "$EFDEM_VALIDATION_OUT"
mkdir -p "$EFDEM_VALIDATION_OUT"
filter=${EFDEM_VALIDATION_FILTER:-[.validation]}
status=0
"$EFDEM_BUILD_DIR/tests/efdem_physics_tests" "$filter" --durations yes || status=$?
# Whole-program validation checks (ctest label validation): the recorded pressure drop.
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
(cd "$EFDEM_BUILD_DIR" && ctest --output-on-failure -V -L validation) || status=1
# Plot with Debian's matplotlib (python3-matplotlib), not whatever python3 comes first on PATH.
/usr/bin/python3 "$src/scripts/plot_validation.py" "$EFDEM_VALIDATION_OUT" "$src/docs/validation"
echo "run_validation: numbers in $EFDEM_VALIDATION_OUT/numbers.txt, figures in docs/validation/"
exit $status
