#!/usr/bin/env bash
# README.md's "Quick start" block, command by command and in order, as a user on a fresh build
# would run it: the block is read from README.md (so this test fails when the README drifts)
# and run in a scratch copy of the layout it assumes (examples/demo_small/scene.cfg copied, so
# that its output.directory = ../../runs/demo_small lands in the scratch folder; scripts/ and
# build/mpi_driver/efdem linked to this source tree and this build).
#
# What differs from a user's run, and only that:
# * the install-and-build line is not run (ctest runs on a build made already); the test checks
#   that the two scripts it names exist;
# * every `mpirun` line gets overrides appended that make it short (a smaller bed and run, short
#   cpi bursts): the README's durations take minutes.
# Asserted: the block has the commands the README promises (list, check, a direct and a cpi
# run, the plots, the summary); every command exits 0 (so the output guard refuses none); every
# run's file says 'completed'; the plot's PNG exists.
#   quick_start.sh EFDEM_BINARY MPIEXEC [MPIEXEC_PREFLAGS...]
source "$(dirname "$0")/lib.sh" "$@"
src=$(cd "$here/../.." && pwd)
short=("bed.count=100 100" run.duration=8 cpi.warmup=1 cpi.healing=1 cpi.window=4)

block=$(awk '/^## Quick start/ {s = 1; next} s && /^```/ {if (inside) exit; inside = 1; next} inside' "$src/README.md")
[ -n "$block" ] || { echo "FAIL: no code block under '## Quick start' in README.md"; exit 1; }

mkdir -p "$work/examples/demo_small" "$work/build/mpi_driver"
cp "$src/examples/demo_small/scene.cfg" "$work/examples/demo_small/"
ln -s "$src/scripts" "$work/scripts"
ln -s "$efdem" "$work/build/mpi_driver/efdem"
# The README's mpirun is the one on PATH; use the one ctest was configured with.
mpirun() { "$mpiexec" "$@"; }
export -f mpirun
export mpiexec

failures=0
fail() { echo "FAIL: $*"; failures=$((failures + 1)); }
for want in "efdem --list-effects" "efdem --check" "efdem --list-keys" "scripts/plot_bed.py" "mode=direct" "mode=cpi" "scripts/plot_icdf.py" "scripts/demo_summary.py"; do
  grep -qF -- "$want" <<< "$block" || fail "the Quick start block has no command with '$want'"
done

cd "$work" || exit 1
n=0
while IFS= read -r line; do
  command=$(sed 's/[[:space:]]\+#.*$//' <<< "$line")
  [ -n "${command// /}" ] || continue
  n=$((n + 1))
  case "$command" in
    "bash scripts/install_deps.sh && bash scripts/build.sh")
      [ -f "$src/scripts/install_deps.sh" ] && [ -f "$src/scripts/build.sh" ] \
        && echo "PASS (not run): $command" || fail "$command: a script it names is missing"
      continue ;;
    export\ *) eval "$command"; echo "PASS: $command"; continue ;;
    mpirun\ *) for o in "${short[@]}"; do command+=" '$o'"; done ;;
  esac
  # stdin from /dev/null: mpirun would read the rest of the block.
  if bash -c "$command" > "$work/command_$n.log" 2>&1 < /dev/null; then
    echo "PASS: $command"
  else
    fail "exit $? from: $command"; tail -20 "$work/command_$n.log"
  fi
done <<< "$block"

# Every run's file ended 'completed', and the plot exists.
for prefix in $(grep -o 'output\.prefix=[^ ]*' <<< "$block" | cut -d= -f2); do
  status=$(/usr/bin/python3 -c "import h5py, sys; print(h5py.File(sys.argv[1], 'r').attrs['end_status'])" \
           "runs/demo_small/$prefix.h5" 2>&1 | tail -1)
  [[ $status == completed* ]] && echo "PASS: $prefix.h5: $status" || fail "runs/demo_small/$prefix.h5: $status"
done
pngs=$(grep -o -- '-o [^ ]*\.png' <<< "$block" | cut -c4-)
[ -n "$pngs" ] || fail "the Quick start block writes no plot"
for png in $pngs; do
  [ -s "$png" ] && echo "PASS: $png written" || fail "the plot '$png' was not written"
done

[ $failures -eq 0 ] || { echo "$failures failure(s)"; exit 1; }
