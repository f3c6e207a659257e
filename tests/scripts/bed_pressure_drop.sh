#!/usr/bin/env bash
# Validation tier (ctest -L validation, scripts/run_validation.sh): the pressure drop efdem
# records (observe.bed) is the bed weight per area once the bed is fluidized. A light
# single-species bed (U_mf,bed = 0.1005, docs/validation.md section 1) at U_s = 0.22 and 0.30
# (2.2 and 3 U_mf), 30 time units each: the time average of /bed/ensemble_mean/pressure_drop_ratio over
# t > 10 must be within 2 % of 1. The binary demo bed at U_s = 0.41 is reported, not checked
# (heavy spheres resting on the floor carry part of the weight, so it reads a few % low).
#   bed_pressure_drop.sh EFDEM_BINARY MPIEXEC [MPIEXEC_PREFLAGS...]
source "$(dirname "$0")/lib.sh" "$@"
set -e
scene="$here/single_species_bed.cfg"
for u in 0.22 0.30; do
  "$mpiexec" -n 1 "${launcher[@]}" "$efdem" "$scene" gas_drag.superficial_velocity=$u \
    output.directory="$work" output.prefix=single_$u > "$work/log_$u" 2>&1 || { cat "$work/log_$u"; exit 1; }
done
"$mpiexec" -n 1 "${launcher[@]}" "$efdem" "$here/../../examples/demo_small/scene.cfg" mode=direct \
  bed.count="250 250" domain.lx=5 domain.ly=5 run.duration=30 ensemble.realizations_per_rank=1 \
  observe.bed=true output.directory="$work" output.prefix=binary > "$work/log_binary" 2>&1 \
  || { cat "$work/log_binary"; exit 1; }
/usr/bin/python3 - "$work" <<'PY'
import os
import sys
import h5py
import numpy as np
work, bad = sys.argv[1], []
for name, checked in (("single_0.22", True), ("single_0.30", True), ("binary", False)):
    with h5py.File(os.path.join(work, name + ".h5"), "r") as f:
        t = f["samples/time"][:]
        r = f["bed/ensemble_mean/pressure_drop_ratio"][:][t > 10]
    # Samples 0.5 apart are correlated; the standard error below is a lower bound (blocks of
    # 5 time units give about twice it), and 2 % is 10 of them.
    se = r.std(ddof=1) / np.sqrt(len(r))
    print(f"{name}: Delta P / (W/A) = {r.mean():.4f} +- {se:.4f} (t > 10, {len(r)} samples)"
          + ("" if checked else "  [reported, not checked]"))
    if checked and abs(r.mean() - 1) > 0.02:
        bad.append(name)
if bad:
    print("bed_pressure_drop: not within 2 % of W/A: " + ", ".join(bad))
    sys.exit(1)
print("bed_pressure_drop: ok")
PY
