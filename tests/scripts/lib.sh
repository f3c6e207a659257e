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
# expect_exit CODE LOG COMMAND...: runs COMMAND with its output to LOG and fails the script
# (showing LOG) unless COMMAND exits with CODE.
expect_exit() {
  local code=$1 log=$2 rc=0
  shift 2
  "$@" > "$log" 2>&1 || rc=$?
  [ "$rc" = "$code" ] || { echo "${*:1:3}...: exit $rc, expected $code"; cat "$log"; exit 1; }
}
