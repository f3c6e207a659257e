#!/usr/bin/env bash
# Realizations at rest (issue 34): the tiny bed without gas settles from its lattice start and comes
# to rest (every particle slower than 1e-6 sqrt(g d_p)) after ~26-30 time units (measured
# 2026-12-04; /samples/at_rest). Asserted on real DEM ensembles of 2 realizations on 2 ranks:
#  1. direct, every realization advanced (ensemble.at_rest = simulate): a realization at rest
#     stays at rest (an absorbing state of the DEM, the premise of cpi.at_rest = hold,
#     cpi.finish and ensemble.at_rest = pause): once at_rest is 1 it stays 1, and its
#     light ICDF moves by less than 1e-6 d_p for good (measured: 2e-10 and 1e-12; a settling bed
#     moves by > 1e-4 per sample, a fluidized one by ~1e-2);
#  2. ensemble.at_rest = pause (the default) against simulate, direct: the ICDFs agree to 1e-6 d_p
#     (a paused bed is one at rest left alone; measured 1.7e-10) and the paused run counts fewer
#     particle-steps, by exactly the realization-samples at rest but the last sample's (a
#     realization is paused from the sample that finds it at rest; measured 99 of 320);
#  3. cpi with cpi.finish = at_rest and run.duration = 200: the run ends at the end state, long
#     before 200 (status "completed (end state at t = ...)"), every realization at rest at the last
#     sample, and the time named is where the last unbroken run of samples with both at rest
#     began (a lift relabels a realization that still moves, and the bed's vibration can pass
#     below the threshold and above it again while it decays). at_rest, not steady: on this
#     settling bed the light ICDF stops changing (the drift test of steady: z <= 2 by t ~ 31)
#     while its particles still vibrate above the threshold;
#  5. a restart with paused realizations continues the run bit for bit (their still count is in
#     the checkpoint, /realizations/still_samples), on another layout;
#  6. cpi.jump_until = 10 with cpi.finish = at_rest: the jumps end by t = 10 (no jump ends later),
#     every coarse step after is a burst without a jump or a lift (no label changed, DT 0,
#     limited by "cpi.jump_until"), and the run still ends at its end state (measured: at 42.25);
#  4. the lifts on the way held the realizations at rest (/cpi/lift_at_rest) and left their
#     labels: their ICDF moved by less than 1e-6 d_p across those lifts (a relabelling moves it by
#     about a light particle's spacing, ~1e-2 d_p; a bed slower than 1e-6 sqrt(g d_p) moves less
#     than 1e-6 in a sample interval).
#   at_rest.sh EFDEM_BINARY MPIEXEC [MPIEXEC_PREFLAGS...]
source "$(dirname "$0")/lib.sh" "$@"
common=(ensemble.realizations_per_rank=1 gas_drag.superficial_velocity=0.0)
timeout 300 "$mpiexec" -n 2 "${launcher[@]}" "$efdem" "$here/tiny_scene.cfg" mode=direct run.duration=40 \
  "${common[@]}" output.directory="$work" output.prefix=direct checkpoint.interval=40 checkpoint.keep=10 \
  > "$work/direct.log" 2>&1 || { cat "$work/direct.log"; echo "FAIL: the direct run failed"; exit 1; }
# 5. A restart from t = 30, where both realizations have been still for a while (paused, their count
#    in the checkpoint), on another layout (1 rank x 2), continues the paused run bit for bit.
ckpt="$work/direct_ckpt_00000120.h5"
/usr/bin/python3 -c "import h5py, sys; s = h5py.File(sys.argv[1], 'r')['/realizations/still_samples'][:]
sys.exit(0 if (s >= 4).any() else f'FAIL: no realization at rest in the checkpoint: {s.ravel()}')" "$ckpt" || exit 1
timeout 300 "$mpiexec" -n 1 "${launcher[@]}" "$efdem" "$here/tiny_scene.cfg" mode=direct run.duration=40 \
  ensemble.realizations_per_rank=2 gas_drag.superficial_velocity=0.0 output.directory="$work" \
  output.prefix=restarted restart="$ckpt" > "$work/restarted.log" 2>&1 \
  || { cat "$work/restarted.log"; echo "FAIL: the restart failed"; exit 1; }
/usr/bin/python3 "$here/compare_runs.py" "$work/direct.h5" "$work/restarted.h5" || { echo "FAIL: the restart differs"; exit 1; }
cmp -s "$work/direct_mean_icdf.csv" "$work/restarted_mean_icdf.csv" || { echo "FAIL: its CSV differs"; exit 1; }
echo "PASS: a restart with paused realizations continues the run bit for bit"
timeout 300 "$mpiexec" -n 2 "${launcher[@]}" "$efdem" "$here/tiny_scene.cfg" mode=direct run.duration=40 \
  "${common[@]}" ensemble.at_rest=simulate output.directory="$work" output.prefix=simulated \
  > "$work/simulated.log" 2>&1 || { cat "$work/simulated.log"; echo "FAIL: the simulate run failed"; exit 1; }
timeout 300 "$mpiexec" -n 2 "${launcher[@]}" "$efdem" "$here/tiny_scene.cfg" mode=cpi run.duration=200 \
  "${common[@]}" cpi.finish=at_rest output.directory="$work" output.prefix=cpi > "$work/cpi.log" 2>&1 \
  || { cat "$work/cpi.log"; echo "FAIL: the cpi run failed"; exit 1; }
/usr/bin/python3 "$here/check_run_file.py" "$work/cpi.h5" > /dev/null || { echo "FAIL: cpi.h5 layout"; exit 1; }
timeout 300 "$mpiexec" -n 2 "${launcher[@]}" "$efdem" "$here/tiny_scene.cfg" mode=cpi run.duration=200 \
  "${common[@]}" cpi.finish=at_rest cpi.jump_until=10 output.directory="$work" output.prefix=until \
  > "$work/until.log" 2>&1 || { cat "$work/until.log"; echo "FAIL: the cpi.jump_until run failed"; exit 1; }
/usr/bin/python3 - "$work" <<'PY' || exit 1
import re
import sys
import h5py
import numpy as np
work = sys.argv[1]
# 1. judged where every realization is advanced (ensemble.at_rest = simulate)
with h5py.File(f"{work}/simulated.h5", "r") as f:
    t, rest, icdf = f["samples/time"][:], f["samples/at_rest"][:], f["samples/icdf"][:]
for r in range(rest.shape[1]):
    first = np.nonzero(rest[:, r])[0]
    if len(first) == 0:
        sys.exit(f"FAIL: direct realization {r} never came to rest in 40 units (expected ~30)")
    k = first[0]
    if not np.all(rest[k:, r] == 1):
        sys.exit(f"FAIL: direct realization {r} at rest at t = {t[k]:.2f} moved again")
    drift = np.abs(icdf[k:, r, :] - icdf[k, r, :]).max()
    if drift > 1e-6:
        sys.exit(f"FAIL: direct realization {r} at rest from t = {t[k]:.2f}: its ICDF moved {drift:.2e} d_p")
    print(f"direct realization {r}: at rest from t = {t[k]:.2f}, ICDF drift since {drift:.1e} d_p")
icdf_sim, rest_sim = icdf, rest
with h5py.File(f"{work}/simulated.h5", "r") as f:
    steps_sim = float(f.attrs["particle_steps"])
with h5py.File(f"{work}/direct.h5", "r") as f:  # 2. paused (the default)
    steps_paused = float(f.attrs["particle_steps"])
    rest, icdf = f["samples/at_rest"][:], f["samples/icdf"][:]
    per_sample = steps_sim / (len(t) * rest.shape[1])  # particle-steps of one realization-sample
    interval = float(t[1] - t[0])
gap = np.abs(icdf_sim - icdf).max()
# Paused from the sample after the one that found it at rest: every at-rest flag but the last
# sample's saves one realization-sample.
saved = int(rest[:-1].sum())
if gap > 1e-6 or not np.array_equal(rest, rest_sim) or abs((steps_sim - steps_paused) / per_sample - saved) > 1e-6:
    sys.exit(f"FAIL: pause vs simulate: ICDFs {gap:.2e} d_p apart, at rest alike {np.array_equal(rest, rest_sim)}, "
             f"particle-steps saved {(steps_sim - steps_paused) / per_sample:.3f} realization-samples, expected {saved}")
print(f"pause vs simulate: ICDFs {gap:.1e} d_p apart; {saved} realization-samples of "
      f"{rest.size} not computed ({100 * saved / rest.size:.0f} %)")
with h5py.File(f"{work}/cpi.h5", "r") as f:
    status = f.attrs["end_status"]
    status = status.decode() if isinstance(status, bytes) else str(status)
    t, rest, icdf = f["samples/time"][:], f["samples/at_rest"][:], f["samples/icdf"][:]
    held, t_lift = f["cpi/lift_at_rest"][:], f["cpi/t_end"][:]
m = re.search(r"end state at t = ([0-9.eE+-]+)", status)
if not m:
    sys.exit(f"FAIL: the cpi run did not end at its end state: {status}")
t_end_state = float(m.group(1))
moving = np.nonzero(~rest.all(axis=1))[0]
since = t[moving[-1] + 1] if len(moving) and moving[-1] + 1 < len(t) else (t[0] if not len(moving) else None)
if not (since is not None and abs(since - t_end_state) < 1e-9 and rest[-1].all() and t[-1] < 100):
    sys.exit(f"FAIL: end state at {t_end_state}, both at rest for good from {since}, "
             f"last sample {t[-1]:.2f} {rest[-1]}")
print(f"cpi: {status}; last sample t = {t[-1]:.2f}")
# Every lift that held a realization left its ICDF: the first sample after the lift equals the
# last one before it (to the drift of a bed at rest).
checked = 0
for j, te in enumerate(t_lift):
    for r in np.nonzero(held[j])[0]:
        before = np.searchsorted(t, te - 1e-9)
        if before + 1 < len(t):
            jump = np.abs(icdf[before + 1, r] - icdf[before, r]).max()
            if jump > 1e-6:
                sys.exit(f"FAIL: realization {r} held at the lift after t = {te:.2f} moved {jump:.2e} d_p")
            checked += 1
print(f"PASS: realizations at rest stay at rest; cpi.finish = at_rest ended at the end state; "
      f"{checked} held lift(s) left their realization where it was")
# 6. cpi.jump_until = 10
with h5py.File(f"{work}/until.h5", "r") as f:
    status = f.attrs["end_status"]
    status = status.decode() if isinstance(status, bytes) else str(status)
    te, dt, changed = f["cpi/t_end"][:], f["cpi/dt"][:], f["cpi/lift_changed"][:].sum(axis=1)
    limited = [v.decode() if isinstance(v, bytes) else str(v) for v in f["cpi/controller/limited_by"][:]]
jumped = dt > 0
if not jumped.any() or (te[jumped] + dt[jumped]).max() > 10 + 1e-9:
    sys.exit(f"FAIL: cpi.jump_until = 10: jumps ending at {te[jumped] + dt[jumped]}")
after = te >= 10 - 1e-9
if not after.any() or dt[after].any() or changed[after].any() or any(limited[k] != "cpi.jump_until" for k in np.nonzero(after)[0]):
    sys.exit(f"FAIL: after t = 10: DT {dt[after]}, labels changed {changed[after]}, limited by "
             f"{sorted(set(limited[k] for k in np.nonzero(after)[0]))}")
if "end state at" not in status:
    sys.exit(f"FAIL: the cpi.jump_until run did not end at its end state: {status}")
print(f"PASS: cpi.jump_until = 10: {int(jumped.sum())} jumps, the last ending at "
      f"{(te[jumped] + dt[jumped]).max():g}; {int(after.sum())} bursts after without a jump or a lift; {status}")
PY
