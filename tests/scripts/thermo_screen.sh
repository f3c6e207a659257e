#!/usr/bin/env bash
# The ensemble's thermo line (docs/output.md, "Thermo on the screen"), on real DEM ensembles of
# 4 realizations on 2 ranks x 2, output.thermo_interval = 0.5, samples every 0.25:
#  1. direct: the header once, then a line at t = 0.5, 1, ..., 3, on the screen and the same lines
#     in PREFIX_log.txt; each line's numbers are those of the realizations' own thermo logs
#     (PREFIX_rNNNN_thermo.csv) at that time: mean KE per particle (trans + rot), mean contacts
#     per particle, the largest overlap, mean neighbour-list builds. Tolerance: the line prints
#     4-5 significant digits, so relative 2e-4 (KE, overlap: %.4e) and absolute 1e-4 (contacts,
#     %.4f) and 0.05 (builds, %.1f) hold for the right numbers, while the wrong statistic (mean
#     overlap for the largest, one realization for the mean) differs by far more on a fluidized
#     bed whose realizations differ (checked: the four realizations' KE are not all equal);
#  2. cpi: the lines' times increase strictly (a redone burst prints nothing twice), and every
#     line but the first comes at least one interval after the previous one.
#   thermo_screen.sh EFDEM_BINARY MPIEXEC [MPIEXEC_PREFLAGS...]
source "$(dirname "$0")/lib.sh" "$@"
for mode in direct cpi; do
  timeout 300 "$mpiexec" -n 2 "${launcher[@]}" "$efdem" "$here/tiny_scene.cfg" mode=$mode run.duration=3 \
    ensemble.realizations_per_rank=2 output.thermo_interval=0.5 output.directory="$work" \
    output.prefix=$mode > "$work/$mode.log" 2>&1 || { cat "$work/$mode.log"; echo "FAIL: the $mode run failed"; exit 1; }
done
/usr/bin/python3 - "$work" <<'PY'
import csv, glob, os, sys
work = sys.argv[1]
fail = 0
def check(ok, what):
    global fail
    print(("PASS: " if ok else "FAIL: ") + what)
    fail += 0 if ok else 1

def thermo_lines(path):
    lines = open(path).read().splitlines()
    heads = [i for i, l in enumerate(lines) if l.split()[:2] == ["Time", "KinEng/N"]]
    rows = []
    for l in lines[heads[0] + 1:] if heads else []:
        parts = l.split()
        try:
            rows.append([float(p) for p in parts])
        except ValueError:
            continue
        if len(parts) != 6: rows.pop()
    return len(heads), rows

for mode in ["direct", "cpi"]:
    heads, screen = thermo_lines(os.path.join(work, f"{mode}.log"))
    check(heads == 1, f"{mode}: one thermo header on the screen ({heads})")
    heads_log, logged = thermo_lines(os.path.join(work, f"{mode}_log.txt"))
    check(heads_log == 1 and logged == screen, f"{mode}: the log file holds the same {len(screen)} lines")
    times = [r[0] for r in screen]
    if mode == "direct":
        check(times == [0.5 * k for k in range(1, 7)], f"direct: lines at t = 0.5, 1, ..., 3 ({times})")
        logs = sorted(glob.glob(os.path.join(work, "direct_r*_thermo.csv")))
        check(len(logs) == 4, f"direct: four realization thermo logs ({len(logs)})")
        per = [list(csv.DictReader(open(p))) for p in logs]
        kes_differ = False
        for line in screen:
            t = line[0]
            rows = [next(r for r in rs if abs(float(r["time"]) - t) < 1e-9) for rs in per]
            ke = [float(r["ke_trans_per_particle"]) + float(r["ke_rot_per_particle"]) for r in rows]
            kes_differ |= max(ke) > 1.01 * min(ke)
            want = [sum(ke) / 4, sum(float(r["contacts_per_particle"]) for r in rows) / 4,
                    max(float(r["max_overlap"]) for r in rows),
                    sum(float(r["neighbor_builds"]) for r in rows) / 4, 4]
            got = line[1:]
            ok = (abs(got[0] - want[0]) <= 2e-4 * want[0] and abs(got[1] - want[1]) <= 1e-4
                  and abs(got[2] - want[2]) <= 2e-4 * want[2] + 1e-12 and abs(got[3] - want[3]) <= 0.05
                  and got[4] == 4)
            check(ok, f"direct t = {t}: line {got} = the realizations' logs {[float(f'{w:.5g}') for w in want]}")
        check(kes_differ, "direct: the realizations' KE differ (so a mean is not one realization's value)")
    else:
        check(len(times) >= 3 and all(b > a for a, b in zip(times, times[1:])),
              f"cpi: {len(times)} lines, times increasing ({times})")
        check(all(b - a >= 0.5 - 1e-9 for a, b in zip(times, times[1:])),
              "cpi: at least one interval between lines")
sys.exit(1 if fail else 0)
PY
