#!/usr/bin/env bash
# One failing realization does not lose the ensemble's work (ensemble.on_failure; 4 realizations
# on 2 ranks, realization 1 fails by debug.fail_realization):
#  1. direct + drop: the run completes "with 1 failure(s)", the run file names the failure, the
#     means are over 3 realizations from then on (/samples/realizations_used), and the three
#     survivors' trajectories equal those of the run without the failure bit for bit;
#  2. a restart from a checkpoint written after the drop equals the uninterrupted run;
#  3. cpi + drop / replace: every sample up to where the interrupted coarse step began equals the
#     run without the failure (afterwards the ensemble mean, and with it the lifts, differ); drop
#     leaves 3 realizations, replace keeps 4 and the rebuilt realization leaves its donor;
#  4. direct + replace is refused (a copy would follow its donor); more failures than
#     ensemble.max_failures end the run (exit 3, run file marked failed).
#   failing_realization.sh EFDEM_BINARY MPIEXEC [MPIEXEC_PREFLAGS...]
source "$(dirname "$0")/lib.sh" "$@"
scene="$here/tiny_scene.cfg"
run() {  # run PREFIX ARGS...: expects success
  local p=$1; shift
  timeout 300 "$mpiexec" -n 2 "${launcher[@]}" "$efdem" "$scene" ensemble.realizations_per_rank=2 \
    output.directory="$work" output.prefix=$p "$@" > "$work/$p.log" 2>&1 \
    || { grep -v "^t = " "$work/$p.log"; echo "FAIL: run $p"; exit 1; }
}
fail=(debug.fail_realization=1 debug.fail_time=1)

run dref mode=direct run.duration=4
run ddrop mode=direct run.duration=4 ensemble.on_failure=drop checkpoint.interval=4 checkpoint.keep=10 "${fail[@]}"
run dre mode=direct run.duration=4 ensemble.on_failure=drop "${fail[@]}" restart="$work/ddrop_ckpt_00000008.h5"
run cref mode=cpi run.duration=12
run cdrop mode=cpi run.duration=12 ensemble.on_failure=drop debug.fail_realization=1 debug.fail_time=4
run crep mode=cpi run.duration=12 ensemble.on_failure=replace debug.fail_realization=1 debug.fail_time=4 \
  checkpoint.interval=1 checkpoint.keep=100
# The injected failure happens once per run: a restart from a checkpoint written after the
# replacement must not see it again (it did: the rebuilt realization failed a second time).
newest=$(ls "$work"/crep_ckpt_*.h5 | tail -1)
run crep_re mode=cpi run.duration=12 ensemble.on_failure=replace debug.fail_realization=1 debug.fail_time=4 \
  restart="$newest"
/usr/bin/python3 "$here/compare_runs.py" "$work/crep.h5" "$work/crep_re.h5" \
  || { echo "FAIL: the restart after the replacement ($newest) differs from the uninterrupted run"; exit 1; }
echo "PASS: a restart from $(basename "$newest"), written after the replacement, equals the uninterrupted run (the injected failure does not fire again)"
# A failure on a non-root rank while the ensemble keeps its state (a local step
# of a stage every rank runs): the ranks agree, every rank exits 3 and the root marks the run
# file. (It was an MPI_Abort from that rank: the run file stayed 'running'.)
timeout 300 "$mpiexec" -n 2 "${launcher[@]}" "$efdem" "$scene" ensemble.realizations_per_rank=2 mode=cpi \
  run.duration=12 output.directory="$work" output.prefix=keepfail debug.fail_realization=2 debug.fail_time=4 \
  debug.fail_stage=keep > "$work/keepfail.log" 2>&1
code=$?
status=$(/usr/bin/python3 -c "import h5py, sys; print(h5py.File(sys.argv[1], 'r').attrs['end_status'])" "$work/keepfail.h5")
if [ $code -eq 3 ] && [[ $status == "failed: "*"realization 2: keeping the state "*": injected failure (debug.fail_stage = keep);"* ]] \
   && ! grep -q "MPI_ABORT" "$work/keepfail.log"; then
  echo "PASS: a failure keeping the state on rank 1 ends every rank (exit 3, no abort); run file: $(cut -c1-100 <<< "$status")..."
else
  grep -v "^t = " "$work/keepfail.log"; echo "FAIL: keep-stage failure: exit $code, status '$status'"; exit 1
fi
/usr/bin/python3 "$here/compare_runs.py" "$work/ddrop.h5" "$work/dre.h5" \
  || { echo "FAIL: the restart after the drop differs from the uninterrupted run"; exit 1; }
echo "PASS: a restart from a checkpoint written after the drop equals the uninterrupted run"
/usr/bin/python3 - "$work" <<'PY' || exit 1
import sys, h5py, numpy as np
w = sys.argv[1]
f = {n: h5py.File(f"{w}/{n}.h5", "r") for n in ("dref", "ddrop", "cref", "cdrop", "crep")}
def text(v): return v.decode() if isinstance(v, bytes) else str(v)
def check(ok, what):
    print(("PASS: " if ok else "FAIL: ") + what)
    if not ok: sys.exit(1)
d, ref = f["ddrop"], f["dref"]
check(text(d.attrs["end_status"]) == "completed with 1 failure(s)", f"direct drop ends '{text(d.attrs['end_status'])}'")
check(list(d["failures/realization"][:]) == [1] and text(d["failures/action"][0]) == "dropped"
      and "injected failure" in text(d["failures/reason"][0]), "the run file names the failure (realization 1, dropped, why)")
used = d["samples/realizations_used"][:]
t_fail = d["failures/time"][0]
check(set(used[d["samples/time"][:] < t_fail - 1e-9]) == {4} and set(used[d["samples/time"][:] >= t_fail - 1e-9]) == {3},
      f"the means are over 4 realizations before t = {t_fail:g} and over 3 from then on")
a, b = ref["samples/icdf"][:], d["samples/icdf"][:]
check(all(np.array_equal(a[:, r], b[:, r]) for r in (0, 2, 3)), "the survivors' ICDFs equal the run without the failure bit for bit")
check(np.isnan(b[d["samples/time"][:] >= t_fail - 1e-9, 1]).all(), "the dropped realization's rows are NaN")
mean = np.nanmean(b[-1], axis=0)
check(np.allclose(d["samples/mean_icdf"][-1], mean, rtol=0, atol=1e-12), "the last mean is the mean of the 3 survivors")
for name, left in (("cdrop", 3), ("crep", 4)):
    c, cr = f[name], f["cref"]
    t0 = c["failures/resumed_at"][0]
    tc = c["samples/time"][:]
    before = tc <= t0 + 1e-9
    same = all(np.array_equal(c["samples/icdf"][k], cr["samples/icdf"][k]) for k in np.nonzero(before)[0])
    check(same and before.sum() > 0, f"{name}: the {before.sum()} samples up to t = {t0:g} (where the step was redone) equal the run without the failure")
    check(text(c.attrs["end_status"]).startswith("completed with 1 failure") and
          int(c["samples/realizations_used"][-1]) == left, f"{name}: completed with {left} realizations")
c = f["crep"]
donor = int(c["failures/donor"][0])
check(donor == 2 and text(c["failures/action"][0]) == "replaced", "crep: realization 1 rebuilt from realization 2")
icdf = c["samples/icdf"][:]
check(not np.array_equal(icdf[-1, 1], icdf[-1, donor]), "crep: the rebuilt realization left its donor's trajectory")
PY

# 4. Refusals and the failure limit.
out=$("$mpiexec" -n 1 "${launcher[@]}" "$efdem" --check "$scene" mode=direct ensemble.on_failure=replace 2>&1)
[ $? -eq 2 ] && grep -q "key 'ensemble.on_failure' = 'replace': = replace needs cpi mode" <<< "$out" \
  && echo "PASS: direct + replace is refused" || { echo "$out"; echo "FAIL: direct + replace"; exit 1; }
timeout 300 "$mpiexec" -n 2 "${launcher[@]}" "$efdem" "$scene" mode=direct ensemble.realizations_per_rank=2 \
  output.directory="$work" output.prefix=limit ensemble.on_failure=drop ensemble.max_failures=0 "${fail[@]}" \
  > "$work/limit.log" 2>&1
code=$?
status=$(/usr/bin/python3 -c "import h5py; print(h5py.File('$work/limit.h5', 'r').attrs['end_status'])")
[ $code -eq 3 ] && [[ $status == *"more than ensemble.max_failures = 0"* ]] \
  && echo "PASS: a failure beyond ensemble.max_failures ends the run (exit 3): $status" \
  || { grep -v "^t = " "$work/limit.log"; echo "FAIL: max_failures (exit $code): $status"; exit 1; }
# A rank whose realizations were all dropped keeps the ensemble's time (its clock was frozen:
# the run stopped with "sample times are not strictly increasing").
timeout 300 "$mpiexec" -n 2 "${launcher[@]}" "$efdem" "$scene" mode=cpi run.duration=8 output.directory="$work" \
  output.prefix=rootdrop ensemble.on_failure=drop debug.fail_realization=0 debug.fail_time=2 > "$work/rootdrop.log" 2>&1
code=$?
grep -q "^completed with 1 failure(s): simulated 8 time units" "$work/rootdrop.log" && [ $code -eq 0 ] \
  && echo "PASS: cpi with the root's only realization dropped completes" \
  || { grep -v "^t = " "$work/rootdrop.log"; echo "FAIL: root's realization dropped (exit $code)"; exit 1; }
echo "PASS: failing realizations"
