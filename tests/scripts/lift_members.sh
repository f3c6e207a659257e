#!/usr/bin/env bash
# cpi.lift on a real DEM ensemble (4 realizations of the tiny bed on 2 ranks, fixed DT):
# `mean` lifts every realization to the projected ICDF, so the spread between them collapses;
# `members` moves each by the jump's increment, so the spread a direct ensemble has is kept;
# `own` (each by its own slope's jump too) keeps it as well and records every jump's member step.
# Measured (2026-12-02): RMS s.d. over the nodes 0.466 d_p at the last sample before the first
# lift, then 0.08 (mean) and 0.45 (members) at the first sample after it. Asserted with margins
# an ensemble of 4 cannot cross by chance: members >= 0.7 x before, mean <= 0.4 x before. Also
# refused: cpi.lift = members with the compact observable (no per-realization coarse state).
#   lift_members.sh EFDEM_BINARY MPIEXEC [MPIEXEC_PREFLAGS...]
source "$(dirname "$0")/lib.sh" "$@"
for lift in mean members own; do
  timeout 300 "$mpiexec" -n 2 "${launcher[@]}" "$efdem" "$here/tiny_scene.cfg" mode=cpi run.duration=12 \
    ensemble.realizations_per_rank=2 cpi.lift=$lift output.directory="$work" output.prefix=$lift \
    > "$work/$lift.log" 2>&1 || { cat "$work/$lift.log"; echo "FAIL: the cpi.lift = $lift run failed"; exit 1; }
  /usr/bin/python3 "$here/check_run_file.py" "$work/$lift.h5" > /dev/null || { echo "FAIL: $lift.h5 layout"; exit 1; }
done
/usr/bin/python3 - "$work" <<'PY' || exit 1
import sys
import h5py
import numpy as np
ratio = {}
for lift in ("mean", "members", "own"):
    with h5py.File(f"{sys.argv[1]}/{lift}.h5", "r") as f:
        t, var = f["samples/time"][:], f["samples/variance"][:]
        t_end, dt = f["cpi/t_end"][0], f["cpi/dt"][0]  # the first jump: from t_end to t_end + dt
        # own (fixed DT here): every jump moved the realizations apart, and says by how much.
        if lift == "own":
            step = f["cpi/controller/member_step"][:] if "cpi/controller/member_step" in f else np.zeros(0)
            if not (len(step) > 0 and np.all(step[np.asarray(f["cpi/dt"][:]) > 0] > 0)):
                sys.exit(f"FAIL: cpi.lift = own with a fixed DT did not lift apart: member_step {step}")
    before = np.sqrt(var[np.searchsorted(t, t_end - 1e-9)].mean())
    after = np.sqrt(var[np.searchsorted(t, t_end + dt + 1e-9)].mean())
    ratio[lift] = after / before
    print(f"cpi.lift = {lift}: RMS s.d. {before:.3f} d_p before the first lift, {after:.3f} after")
if not (ratio["members"] >= 0.7 and ratio["own"] >= 0.7 and ratio["mean"] <= 0.4):
    sys.exit(f"FAIL: spread after / before the first lift: members {ratio['members']:.2f}, own "
             f"{ratio['own']:.2f} (want >= 0.7), mean {ratio['mean']:.2f} (want <= 0.4)")
print("PASS: cpi.lift = members and own keep the realizations' spread through a lift; mean collapses it")
PY
set +e
timeout 120 "$mpiexec" -n 2 "${launcher[@]}" "$efdem" "$here/tiny_scene.cfg" mode=cpi cpi.lift=members \
  cpi.observable=compact output.directory="$work/refused" > "$work/refused.log" 2>&1
rc=$?
set -e
[ $rc -eq 2 ] && grep -q "cpi.lift" "$work/refused.log" && [ ! -e "$work/refused/efdem.h5" ] \
  || { cat "$work/refused.log"; echo "FAIL: cpi.lift = members with the compact observable: exit $rc, expected 2"; exit 1; }
echo "PASS: cpi.lift = members with the compact observable is refused (exit 2, the key named)"
# cpi.lift = own with what cannot carry each realization's own slope: periods (no member slopes)
# and cpi.curvature = pooled (the ensemble's curvature only). WORD: in the message besides cpi.lift.
for refusal in "periods periods cpi.projection=periods" \
               "curvature cpi.curvature cpi.curvature=pooled cpi.projection=adaptive cpi.tolerance=1"; do
  read -r name word overrides <<< "$refusal"
  set +e
  # shellcheck disable=SC2086
  timeout 120 "$mpiexec" -n 2 "${launcher[@]}" "$efdem" "$here/tiny_scene.cfg" mode=cpi cpi.lift=own \
    $overrides output.directory="$work/refused_$name" > "$work/refused_$name.log" 2>&1
  rc=$?
  set -e
  [ $rc -eq 2 ] && grep -q "cpi.lift" "$work/refused_$name.log" && grep -q "$word" "$work/refused_$name.log" \
    && [ ! -e "$work/refused_$name/efdem.h5" ] \
    || { cat "$work/refused_$name.log"; echo "FAIL: cpi.lift = own with $overrides: exit $rc, expected 2"; exit 1; }
  echo "PASS: cpi.lift = own with $overrides is refused (exit 2, the key named)"
done
# cpi.relabel = moving: the same interval counts, so the first lift (from the same state as the
# mean run's) changes the same number of labels per realization; which particles differs.
timeout 300 "$mpiexec" -n 2 "${launcher[@]}" "$efdem" "$here/tiny_scene.cfg" mode=cpi run.duration=12 \
  ensemble.realizations_per_rank=2 cpi.lift=mean cpi.relabel=moving output.directory="$work" \
  output.prefix=moving > "$work/moving.log" 2>&1 || { cat "$work/moving.log"; echo "FAIL: the cpi.relabel = moving run failed"; exit 1; }
/usr/bin/python3 - "$work" <<'PY' || exit 1
import sys
import h5py
import numpy as np
with h5py.File(f"{sys.argv[1]}/mean.h5", "r") as a, h5py.File(f"{sys.argv[1]}/moving.h5", "r") as b:
    ca, cb = a["cpi/lift_changed"][0], b["cpi/lift_changed"][0]
if not (np.array_equal(ca, cb) and ca.sum() > 0):
    sys.exit(f"FAIL: first lift changed {list(ca)} labels with any, {list(cb)} with moving")
print(f"PASS: cpi.relabel = moving changes as many labels at the first lift as any ({list(cb)})")
PY
