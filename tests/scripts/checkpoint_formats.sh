#!/usr/bin/env bash
# Every checkpoint format this efdem reads restarts a run that continues bit for bit: stored files
# of formats 1, 2 and 3 (tests/data/checkpoint_format_*.h5) and one written now (format 4), each
# restarted on 2 ranks and compared with the uninterrupted run of this binary (compare_runs.py on
# the run file, the CSVs byte for byte). The stored checkpoints hold run files of format 2, which
# the restart upgrades to format 3 (check_run_file.py checks the layout).
#
# The stored files (tests/data/README.md):
#   checkpoint_format_3_adaptive.h5  written by efdem c8ed428 (format 3, before the integrator's
#       state had names): adaptive Adams-Bashforth 2, checkpoint after coarse step 2, right after a
#       rejection (the controller's cap and rejection count are in it);
#   checkpoint_format_3_fixed.h5     the same binary, fixed-DT forward Euler (no integrator
#       state), after coarse step 1;
#   checkpoint_format_2_adaptive.h5, checkpoint_format_1_fixed.h5   derived from those two by
#       derive_old_checkpoint.py (the differences between formats 1, 2 and 3 are three datasets
#       and the checksum's rules; the script says which), not written by an old build.
# Also checked: the format-4 checkpoint this binary writes at the same point as the stored
# format-3 one holds, by name, the values the format-3 file holds by position.
#   checkpoint_formats.sh EFDEM_BINARY MPIEXEC [MPIEXEC_PREFLAGS...]
set -euo pipefail
efdem=$1; mpiexec=$2; shift 2
here=$(cd "$(dirname "$0")" && pwd)
data=$(cd "$here/../data" && pwd)
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
# The stored checkpoints' run files name the scene as tests/scripts/tiny_scene.cfg (their runs
# were started from the repository's top), and the run file records that name: do the same.
cd "$here/../.."
scene=tests/scripts/tiny_scene.cfg

run() {  # run NP LOG ARGS...
  local np=$1 log=$2; shift 2
  timeout 300 "$mpiexec" -n "$np" "$@" > "$log" 2>&1 || { echo "FAIL: run failed ($log):"; cat "$log"; exit 1; }
}

same_output() {  # same_output PREFIX_A PREFIX_B [--ignore DATASET...]
  /usr/bin/python3 "$here/compare_runs.py" "$work/$1.h5" "$work/$2.h5" "${@:3}"
  for csv in _mean_icdf.csv _cpi_steps.csv; do
    [ -f "$work/$1$csv" ] || continue
    if [ $# -gt 2 ] && [ "$csv" = _cpi_steps.csv ]; then
      # The CSV columns of the ignored datasets (cpi/NAME -> column NAME) are left out.
      /usr/bin/python3 - "$work/$1$csv" "$work/$2$csv" "${@:4}" <<'EOF' \
        || { echo "FAIL: $2$csv differs from $1$csv beyond the ignored columns"; exit 1; }
import csv, sys
drop = {name.split("/")[-1] for name in sys.argv[3:]}
def rows(path):
    with open(path) as f:
        lines = [line for line in f if not line.startswith("#")]
    table = list(csv.reader(lines))
    keep = [i for i, name in enumerate(table[0]) if name not in drop]
    return [[row[i] for i in keep] for row in table]
sys.exit(0 if rows(sys.argv[1]) == rows(sys.argv[2]) else 1)
EOF
    else
      cmp -s "$work/$1$csv" "$work/$2$csv" \
        || { echo "FAIL: $2$csv differs from $1$csv"; exit 1; }
    fi
  done
}

# cpi.noisy_curvature = counted, cpi.at_rest = lift, cpi.lift_error = ignored,
# cpi.relabel_nodes = random: what the stored checkpoints' runs did (the rejection in them came
# from a curvature within its noise; they lifted every realization; the lift's error in X was not
# part of a jump's; the colour lift drew every switch at random).
adaptive=(mode=cpi cpi.projection=adaptive cpi.integrator=adams_bashforth2 cpi.tolerance=0.06
          cpi.dt_min=0.5 run.duration=24 cpi.noisy_curvature=counted cpi.at_rest=lift
          cpi.lift_error=ignored cpi.relabel_nodes=random)
fixed=(mode=cpi cpi.at_rest=lift cpi.relabel_nodes=random)
run 2 "$work/adaptive-ref.log" "$@" "$efdem" "$scene" "${adaptive[@]}" ensemble.realizations_per_rank=2 \
  output.directory="$work" output.prefix=adaptive-ref checkpoint.interval=2 checkpoint.keep=10
run 2 "$work/fixed-ref.log" "$@" "$efdem" "$scene" "${fixed[@]}" ensemble.realizations_per_rank=2 \
  output.directory="$work" output.prefix=fixed-ref
now="$work/adaptive-ref_ckpt_00000002.h5"
[ -f "$now" ] || { echo "FAIL: no checkpoint $now"; ls "$work"; exit 1; }

# The named fields written now against the positional layout of the stored format-3 file.
/usr/bin/python3 - "$now" "$data/checkpoint_format_3_adaptive.h5" <<'EOF'
import sys
import h5py
import numpy as np
new, old = h5py.File(sys.argv[1], "r"), h5py.File(sys.argv[2], "r")
assert int(new.attrs["format_version"]) == 4 and int(old.attrs["format_version"]) == 3
g = new["/driver/integrator"]
r = old["/driver/integrator"][()]
decay_message, hold_kind, hold = old["/driver/integrator_text"][()].decode().split("\n", 2)
n, m = int(r[1]), int(r[2])
def same(a, b):
    return np.array_equal(np.asarray(a, dtype=float), np.asarray(b, dtype=float), equal_nan=True)
checks = {
    "t_end": same(g["t_end"][()], [r[3]]),
    "controller/dt_last": same(g["controller/dt_last"][()], [r[4]]),
    "controller/dt_cap": same(g["controller/dt_cap"][()], [r[5]]),
    "controller/consecutive_rejections": int(g["controller/consecutive_rejections"][0]) == r[6],
    "decay/rate,ratio,delay": same([g["decay/rate"][0], g["decay/ratio"][0], g["decay/delay"][0]], r[8:11]),
}
# Since 15fd576 a decay rate within the realizations' noise is kept but marked not ok (it no longer
# halves DT); the format-3 file was written before that. Same rate: the flag and message agree, or
# the new one says why the rate is not used.
new_message = g["decay/message"][()].decode()
checks["decay/ok, message"] = (int(g["decay/ok"][0]) == r[7] and new_message == decay_message) or \
    (int(g["decay/ok"][0]) == 0 and r[7] == 1 and "is not resolved" in new_message)
checks |= {
    "hold_kind": g["hold_kind"][()].decode() == hold_kind,
    "hold": g["hold"][()].decode() == hold,
    "x_end": same(g["x_end"][()], r[11:11 + m]),
}
k = 11 + m
tau, slope, se = [], [], []
for i in range(n):
    tau.append(r[k]); slope.append(r[k + 1:k + 1 + m]); se.append(r[k + 1 + m:k + 1 + 2 * m])
    k += 1 + 2 * m
checks["history/tau"] = same(g["history/tau"][()], tau)
checks["history/slope"] = same(g["history/slope"][()].reshape(n, m), np.reshape(slope, (n, m)))
checks["history/se"] = same(g["history/se"][()].reshape(n, m), np.reshape(se, (n, m)))
names = ["attempts", "accepted", "rejected", "direct", "dt_taken", "dt_tolerance", "dt_tolerance_2r",
         "dt_tolerance_4r", "statistical", "truncation"]
checks["totals"] = same([g["totals/" + x][0] for x in names], r[k:k + 10])
checks["curvature_only_front"] = int(g["curvature_only_front"][0]) == r[k + 10]
bad = [name for name, ok in checks.items() if not ok]
if bad:
    sys.exit("FAIL: the format-4 integrator state differs from the stored format-3 one in " + ", ".join(bad))
print(f"PASS: the format-4 integrator state (named) equals the stored format-3 one (positional): {n} slopes of {m} nodes, "
      f"dt_cap {g['controller/dt_cap'][0]:g}, {int(g['controller/consecutive_rejections'][0])} rejection(s) in a row")
EOF

for spec in "adaptive $now 4" "adaptive $data/checkpoint_format_3_adaptive.h5 3" \
            "adaptive $data/checkpoint_format_2_adaptive.h5 2" \
            "fixed $data/checkpoint_format_3_fixed.h5 3" "fixed $data/checkpoint_format_1_fixed.h5 1"; do
  read -r kind file version <<< "$spec"
  found=$(/usr/bin/python3 -c "import h5py, sys; print(int(h5py.File(sys.argv[1], 'r').attrs['format_version']))" "$file")
  [ "$found" = "$version" ] || { echo "FAIL: $file has format $found, not $version"; exit 1; }
  if [ "$kind" = adaptive ]; then overrides=("${adaptive[@]}"); else overrides=("${fixed[@]}"); fi
  run 2 "$work/$kind-f$version.log" "$@" "$efdem" "$scene" "${overrides[@]}" ensemble.realizations_per_rank=2 \
    output.directory="$work" output.prefix=$kind-f$version restart="$file"
  grep -q "restarted from" "$work/$kind-f$version.log" || { echo "FAIL: no restart in $kind-f$version.log"; exit 1; }
  # The slope pool's and the healing evidence's records (issue 33) came after formats 1-3: the run
  # file stored in such a checkpoint has no rows of them before the restart (they begin with fill
  # rows, checked below). And a format-3 state
  # carries the decay verdict of the code that wrote it (before 15fd576), which assesses the
  # first step's stability from a rate the current code counts as noise: that step's stability
  # record differs, its DT and every sample do not (compared).
  # The window evidence's records (cpi.window_auto), the lift apart's (cpi.lift = own) and the
  # trajectory budget's (cpi.accuracy) and the realizations at rest (each sample's, and the
  # lift's: cpi.at_rest) came after every stored checkpoint.
  ignore=(--ignore cpi/controller/window_noise_ratio cpi/controller/window_noise_correlation
          cpi/controller/window_next cpi/controller/member_step cpi/controller/budget
          cpi/controller/ensemble_standard_error cpi/controller/budget_spent cpi/controller/budget_walk
          cpi/controller/contraction_rate cpi/lift_at_rest cpi/lift_error samples/at_rest)
  [ "$version" = 4 ] || ignore+=(cpi/controller/error_statistical_jump cpi/controller/error_statistical_burst
                                cpi/controller/error_statistical_pool cpi/controller/slope cpi/controller/pooled_bursts
                                cpi/controller/transient cpi/controller/transient_threshold
                                cpi/stability_assessed cpi/stability_rate cpi/stability_amplification)
  same_output $kind-ref $kind-f$version "${ignore[@]}"
  # The run file put back from an older checkpoint is format 2: the restart upgraded it to
  # format 3 (renames, every group's own axes, dimension scales laid anew).
  /usr/bin/python3 "$here/check_run_file.py" "$work/$kind-f$version.h5" --mode cpi \
    || { echo "FAIL: the run file restarted from $(basename "$file") is not a format-3 run file"; exit 1; }
  # The records the old run did not make start with fill rows up to the restart: every ignored
  # dataset has the uninterrupted run's shape, and /samples/at_rest is -1 before the restart and
  # the uninterrupted run's after it.
  [ "$version" = 4 ] || /usr/bin/python3 - "$work/$kind-ref.h5" "$work/$kind-f$version.h5" "${ignore[@]:1}" <<'EOF'
import sys
import h5py
import numpy as np
ref, got = h5py.File(sys.argv[1], "r"), h5py.File(sys.argv[2], "r")
bad = [n for n in sys.argv[3:] if n in ref and n in got and ref[n].shape != got[n].shape]
if bad:
    sys.exit(f"FAIL: {sys.argv[2]}: rows not aligned with their axis in {bad}")
a, b = ref["samples/at_rest"][:], got["samples/at_rest"][:]
filled = np.all(b == -1, axis=1)
k = int(np.argmin(filled)) if not filled.all() else len(b)
if not (0 < k < len(b) and filled[:k].all() and np.array_equal(a[k:], b[k:])):
    sys.exit(f"FAIL: {sys.argv[2]}: /samples/at_rest is not -1 up to the restart and the uninterrupted run's after it")
print(f"PASS: the records the old run did not make are filled up to the restart ({k} of {len(b)} samples)")
EOF
  # The stored checkpoints came before /driver/wall_seconds: the restarted run's wall time is
  # its own process's and says the earlier one is unknown; the one written now carries it.
  /usr/bin/python3 -c "
import h5py, math, sys
a = h5py.File(sys.argv[1], 'r').attrs
resumed = float(a['resumed_wall_seconds'])
assert (math.isnan(resumed) if sys.argv[2] != '4' else 0 < resumed < a['wall_seconds']), (resumed, a['wall_seconds'])" \
    "$work/$kind-f$version.h5" "$version" \
    || { echo "FAIL: $kind-f$version's resumed wall time is not what its checkpoint says"; exit 1; }
  echo "PASS: $kind run restarted from a format-$version checkpoint ($(basename "$file")) equals the uninterrupted run"
done
