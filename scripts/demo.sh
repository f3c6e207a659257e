#!/usr/bin/env bash
# The README's main job: set up (apt-get, only what is missing), build, run a direct and a CPI
# ensemble of examples/demo_small on 2 ranks (R = 4, independent seeds), and plot both. About ten
# minutes on 2 cores.
set -euo pipefail
src=$(cd "$(dirname "$0")/.." && pwd)
bash "$src/scripts/install_deps.sh"
build=${EFDEM_BUILD_DIR:-$src/build}
cmake -S "$src" -B "$build" -DCMAKE_BUILD_TYPE=Release > "$build.configure.log" 2>&1 \
  || { cat "$build.configure.log"; exit 1; }
cmake --build "$build" -j "$(nproc)" --target efdem

export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
scene=$src/examples/demo_small/scene.cfg
out=$src/runs/demo_small
mkdir -p "$out"
# Two independent ensembles (their own seeds): a CPI run that shared the direct run's seeds would
# follow it for a while after every jump and look better than it is.
echo "== direct ensemble (2 ranks x 2 realizations, seed 1) =="
mpirun -np 2 --oversubscribe "$build/mpi_driver/efdem" "$scene" mode=direct seed=1 output.prefix=direct output.overwrite=true
echo "== adaptive coarse projective integration (2 ranks x 2 realizations, seed 2) =="
mpirun -np 2 --oversubscribe "$build/mpi_driver/efdem" "$scene" mode=cpi seed=2 output.prefix=cpi output.overwrite=true
/usr/bin/python3 "$src/scripts/plot_icdf.py" "$out/direct.h5" "$out/cpi.h5" -o "$out/icdf.png" \
  --title "demo_small: light-particle heights, direct vs adaptive CPI (R = 4, independent seeds)"
/usr/bin/python3 - "$out/direct.h5" "$out/cpi.h5" <<'PY'
import sys, h5py
d, c = (h5py.File(p, "r") for p in sys.argv[1:3])
for name, f in (("direct", d), ("cpi", c)):
    m = f["samples/mean"]
    print(f"{name:>6}: median light height {m[0, 9]:.2f} -> {m[-1, 9]:.2f} d_p at t = {f['samples/time'][-1]:.1f}; "
          f"{f.attrs['particle_steps']:.3g} particle-steps, {f.attrs['wall_seconds']:.0f} s wall")
print(f"cpi simulated {c.attrs['simulated_time']:.0f} time units with {c.attrs['dem_time']:.0f} of DEM "
      f"({d.attrs['wall_seconds'] / max(c.attrs['wall_seconds'], 1e-9):.1f}x less wall time than direct)")
# Within the direct ensemble's band? Where both have a sample: |difference| against the standard
# error of the difference of two independent ensemble means.
import numpy as np
t_d, t_c = d["samples/time"][:], c["samples/time"][:]
common, i_d, i_c = np.intersect1d(np.round(t_d, 6), np.round(t_c, 6), return_indices=True)
R = d.attrs["realizations"]
diff = c["samples/mean"][i_c] - d["samples/mean"][i_d]
se = np.sqrt((d["samples/variance"][i_d] + c["samples/variance"][i_c]) / R)
z = np.abs(diff) / np.maximum(se, 1e-12)
print(f"cpi vs direct at {len(common)} common sample times: RMS difference {np.sqrt(np.mean(diff**2)):.3f} d_p; "
      f"{100 * np.mean(z <= 1.96):.0f} % of (time, node) points within the 95 % band of the difference")
if "cpi/controller_summary" in c:
    print(c["cpi/controller_summary"][()].decode())
PY
echo "plot: $out/icdf.png"
