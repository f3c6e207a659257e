#!/usr/bin/env bash
# The scripts that read files (scripts/plot_icdf.py, scripts/plot_bed.py, scripts/demo_summary.py,
# scripts/plot_validation.py) on real small run files, also laid out as format 2, and on bad input:
# * good input: exit 0; plot_icdf writes the PNG and names each run's mode and line style, and
#   the CPI run's last projective jump where the run file's /cpi records put it; plot_icdf's and
#   plot_bed's legends name the band (the 95 % Student-t interval of the mean), sit outside the
#   axes, and a run of R = 1 has no band and says so; demo_summary
#   prints its labelled lines, and its numbers are facts of constructed pairs (a CPI file whose
#   means equal the direct ones: RMS 0, 100 % inside; shifted by 1 d_p: RMS 1.000) and of the
#   run file (speed-up = simulated_time / dem_time);
# * bad input (no arguments, a missing file, a file that is not HDF5, an HDF5 file that is not
#   a run file, a run file without samples, the runs in the wrong order, a folder without the
#   validation CSVs, a CSV without its columns): exit 2 and a message naming the problem, no
#   traceback.
#   plot_scripts.sh EFDEM_BINARY MPIEXEC [MPIEXEC_PREFLAGS...]
source "$(dirname "$0")/lib.sh" "$@"
src=$(cd "$here/../.." && pwd)
py=/usr/bin/python3
failures=0
pass() { echo "PASS: $*"; }
fail() { echo "FAIL: $*"; failures=$((failures + 1)); }

# Two small runs of the tiny scene: direct, and cpi with one jump (warm-up 0.5, burst 1.5 to
# t = 2, jump 1.5 to 3.5, last burst to 5); with the bed quantities, for plot_bed.
for mode in direct cpi; do
  "$mpiexec" -n 2 "${launcher[@]}" "$efdem" "$here/tiny_scene.cfg" mode=$mode run.duration=5 observe.bed=true \
    output.directory="$work" output.prefix=$mode > "$work/$mode.log" 2>&1 \
    || { cat "$work/$mode.log"; echo "FAIL: the $mode run"; exit 1; }
done

expect() {  # expect CODE MESSAGE_SUBSTRING DESCRIPTION COMMAND...
  local code=$1 message=$2 what=$3; shift 3
  local out got
  out=$("$@" 2>&1); got=$?
  if [ $got -eq "$code" ] && grep -qF -- "$message" <<< "$out" && ! grep -q Traceback <<< "$out"; then
    pass "$what: exit $got, '$message'"
  else
    fail "$what: exit $got (want $code), output: $(tail -5 <<< "$out")"
  fi
}

# plot_icdf: good input.
expect 0 "line style '--', last projective jump lands at t = 3.5" "plot_icdf direct + cpi" \
  $py "$src/scripts/plot_icdf.py" "$work/direct.h5" "$work/cpi.h5" -o "$work/icdf.png"
[ -s "$work/icdf.png" ] && pass "icdf.png written" || fail "icdf.png not written"
expect 0 "direct: direct.h5 (R = 2, seed 11): line style '-'" "plot_icdf names the direct run" \
  $py "$src/scripts/plot_icdf.py" "$work/direct.h5" -o "$work/direct.png"

# The legends as drawn: the band named, beside the axes (not over them); R = 1: no band, said.
# one.h5 is the direct run cut to its first realization (R = 1, variance 0, as efdem writes it).
$py - "$work" <<'PY' || fail "could not make the R = 1 run file"
import shutil, sys, h5py
w = sys.argv[1]
shutil.copy(f"{w}/direct.h5", f"{w}/one.h5")
with h5py.File(f"{w}/one.h5", "a") as f:
    f.attrs["realizations"] = 1
    f["samples/realizations_used"][...] = 1
    f["samples/variance"][...] = 0.0
    for name in ("height", "pressure_drop_ratio", "mixing_index", "species_height"):
        d = f[f"bed/{name}"][...]
        d[:, 1:] = float("nan")  # the second realization dropped
        f[f"bed/{name}"][...] = d
PY
legends() {  # legends SCRIPT RUN.h5... : one line per legend text, then 'bands: N' and 'covers: ...'
  local script=$1; shift
  $py - "$src/scripts" "$script" "$work/legend.png" "$@" <<'PY'
import sys
sys.path.insert(0, sys.argv[1])
import importlib
import matplotlib.pyplot as plt
mod = importlib.import_module(sys.argv[2])
mod.main(sys.argv[4:] + ["-o", sys.argv[3]])
fig = plt.gcf()
fig.canvas.draw()
for legend in fig.legends:
    print("\n".join(t.get_text() for t in legend.get_texts()))
    lb = legend.get_window_extent()
    for ax in fig.axes:
        ab = ax.get_window_extent()
        if lb.x0 < ab.x1 and ab.x0 < lb.x1 and lb.y0 < ab.y1 and ab.y0 < lb.y1:
            print("covers: an axes")
print("bands:", sum(len(ax.collections) for ax in fig.axes))
PY
}
for script in plot_icdf plot_bed; do
  out=$(legends $script "$work/direct.h5" "$work/cpi.h5" 2>&1)
  grep -qF "band: 95 % Student-t interval of the mean of R realizations" <<< "$out" \
    && pass "$script: the legend names the band" || fail "$script: no band in the legend: $out"
  ! grep -q "covers:" <<< "$out" && grep -q "^bands: [1-9]" <<< "$out" \
    && pass "$script: bands drawn, the legend beside the axes" || fail "$script: legend over the axes or no band: $out"
  out=$(legends $script "$work/one.h5" 2>&1)
  grep -qF "R = 1: no band (one realization has no spread)" <<< "$out" && grep -q "^bands: 0$" <<< "$out" \
    && ! grep -q "^band: " <<< "$out" \
    && pass "$script: R = 1 draws no band and says so" || fail "$script, R = 1: $out"
done
expect 0 "plot_bed.py: wrote $work/bed.png" "plot_bed direct + cpi" \
  $py "$src/scripts/plot_bed.py" "$work/direct.h5" "$work/cpi.h5" -o "$work/bed.png"
[ -s "$work/bed.png" ] && pass "bed.png written" || fail "bed.png not written"

# Bad files, made here: text, HDF5 without the attributes, a run file without /samples/mean.
echo "not a run file" > "$work/text.h5"
$py - "$work" <<'PY' || fail "could not make the bad HDF5 files"
import shutil, sys, h5py
w = sys.argv[1]
with h5py.File(f"{w}/other.h5", "w") as f:
    f["x"] = [1.0]
shutil.copy(f"{w}/direct.h5", f"{w}/nosamples.h5")
with h5py.File(f"{w}/nosamples.h5", "a") as f:
    del f["samples/mean_icdf"]
PY
expect 2 "required: runs" "plot_icdf without arguments" $py "$src/scripts/plot_icdf.py"
expect 2 "missing.h5: no such file" "plot_icdf, missing file" $py "$src/scripts/plot_icdf.py" "$work/missing.h5"
expect 2 "text.h5: not an HDF5 file" "plot_icdf, text file" $py "$src/scripts/plot_icdf.py" "$work/text.h5"
expect 2 "other.h5: an HDF5 file but not an efdem run file" "plot_icdf, other HDF5" \
  $py "$src/scripts/plot_icdf.py" "$work/other.h5"
expect 2 "nosamples.h5: the run file has no /samples/mean_icdf" "plot_icdf, no samples" \
  $py "$src/scripts/plot_icdf.py" "$work/nosamples.h5"
expect 2 "cannot be written" "plot_icdf, output folder missing" \
  $py "$src/scripts/plot_icdf.py" "$work/direct.h5" -o "$work/no/such/folder/x.png"

# demo_summary: the real pair, then constructed pairs whose answers are known.
out=$($py "$src/scripts/demo_summary.py" "$work/direct.h5" "$work/cpi.h5" 2>&1); code=$?
for line in "RMS difference of the ensemble means" "inside the direct ensemble's 95 % Student-t interval of its mean" \
            "inside Welch's 95 % Student-t interval of the difference" "DEM-time speed-up of CPI (simulated / DEM time)" \
            "wall-time ratio direct / CPI" "noise floor of this comparison" "1 projective jump(s) kept, 0 rejected"; do
  [ $code -eq 0 ] && grep -qF "$line" <<< "$out" && pass "demo_summary: '$line'" || fail "demo_summary lacks '$line': $out"
done
# The speed-up is simulated / DEM time of the cpi file, printed to 2 decimals.
want=$($py -c "import h5py, sys; f = h5py.File(sys.argv[1]); print(f'{f.attrs[\"simulated_time\"] / f.attrs[\"dem_time\"]:.2f}x')" "$work/cpi.h5")
grep -qF "speed-up of CPI (simulated / DEM time) $want" <<< "$out" && pass "speed-up $want" || fail "speed-up is not $want: $out"
$py - "$work" <<'PY' || fail "could not make the constructed pairs"
import shutil, sys, h5py
w = sys.argv[1]
for name, shift in (("same", 0.0), ("shifted", 1.0)):
    shutil.copy(f"{w}/direct.h5", f"{w}/{name}.h5")
    with h5py.File(f"{w}/{name}.h5", "a") as f:
        f.attrs["mode"] = "cpi"
        f["samples/mean_icdf"][...] = f["samples/mean_icdf"][...] + shift
# A CPI file of a longer span than the direct run's (the old quick start's 40 against 100).
shutil.copy(f"{w}/cpi.h5", f"{w}/longer.h5")
with h5py.File(f"{w}/longer.h5", "a") as f:
    f.attrs["simulated_time"] = f.attrs["simulated_time"] + 2.5
# The floor of two copies of one ensemble: sqrt(2) se, its RMS over the points.
import numpy as np
with h5py.File(f"{w}/direct.h5", "r") as f:
    se2 = f["samples/variance"][:] / f.attrs["realizations"]
print(f"{np.sqrt(np.mean(2 * se2)):.3f}", file=open(f"{w}/floor.txt", "w"))
PY
# Equal means: every difference is 0 (<= any band); shifted by 1 d_p everywhere: RMS exactly 1.
expect 0 "RMS difference of the ensemble means (CPI - direct): 0.000 d_p" "demo_summary, equal means" \
  $py "$src/scripts/demo_summary.py" "$work/direct.h5" "$work/same.h5"
expect 0 "95 % Student-t interval of its mean: 100 % of points" "demo_summary, equal means inside" \
  $py "$src/scripts/demo_summary.py" "$work/direct.h5" "$work/same.h5"
# R = 2 and 2: an exact CPI's mean is inside the direct interval at 2 P(|t_1| <= 12.706 / sqrt 2) - 1.
expect 0 "(an exact CPI with independent seeds and equal spread: 93 %)" "demo_summary, exact share for R = 2" \
  $py "$src/scripts/demo_summary.py" "$work/direct.h5" "$work/same.h5"
# A direct run of one realization has no interval: said, not a share of 0 or 100 %.
expect 0 "interval of its mean: no interval (R = 1: one realization has no spread)" "demo_summary, R = 1" \
  $py "$src/scripts/demo_summary.py" "$work/one.h5" "$work/cpi.h5"
expect 0 "RMS difference of the ensemble means (CPI - direct): 1.000 d_p" "demo_summary, shifted by 1" \
  $py "$src/scripts/demo_summary.py" "$work/direct.h5" "$work/shifted.h5"
# The floor: the same ensemble twice has sqrt(2) times one's standard error at every point.
expect 0 "two exact independent ensembles of these sizes, from their own spread): $(cat "$work/floor.txt") d_p" \
  "demo_summary, the floor of an ensemble compared with itself" $py "$src/scripts/demo_summary.py" "$work/direct.h5" "$work/same.h5"
# Different spans: refused, both spans named.
expect 2 "their wall times and costs compare only over equal spans" "demo_summary, unequal spans" \
  $py "$src/scripts/demo_summary.py" "$work/direct.h5" "$work/longer.h5"
expect 2 "expected 2 arguments" "demo_summary without arguments" $py "$src/scripts/demo_summary.py"
expect 2 "cpi.h5: a cpi run; expected the direct run here" "demo_summary, runs swapped" \
  $py "$src/scripts/demo_summary.py" "$work/cpi.h5" "$work/direct.h5"
expect 2 "missing.h5: no such file" "demo_summary, missing file" \
  $py "$src/scripts/demo_summary.py" "$work/direct.h5" "$work/missing.h5"

# Run files of format 2 (written before format 3, e.g. those kept in bench/results): the two runs
# laid out as format 2 did (/samples/mean, /bed/mean, no group-local axes) read the same: the
# summary prints the same lines, the plots are drawn.
$py - "$work" <<'PY' || fail "could not make the format-2 run files"
import shutil, sys, h5py
w = sys.argv[1]
for mode in ("direct", "cpi"):
    shutil.copy(f"{w}/{mode}.h5", f"{w}/{mode}_f2.h5")
    with h5py.File(f"{w}/{mode}_f2.h5", "a") as f:
        f.attrs["format_version"] = 2
        f.move("samples/mean_icdf", "samples/mean")
        f.move("bed/ensemble_mean", "bed/mean")
        for name in ("samples/p", "samples/realization", "samples/compact_parameter", "bed/time", "bed/realization",
                     "bed/mean/time", "bed/mean/z", "bed/mean/species", "cpi/realization"):
            if name in f:
                del f[name]
PY
new=$($py "$src/scripts/demo_summary.py" "$work/direct.h5" "$work/cpi.h5" 2>&1 | grep -v "wall")
old=$($py "$src/scripts/demo_summary.py" "$work/direct_f2.h5" "$work/cpi_f2.h5" 2>&1 | grep -v "wall")
[ -n "$old" ] && [ "$old" = "$new" ] && pass "demo_summary reads format 2: the same summary"   || fail "demo_summary of the format-2 files differs: $old"
expect 0 "line style '--', last projective jump lands at t = 3.5" "plot_icdf, format 2"   $py "$src/scripts/plot_icdf.py" "$work/direct_f2.h5" "$work/cpi_f2.h5" -o "$work/icdf_f2.png"
expect 0 "plot_bed.py: wrote $work/bed_f2.png" "plot_bed, format 2"   $py "$src/scripts/plot_bed.py" "$work/direct_f2.h5" "$work/cpi_f2.h5" -o "$work/bed_f2.png"

# plot_validation: no arguments, no folder, a folder without its CSVs, a CSV without its columns.
mkdir -p "$work/empty" "$work/bad"
printf 'a,b\n1,2\n' > "$work/bad/dp_sweep_light.csv"
expect 2 "expected 2 arguments" "plot_validation without arguments" $py "$src/scripts/plot_validation.py"
expect 2 "not a folder" "plot_validation, missing folder" $py "$src/scripts/plot_validation.py" "$work/nope" "$work/fig"
expect 2 "no validation CSV files in" "plot_validation, empty folder" \
  $py "$src/scripts/plot_validation.py" "$work/empty" "$work/fig"
expect 2 "dp_sweep: a CSV in" "plot_validation, malformed CSV" \
  $py "$src/scripts/plot_validation.py" "$work/bad" "$work/fig"

[ $failures -eq 0 ] || { echo "$failures failure(s)"; exit 1; }
