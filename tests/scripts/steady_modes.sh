#!/usr/bin/env bash
# mode = steady and mode = continuation on the tiny bed (docs/steady_states.md):
#  1. the same steady solve (R = 4) on 1, 2 and 4 ranks gives bit-identical run files
#     (iterates, GMRES history, the eigenvalue at the best iterate, samples);
#  2. a solve that cannot converge (one Newton step, |F| ~ 10x its noise) exits 3 with
#     "not converged", the residual history and what to try, and /steady/best = the iterate
#     with the smallest |F|; the run file is self-describing (check_run_file.py);
#  3. a continuation in gas_drag.superficial_velocity records a branch starting at the
#     scene's value and plot_steady.py draws it (PNG);
#  4. bad input is refused (exit 2) naming the key;
#  5. a stop signal mid-solve exits 4 with the iterates so far;
#  6. a cpi run with cpi.hand_off = steady ends in a steady solve from its last state.
#   steady_modes.sh EFDEM_BINARY MPIEXEC [MPIEXEC_PREFLAGS...]
source "$(dirname "$0")/lib.sh" "$@"
set -e
scene=$here/tiny_scene.cfg
solve=(mode=steady run.duration=0 steady.warmup=1 steady.tau=1 steady.max_iterations=1 steady.max_krylov=3
       steady.eigenvalues=1 steady.eigenvalue_products=2)
for np in 1 2 4; do
  k=$((4 / np))
  set +e
  "$mpiexec" -n "$np" "${launcher[@]}" "$efdem" "$scene" "${solve[@]}" ensemble.realizations_per_rank=$k \
    output.directory="$work" output.prefix=np$np > "$work/np$np.log" 2>&1
  rc=$?
  set -e
  [ "$rc" = 3 ] || { echo "np $np: exit $rc, expected 3 (not converged after one Newton step)"; cat "$work/np$np.log"; exit 1; }
done
/usr/bin/python3 "$here/compare_runs.py" "$work/np1.h5" "$work/np2.h5"
/usr/bin/python3 "$here/compare_runs.py" "$work/np1.h5" "$work/np4.h5"
grep -q "not converged" "$work/np2.log" || { echo "no 'not converged' message"; cat "$work/np2.log"; exit 1; }
grep -q "residual history" "$work/np2.log" || { echo "no residual history"; exit 1; }
grep -q "What to try" "$work/np2.log" || { echo "no advice"; exit 1; }
/usr/bin/python3 "$here/check_run_file.py" "$work/np2.h5"
/usr/bin/python3 - "$work/np2.h5" <<'PY'
import sys, h5py, numpy as np
f = h5py.File(sys.argv[1])
s = f["steady"]
assert str(f.attrs["end_status"]).startswith("not converged"), f.attrs["end_status"]
assert s.attrs["converged"] == 0
it = s["iterate"]
r = it["residual"][:]
assert len(r) == 2, r                     # the start and one Newton step
best = it["x"][int(np.argmin(r))]
assert np.array_equal(s["best"][:], best), "best is not the iterate with the smallest |F|"
assert s.attrs["best_residual"] == r.min()
assert len(s["krylov_products"]) == 1 and 1 <= s["krylov_products"][0] <= 3
assert len(s["gmres_residual"]) == s["krylov_products"][0] + 1
# Every evaluation costs tau = 1 of DEM time: warm-up 1 + evaluations x 1.
assert s.attrs["dem_time"] == s.attrs["evaluations"] * 1.0
# Out of iterations: the leading eigenvalue is computed at the best iterate (2 products).
assert len(s["eigenvalue_real"]) == 1 and s.attrs["eigenvalue_products"] == 2
# No steady.difference_step in the scene: h from the noise at the end of the warm-up (R = 4).
assert "x the noise norm" in str(s.attrs["difference_step_origin"]), s.attrs["difference_step_origin"]
assert s.attrs["difference_step"] > 0
print("steady: not converged as asked, best iterate saved; |F| =", r, "; h =", s.attrs["difference_step"])
PY

"$mpiexec" -n 2 "${launcher[@]}" "$efdem" "$scene" mode=continuation continuation.parameter=gas_drag.superficial_velocity \
  continuation.end=0.5 continuation.step=0.05 continuation.max_points=2 run.duration=0 steady.warmup=1 steady.tau=1 \
  steady.max_iterations=1 steady.max_krylov=2 steady.eigenvalues=1 steady.eigenvalue_products=2 steady.noise_factor=50 \
  output.directory="$work" output.prefix=branch > "$work/branch.log" 2>&1 || { cat "$work/branch.log"; exit 1; }
/usr/bin/python3 "$here/check_run_file.py" "$work/branch.h5"
/usr/bin/python3 - "$work/branch.h5" <<'PY'
import sys, h5py, numpy as np
f = h5py.File(sys.argv[1])
b = f["branch"]
lam = b["parameter"][:]
assert len(lam) == 2, lam
assert abs(lam[0] - 0.41) < 1e-12 and lam[1] > lam[0], lam  # from the scene value (lambda/scale x scale) towards the end
assert b["x"].shape == (2, 19)
assert np.all(np.isfinite(b["leading_rate"][:]))
assert np.allclose(b["mean_height"][:], b["x"][:].mean(axis=1))
held = b["from_last_point"][:]
assert held[0] == 0 and set(held) <= {0, 1}, held  # the first point has no predictor
print("continuation: branch", lam, "corrector from the last point:", held)
PY
/usr/bin/python3 "$here/../../scripts/plot_steady.py" "$work/branch.h5" "$work/branch.h5" -o "$work/branch.png"

# 3b. A continuation whose first point cannot converge (no Newton step, a stopping rule far below
#     the noise) exits 3 with the first point's residual history and its best iterate saved.
expect_exit 3 "$work/branch_failed.log" "$mpiexec" -n 2 "${launcher[@]}" "$efdem" "$scene" mode=continuation \
  continuation.parameter=gas_drag.superficial_velocity continuation.end=0.5 continuation.step=0.05 \
  continuation.max_points=2 run.duration=0 steady.warmup=1 steady.tau=1 steady.max_iterations=0 steady.eigenvalues=0 \
  steady.noise_factor=0.001 output.directory="$work" output.prefix=branch_failed
grep -qE "residual history \|F\| \[d_p\]: [0-9]" "$work/branch_failed.log" || { echo "no residual history"; cat "$work/branch_failed.log"; exit 1; }
/usr/bin/python3 "$here/check_run_file.py" "$work/branch_failed.h5"
/usr/bin/python3 - "$work/branch_failed.h5" <<'PY'
import sys, h5py, numpy as np
s = h5py.File(sys.argv[1])["steady"]
assert str(s.attrs["end_status"]).startswith("not converged"), s.attrs["end_status"]
assert np.array_equal(s["best"][:], s["iterate/x"][0])  # the only iterate: the warm-up's end
assert s.attrs["best_residual"] == s["iterate/residual"][0]
print("continuation: first point not converged, best iterate saved")
PY
/usr/bin/python3 "$here/../../scripts/plot_steady.py" "$work/np2.h5" -o "$work/steady.png"
[ -s "$work/branch.png" ] && [ -s "$work/steady.png" ]

# 4b. In gap coordinates every lift is monotone: the repair only clips at the bed's floor and
#     top; the answer is recorded in heights (increasing), and the attribute says which.
"$mpiexec" -n 2 "${launcher[@]}" "$efdem" "$scene" "${solve[@]}" steady.coordinates=gaps ensemble.realizations_per_rank=2 \
  output.directory="$work" output.prefix=gaps > "$work/gaps.log" 2>&1 || [ $? = 3 ] || { cat "$work/gaps.log"; exit 1; }
/usr/bin/python3 "$here/check_run_file.py" "$work/gaps.h5"
/usr/bin/python3 - "$work/gaps.h5" <<'PY'
import sys, h5py, numpy as np
s = h5py.File(sys.argv[1])["steady"]
assert s.attrs["coordinates"] == "gaps", s.attrs["coordinates"]
for name in ("x", "best"):
    assert np.all(np.diff(s[name][:]) > 0), (name, s[name][:])   # heights, strictly increasing
assert np.all(np.diff(s["iterate/x"][:], axis=1) > 0)
print("gaps: answer in heights, increasing; repairs", s.attrs["repairs"], "of", s.attrs["evaluations"])
PY

stop_mid_solve() {  # LOG PATTERN OVERRIDES...: efdem on 2 ranks, SIGTERM to every rank once LOG shows PATTERN; sets rc
  local log=$1 pattern=$2
  shift 2
  setsid "$mpiexec" -n 2 "${launcher[@]}" "$efdem" "$scene" "$@" > "$log" 2>&1 &
  local job=$!
  for _ in $(seq 150); do grep -q "$pattern" "$log" 2>/dev/null && break; sleep 0.2; done
  kill -TERM $(ps -o pid=,comm= -s "$job" | awk '$2 == "efdem" {print $1}')
  set +e
  wait "$job"
  rc=$?
  set -e
}

# 5. A stop signal to every rank mid-solve: exit 4 within seconds, the run file marked
#    interrupted with the iterates so far and the best one.
stop_mid_solve "$work/sig.log" "iterate 1:" mode=steady run.duration=0 steady.warmup=1 steady.tau=1 \
  steady.max_iterations=50 steady.max_krylov=3 steady.eigenvalues=0 output.directory="$work" output.prefix=sig
[ "$rc" = 4 ] || { echo "signal: exit $rc, expected 4"; cat "$work/sig.log"; exit 1; }
grep -q "the iterates so far and the best one are in" "$work/sig.log" || { echo "signal: no message"; cat "$work/sig.log"; exit 1; }
/usr/bin/python3 "$here/check_run_file.py" "$work/sig.h5"
/usr/bin/python3 - "$work/sig.h5" <<'PY'
import sys, h5py
f = h5py.File(sys.argv[1])
assert str(f.attrs["end_status"]).startswith("interrupted"), f.attrs["end_status"]
assert len(f["steady/iterate/residual"]) >= 2 and "best" in f["steady"]
print("signal: interrupted with", len(f["steady/iterate/residual"]), "iterates recorded")
PY

# 6. cpi.hand_off = steady: a cpi run hands its end state to the steady solver (Anderson by
#    default). The solve starts one sample after the cpi run's end from that sample's mean ICDF,
#    converges by its rule (|F| <= 2 x noise), and the DEM time adds up exactly: the cpi run's
#    warm-up and bursts, the solve's one-sample warm-up, its evaluations x tau.
"$mpiexec" -n 2 "${launcher[@]}" "$efdem" "$scene" mode=cpi ensemble.realizations_per_rank=2 cpi.hand_off=steady \
  steady.tau=1 output.directory="$work" output.prefix=hand_off > "$work/hand_off.log" 2>&1 || { cat "$work/hand_off.log"; exit 1; }
grep -q "cpi.hand_off: end state not reached by the cpi run.s bursts" "$work/hand_off.log" || { echo "hand-off: no end-state line"; cat "$work/hand_off.log"; exit 1; }
/usr/bin/python3 "$here/check_run_file.py" "$work/hand_off.h5"
/usr/bin/python3 - "$work/hand_off.h5" <<'PY'
import sys, h5py, numpy as np
f = h5py.File(sys.argv[1])
s = f["steady"]
assert str(f.attrs["end_status"]).startswith("completed; then the steady solve: completed"), f.attrs["end_status"]
assert s.attrs["solver"] == "anderson" and s.attrs["converged"] == 1
assert s.attrs["hand_off_time"] == 6.0          # run.duration of the tiny scene: the cpi run's end
t = f["samples/time"][:]
k = int(np.argmin(np.abs(t - 6.25)))            # one sample (observe.interval 0.25) after it
assert abs(t[k] - 6.25) < 1e-9, t
assert np.allclose(s["x0"][:], f["samples/mean_icdf"][k], rtol=0, atol=1e-12)
r, noise = s["iterate/residual"][:], s["iterate/noise"][:]
assert r[-1] <= 2 * noise[-1] and np.all(r[:-1] > 2 * noise[:-1]), (r, noise)  # stopped at its rule, not before
assert s.attrs["dem_time"] == s.attrs["evaluations"] * 1.0
cpi = 0.5 + f["cpi/burst_length"][:].sum()     # cpi.warmup 0.5 and the bursts
assert abs(f.attrs["dem_time"] - (cpi + 0.25 + s.attrs["dem_time"])) < 1e-9, (f.attrs["dem_time"], cpi, s.attrs["dem_time"])
# The time to the end state: the cpi run's last kept burst (t_end 5) is farther than
# sqrt(2) x 2 x noise from the answer (its |F| at the start was 5.7 x noise): not reached.
assert np.isnan(s.attrs["end_state_time"]), s.attrs["end_state_time"]
print("hand-off: converged in", len(r) - 1, "iterations, |F| =", r[-1], "noise", noise[-1])
PY
# With a threshold 50 x the noise every kept burst is within it: the end state was reached at the
# first kept burst's end, and the solve stops at its start.
"$mpiexec" -n 2 "${launcher[@]}" "$efdem" "$scene" mode=cpi ensemble.realizations_per_rank=2 cpi.hand_off=steady \
  steady.tau=1 steady.noise_factor=50 output.directory="$work" output.prefix=hand_off_wide > "$work/hand_off_wide.log" 2>&1 \
  || { cat "$work/hand_off_wide.log"; exit 1; }
/usr/bin/python3 - "$work/hand_off_wide.h5" <<'PY'
import sys, h5py, numpy as np
f = h5py.File(sys.argv[1])
s, c = f["steady"], f["cpi"]
kept = [t for t, st in zip(c["t_end"][:], c["status"][:]) if st.decode() in ("projected", "burst_only")]
assert s.attrs["end_state_time"] == kept[0], (s.attrs["end_state_time"], kept)
assert len(s["iterate/residual"]) == 1  # converged at its start
print("hand-off: end state reached at t =", s.attrs["end_state_time"])
PY

# 6c. A cpi run with a hand-off restarted from its checkpoint after the first coarse step ends
#     bit for bit as the uninterrupted run: the cpi part continues exactly, and the solve then
#     starts from the same state (compare_runs.py compares /steady too).
rs=(mode=cpi ensemble.realizations_per_rank=2 cpi.hand_off=steady steady.tau=1 checkpoint.interval=1
    output.directory="$work/rs" output.prefix=ho)
"$mpiexec" -n 2 "${launcher[@]}" "$efdem" "$scene" "${rs[@]}" > "$work/rs_a.log" 2>&1 || { cat "$work/rs_a.log"; exit 1; }
cp "$work/rs/ho.h5" "$work/rs_reference.h5"
"$mpiexec" -n 2 "${launcher[@]}" "$efdem" "$scene" "${rs[@]}" restart="$work/rs/ho_ckpt_00000001.h5" > "$work/rs_b.log" 2>&1 \
  || { cat "$work/rs_b.log"; exit 1; }
grep -q "restarted from" "$work/rs_b.log" || { echo "hand-off restart: did not restart"; exit 1; }
/usr/bin/python3 "$here/compare_runs.py" "$work/rs_reference.h5" "$work/rs/ho.h5"
/usr/bin/python3 -c "import h5py, sys; f = h5py.File(sys.argv[1]); assert 'x' in f['steady'], 'no /steady/x'" "$work/rs/ho.h5"
# With every kept burst inside the radius (50 x the noise) the uninterrupted run's end state is its
# first kept burst; the restarted process saw none of the bursts before its checkpoint, so its time
# is later and marked an upper bound (end_state_time_is_bound = 1), not passed off as exact.
rs_wide=("${rs[@]/output.prefix=ho/output.prefix=ho_wide}" steady.noise_factor=50)
"$mpiexec" -n 2 "${launcher[@]}" "$efdem" "$scene" "${rs_wide[@]}" > "$work/rs_c.log" 2>&1 || { cat "$work/rs_c.log"; exit 1; }
cp "$work/rs/ho_wide.h5" "$work/rs_wide_reference.h5"
"$mpiexec" -n 2 "${launcher[@]}" "$efdem" "$scene" "${rs_wide[@]}" restart="$work/rs/ho_wide_ckpt_00000001.h5" \
  > "$work/rs_d.log" 2>&1 || { cat "$work/rs_d.log"; exit 1; }
grep -q "end state reached at or before" "$work/rs_d.log" || { echo "hand-off restart: no bound in the log"; cat "$work/rs_d.log"; exit 1; }
/usr/bin/python3 - "$work/rs_wide_reference.h5" "$work/rs/ho_wide.h5" <<'PY'
import sys, h5py
a, b = (h5py.File(p)["steady"].attrs for p in sys.argv[1:])
assert a["end_state_time_is_bound"] == 0 and b["end_state_time_is_bound"] == 1, (a["end_state_time_is_bound"], b["end_state_time_is_bound"])
assert b["end_state_time"] > a["end_state_time"], (a["end_state_time"], b["end_state_time"])
print("hand-off restart: end state at", a["end_state_time"], "; after the restart an upper bound", b["end_state_time"])
PY

# 6b. A stop signal during a hand-off's solve: exit 4, the status leads with "interrupted" (a
#     study counts the run as incomplete), and the message says a restart redoes the solve.
stop_mid_solve "$work/hand_off_sig.log" "steady: solve 0 iterate 1:" mode=cpi ensemble.realizations_per_rank=2 \
  cpi.hand_off=steady steady.tau=1 steady.noise_factor=0.001 steady.max_iterations=50 output.directory="$work" \
  output.prefix=hand_off_sig
[ "$rc" = 4 ] || { echo "hand-off signal: exit $rc, expected 4"; cat "$work/hand_off_sig.log"; exit 1; }
grep -q "restarting the cpi run's last checkpoint redoes it" "$work/hand_off_sig.log" || { echo "hand-off signal: no message"; cat "$work/hand_off_sig.log"; exit 1; }
/usr/bin/python3 - "$work/hand_off_sig.h5" <<'PY'
import sys, h5py
f = h5py.File(sys.argv[1])
status = str(f.attrs["end_status"])
assert status.startswith("interrupted") and "the cpi run before it: completed" in status, status
assert len(f["steady/iterate/residual"]) >= 2 and len(f["cpi/status"]) >= 1
print("hand-off signal:", status[:60], "...")
PY

refused() {  # WHAT KEY NP OVERRIDES...: exit 2 and the key in the message
  local what=$1 key=$2 np=$3; shift 3
  set +e
  "$mpiexec" -n "$np" "${launcher[@]}" "$efdem" "$scene" output.directory="$work/bad" "$@" > "$work/bad.log" 2>&1
  local rc=$?
  set -e
  [ "$rc" = 2 ] || { echo "$what: exit $rc, expected 2"; cat "$work/bad.log"; exit 1; }
  grep -q -- "$key" "$work/bad.log" || { echo "$what: the message does not name $key"; cat "$work/bad.log"; exit 1; }
  echo "refused: $what"
}
refused "continuation without its end" "continuation.end" 2 mode=continuation continuation.parameter=gas_drag.superficial_velocity
refused "a parameter no realization can change" "continuation.parameter" 2 mode=continuation continuation.parameter=dt continuation.end=0.5
refused "one realization" "mode" 1 mode=steady
refused "checkpoints" "checkpoint.interval" 2 mode=steady checkpoint.interval=2
refused "an Anderson key with Newton" "steady.depth" 2 mode=steady steady.depth=2
refused "a continuation key in mode = steady" "continuation.end" 2 mode=steady continuation.end=0.5
refused "the predictor fallback in mode = steady" "continuation.predictor_fallback" 2 mode=steady continuation.predictor_fallback=1
refused "a negative predictor fallback" "continuation.predictor_fallback" 2 mode=continuation \
  continuation.parameter=gas_drag.superficial_velocity continuation.end=0.5 continuation.predictor_fallback=-1
refused "drop on failure" "ensemble.on_failure" 2 mode=steady ensemble.on_failure=drop
refused "tau off the sampling grid" "steady.tau" 2 mode=steady steady.tau=0.3
refused "gap coordinates of the compact vector" "steady.coordinates" 2 mode=steady steady.coordinates=gaps cpi.observable=compact
refused "a restart" "restart" 2 mode=steady restart=$work/none_ckpt.h5
refused "a hand-off with drop on failure" "ensemble.on_failure" 2 mode=cpi cpi.hand_off=steady ensemble.on_failure=drop
refused "a hand-off of one realization" "cpi.hand_off" 1 mode=cpi cpi.hand_off=steady
refused "a steady key without a hand-off" "steady.tau" 2 mode=cpi steady.tau=1
echo "steady_modes: ok"
