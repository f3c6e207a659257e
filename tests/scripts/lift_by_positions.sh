#!/usr/bin/env bash
# cpi.lift_by = positions on a real DEM ensemble of a bed of two sizes (two_sizes_tiny.cfg,
# 2 realizations on 2 ranks, adaptive): the run jumps, each lift moves particles in exchanges
# and relaxes their overlaps, and the DEM goes on from it without a violent start: the largest
# overlap at the samples after each jump stays at the size of ordinary contacts. Measured
# (2026-12-05): 2e-5 .. 3.6e-4 of a diameter in the unit after a jump (the relaxation leaves
# 1e-4; ordinary contacts in the fluidized bed reach a few 1e-4); asserted
# <= 0.01, a tenth of the watchdog's limit, which a lift left unrelaxed (0.7-0.9) exceeds by far.
# Also refused with exit 2 and the key named: colour lifting of unequal sizes, positions with a
# fixed DT (a failed relaxation could not be redone), with cpi.relabel = moving or clustered and with
# cpi.relabel_velocity = species (both act on relabelled particles, which positions has none of).
#   lift_by_positions.sh EFDEM_BINARY MPIEXEC [MPIEXEC_PREFLAGS...]
source "$(dirname "$0")/lib.sh" "$@"
scene="$here/two_sizes_tiny.cfg"
timeout 300 "$mpiexec" -n 2 "${launcher[@]}" "$efdem" "$scene" mode=cpi cpi.lift_by=positions \
  cpi.projection=adaptive cpi.tolerance=1 output.thermo_interval=0.25 output.directory="$work" \
  > "$work/run.log" 2>&1 || { cat "$work/run.log"; echo "FAIL: the cpi.lift_by = positions run failed"; exit 1; }
/usr/bin/python3 "$here/check_run_file.py" "$work/efdem.h5" > /dev/null || { echo "FAIL: efdem.h5 layout"; exit 1; }
# The step report of a kept jump says how far the lift left the ensemble from X.
grep -q "projected, .* particles moved, lift error [0-9.e-]* d_p" "$work/run.log" \
  || { grep "coarse step" "$work/run.log"; echo "FAIL: no kept jump's report gives its lift error"; exit 1; }
/usr/bin/python3 - "$work" <<'PY' || exit 1
import csv
import sys
import h5py
import numpy as np
work = sys.argv[1]
with h5py.File(f"{work}/efdem.h5", "r") as f:
    status = [s.decode() for s in f["cpi/status"][:]]
    t_end, dt = f["cpi/t_end"][:], f["cpi/dt"][:]
    changed = f["cpi/lift_changed"][:]
    messages = [m.decode() for m in f["cpi/lift_message"][:]]
    lift_error = f["cpi/lift_error"][:]
    step_messages = [m.decode() for m in f["cpi/message"][:]]
jumps = [i for i, s in enumerate(status) if s == "projected" and dt[i] > 0]
if not jumps:
    sys.exit(f"FAIL: no projective jump was kept ({status})")
for i in jumps:
    if not (changed[i] > 0).all():
        sys.exit(f"FAIL: a kept jump moved no particle in some realization: {changed[i]}")
    for word in ("exchanges", "relaxation steps", "largest deviation from the target", "kinetic energy"):
        if messages[i].count(word) != changed.shape[1]:
            sys.exit(f"FAIL: the lift record does not say '{word}' for every realization: {messages[i]!r}")
    # A kept jump's lift left the ensemble mean within the tolerance (cpi.tolerance = 1) of X.
    if not 0 <= lift_error[i] <= 1.0:
        sys.exit(f"FAIL: a kept jump's lift error {lift_error[i]} is not in [0, tolerance 1]")
for i, s in enumerate(status):
    if s == "lift_failed" and "tolerance" in step_messages[i] and not lift_error[i] > 1.0:
        sys.exit(f"FAIL: a lift failed on the tolerance with lift error {lift_error[i]}")
worst = 0.0
for r in range(changed.shape[1]):
    with open(f"{work}/efdem_r{r:04d}_thermo.csv") as fh:
        rows = [(float(row["time"]), float(row["max_overlap"])) for row in csv.DictReader(fh)]
    for i in jumps:
        after = [o for t, o in rows if t_end[i] + dt[i] < t <= t_end[i] + dt[i] + 1.0 + 1e-9]
        if not after:
            sys.exit(f"FAIL: no thermo sample after the jump to t = {t_end[i] + dt[i]}")
        worst = max(worst, max(after))
if worst > 0.01:
    sys.exit(f"FAIL: largest overlap after a lift {worst:.3g} of a diameter (want <= 0.01)")
print(f"PASS: {len(jumps)} jumps lifted by positions; largest overlap in the unit after each: {worst:.2g}")
PY
refused() {  # refused NAME KEY_IN_MESSAGE OVERRIDES...
  local name=$1 key=$2
  shift 2
  set +e
  timeout 120 "$mpiexec" -n 2 "${launcher[@]}" "$efdem" "$scene" mode=cpi "$@" \
    output.directory="$work/$name" > "$work/$name.log" 2>&1
  local rc=$?
  set -e
  [ $rc -eq 2 ] && grep -q "$key" "$work/$name.log" && [ ! -e "$work/$name/efdem.h5" ] \
    || { cat "$work/$name.log"; echo "FAIL: $name: exit $rc, expected 2 naming $key"; exit 1; }
  echo "PASS: $name is refused (exit 2, $key named)"
}
refused colours_two_sizes "species.diameter" cpi.projection=adaptive cpi.tolerance=1
grep -q "cpi.lift_by = positions" "$work/colours_two_sizes.log" || { echo "FAIL: the refusal does not point to cpi.lift_by = positions"; exit 1; }
refused fixed_dt "cpi.lift_by" cpi.lift_by=positions cpi.projection=fixed cpi.dt=2
refused relabel_moving "cpi.relabel" cpi.lift_by=positions cpi.projection=adaptive cpi.tolerance=1 \
  cpi.relabel=moving
refused relabel_clustered "cpi.relabel" cpi.lift_by=positions cpi.projection=adaptive \
  cpi.tolerance=1 cpi.relabel=clustered
refused relabel_velocity "cpi.relabel_velocity" cpi.lift_by=positions cpi.projection=adaptive \
  cpi.tolerance=1 cpi.relabel_velocity=species
