#!/usr/bin/env bash
# observe.bed on a bed that demixes: a direct run of the demo bed's physics (400 spheres, mixed
# lattice start, U_s = 0.41 set here (the demo runs 0.19, which demixes too slowly for 30 time
# units), 2 realizations, 30 time units) records /bed; bed_observables.py
# checks that the Lacey index starts at a random mixture's 1 and falls as the light spheres
# rise, and the layout and volume of /bed (check_run_file.py --bed).
#   bed_observables.sh EFDEM_BINARY MPIEXEC [MPIEXEC_PREFLAGS...]
source "$(dirname "$0")/lib.sh" "$@"
set -e
"$mpiexec" -n 2 "${launcher[@]}" "$efdem" "$here/../../examples/demo_small/scene.cfg" mode=direct \
  bed.count="200 200" bed.settle=false run.duration=30 ensemble.realizations_per_rank=1 gas_drag.superficial_velocity=0.41 \
  observe.interval=1 observe.bed=true output.directory="$work" output.prefix=bed > "$work/log" 2>&1 \
  || { cat "$work/log"; exit 1; }
/usr/bin/python3 "$here/check_run_file.py" "$work/bed.h5" --mode direct --realizations 2 --min-samples 30 \
  --bed --particles 400 --area 56.25
/usr/bin/python3 - "$work/bed.h5" <<'PY'
import sys
import h5py
import numpy as np
with h5py.File(sys.argv[1], "r") as f:
    t = f["samples/time"][:]
    m = f["bed/mixing_index"][:]          # (sample, realization)
    names = [x.decode() if isinstance(x, bytes) else x for x in f["bed/species"][:]]
    zs = f["bed/species_height"][:]      # (sample, realization, species)
light, heavy = names.index("light"), names.index("heavy")
first, last = m[t <= 2].mean(axis=0), m[t >= 26].mean(axis=0)
rise = zs[t >= 26, :, light].mean(axis=0) - zs[t >= 26, :, heavy].mean(axis=0)
print(f"Lacey index t <= 2: {first}, t >= 26: {last}; light - heavy mean height at the end: {rise} d_p")
errors = []
# The lattice start assigns species at random: M = 1 up to s^2/sr^2 fluctuations divided by
# the ~70 particles per 2-d_p layer (s.d. ~0.01); 0.95 allows 5 s.d.
if not np.all(first > 0.95):
    errors.append(f"start not a random mixture: M = {first}")
# Measured on this bed: M falls to 0.66-0.70 by t = 26-30 (light spheres rise 2 d_p above the
# heavy ones); a fall of 0.15 is 15 s.d. of a mixed bed's M and half the measured fall.
if not np.all(last < first - 0.15):
    errors.append(f"Lacey index did not fall as the bed demixed: {first} -> {last}")
if not np.all(rise > 1.0):
    errors.append(f"light spheres did not rise above the heavy ones: {rise}")
if errors:
    print("bed_observables: " + "; ".join(errors))
    sys.exit(1)
print("bed_observables: ok")
PY
# The plot script: a PNG from the run, exit 2 with a message for a file without /bed.
/usr/bin/python3 "$here/../../scripts/plot_bed.py" "$work/bed.h5" -o "$work/bed.png"
test -s "$work/bed.png"
"$mpiexec" -n 1 "${launcher[@]}" "$efdem" "$here/tiny_scene.cfg" mode=direct run.duration=0.5 \
  output.directory="$work" output.prefix=nobed > "$work/log_nobed" 2>&1 || { cat "$work/log_nobed"; exit 1; }
set +e
/usr/bin/python3 "$here/../../scripts/plot_bed.py" "$work/nobed.h5" -o "$work/nobed.png" 2> "$work/err"
rc=$?
set -e
[ "$rc" = 2 ] && grep -q "observe.bed=true" "$work/err" || { echo "plot_bed.py on a run without /bed: rc $rc: $(cat "$work/err")"; exit 1; }
echo "bed_observables: plot ok"

# The SI scales: on a scene with the physical drag keys (defaults: d_p = 1e-4 m, rho_s = 900
# kg/m^3, g = 9.81 m/s^2) the root says what one reduced unit is in SI, and the pressure drop is
# also in pascal; a scene that gives gas_drag.A has no SI scale and writes neither.
"$mpiexec" -n 1 "${launcher[@]}" "$efdem" "$here/tiny_scene.cfg" mode=direct run.duration=0.5 observe.bed=true \
  output.directory="$work" output.prefix=dimensionless gas_drag.A=0.114939 > "$work/log_dimless" 2>&1 \
  || { cat "$work/log_dimless"; exit 1; }
/usr/bin/python3 - "$work/bed.h5" "$work/dimensionless.h5" <<'PY'
import math, sys
import h5py
import numpy as np
with h5py.File(sys.argv[1], "r") as f:
    a = f.attrs
    # The time unit efdem --check prints for these scales: sqrt(d_p/g) = 3.193 ms.
    assert abs(a["si_time_s"] - 3.193e-3) < 1e-6, a["si_time_s"]
    assert math.isclose(a["si_time_s"], math.sqrt(a["si_length_m"] / a["si_acceleration_m_per_s2"]), rel_tol=1e-12)
    assert math.isclose(a["si_velocity_m_per_s"] * a["si_time_s"], a["si_length_m"], rel_tol=1e-12)
    assert math.isclose(a["si_pressure_Pa"], 900 * 9.81 * 1e-4, rel_tol=1e-12)
    assert math.isclose(a["si_mass_kg"], 900 * 1e-12, rel_tol=1e-12)
    pd, pa = f["bed/pressure_drop"][()], f["bed/pressure_drop_pa"][()]
    assert f["bed/pressure_drop_pa"].attrs["units"] == "Pa"
    assert np.allclose(pa, pd * a["si_pressure_Pa"], rtol=1e-15, atol=0)
with h5py.File(sys.argv[2], "r") as f:
    assert not any(k.startswith("si_") for k in f.attrs) and "pressure_drop_pa" not in f["bed"]
print("bed_observables: SI scales ok")
PY
