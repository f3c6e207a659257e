# Sourced by the whole-program test scripts (first line after the usage comment):
#   source "$(dirname "$0")/lib.sh" "$@"
# The scripts are called as SCRIPT EFDEM_BINARY MPIEXEC [MPIEXEC_PREFLAGS...]; this sets
# $efdem, $mpiexec, launcher=(MPIEXEC_PREFLAGS...), $here (the scripts' folder) and $work (a
# scratch folder, removed at exit unless the script sets its own EXIT trap).
set -uo pipefail
efdem=$1
mpiexec=$2
shift 2
launcher=("$@")
here=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
