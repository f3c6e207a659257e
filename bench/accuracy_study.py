#!/usr/bin/python3
"""One value of cpi.accuracy on beds whose noise differs (issue 34, item 1): adaptive CPI with
cpi.accuracy = 1.5 (the jumps may add 1.5 ensemble standard errors to the trajectory, so the run
should lie about sqrt(1 + 1.5^2 / 2) = 1.46x the noise floor from an independent direct ensemble)
on the demo bed, the tall bed and the paper's bed, against the direct ensembles the earlier
studies made (same beds, own seeds). No per-bed tuning: the same key on every bed.

    /usr/bin/python3 bench/accuracy_study.py --efdem build/mpi_driver/efdem          # make and analyse
    /usr/bin/python3 bench/accuracy_study.py --analyse-only

Resumable (bench/study_runs.py): one result file per run under bench/results/accuracy_study/
(not committed), skipped when there; an interrupted run continues from its newest checkpoint.
The direct ensembles are read from the folders of the studies that made them (regenerate them with
the commands in those folders' analysis.md):
  demo bed, U_s 0.19, 600 units: bench/results/slope_study_r4_u0.19_t600/direct_{a,b,c}.h5
  tall bed, U_s 0.19, 400 units: bench/results/tall_study_r4/u0.19/direct_{a,b}.h5 (one pair: the
      floor is uncertain by ~2x)
  tall bed, U_s 0.41, 200 units: bench/results/tall_study_r4/u0.41/direct_{a,b}.h5 (one pair)
  paper's bed (12,500 spheres), U_s 0.41, 200 units, R = 2 (what fits 2 cores):
      bench/results/paper_check_r2/u0.41/direct_{a,b}.h5 (one pair)
The floor is taken at the CPI run's own samples (it samples only in its bursts; the floor changes
with t), as e is. Rows of runs whose result file is not on this machine stay as an earlier
analysis wrote them (marked).
Cost (AMD EPYC, 2 shared cores): demo 600 units ~15 min, tall 400 units ~40 min, tall 0.41 ~25 min,
paper's bed ~20 min.
"""
import argparse
import json
import math
import os
import sys

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
import slope_study as ss  # noqa: E402
import study_runs as sr  # noqa: E402

sys.path.insert(0, os.path.join(HERE, "..", "scripts"))
import accuracy_metrics as am  # noqa: E402

ACCURACY = 1.5
RESULTS = os.path.join(HERE, "results")
# name: scene, U_s, duration, healing, window, folder of the direct ensembles, realizations (on 2 ranks)
CASES = {
    "demo_acc1.5": ("demo_bed.cfg", 0.19, 600.0, 10, 10, "slope_study_r4_u0.19_t600", 4),
    "tall_acc1.5": ("tall_bed.cfg", 0.19, 400.0, 10, 10, os.path.join("tall_study_r4", "u0.19"), 4),
    "tall41_acc1.5": ("tall_bed.cfg", 0.41, 200.0, 2, 20, os.path.join("tall_study_r4", "u0.41"), 4),
    # The paper's bed as bench/adaptive_study.py --bed paper ran it (bursts 2 + 20, R = 2).
    "paper41_acc1.5": ("reference_bed.cfg", 0.41, 200.0, 2, 20, os.path.join("paper_check_r2", "u0.41"), 2),
}
ORDER = ("demo_acc1.5", "tall_acc1.5", "tall41_acc1.5", "paper41_acc1.5")


def overrides(case):
    _, us, duration, healing, window, _, realizations = CASES[case]
    return {"gas_drag.superficial_velocity": us, "run.duration": duration, "cpi.warmup": 10,
            "cpi.healing": healing, "cpi.window": window, "ensemble.realizations_per_rank": realizations // 2,
            "seed": 404, "cpi.projection": "adaptive", "cpi.accuracy": ACCURACY}


def floor_on(run, a, b):
    """RMS between the direct ensembles A and B over the CPI RUN's samples (that both have)."""
    keep, ya = am.align(a["t"], a["mean"], run["t"])
    return ss.rms_on({"t": run["t"][keep], "mean": ya}, b)


def earlier_rows(results):
    """The table rows and summary an earlier analysis wrote, by run name."""
    rows, summary = {}, {}
    path = os.path.join(results, "analysis.md")
    if os.path.exists(path):
        with open(path) as f:
            for line in f:
                name = line.split("|")[1].strip().rstrip("*") if line.startswith("| ") else ""
                if name in CASES:
                    rows[name] = line.rstrip("\n")
    if os.path.exists(os.path.join(results, "analysis.json")):
        with open(os.path.join(results, "analysis.json")) as f:
            summary = json.load(f)
    return rows, summary


def analyse(results):
    lines = ["# One cpi.accuracy on beds of different noise (issue 34)\n",
             "Made by `/usr/bin/python3 bench/accuracy_study.py --efdem build/mpi_driver/efdem`; adaptive CPI "
             f"with cpi.accuracy = {ACCURACY}, R = 4 (the paper's bed: 2), seed 404, against independent direct "
             f"ensembles. Expected e / floor: sqrt(1 + a^2/2) = {math.sqrt(1 + ACCURACY ** 2 / 2):.2f} "
             "(docs/error_control.md §10). The floor at the CPI run's own samples; rows marked * are an earlier "
             "analysis's (their run file is not on this machine), whose floor was over the directs' every sample.\n",
             "| run | bed, U_s, span | direct ensembles | floor [d_p] (pairs) | e [d_p] | e / floor | sigma [d_p] "
             "| budget [d_p] | spent [d_p] | tolerances per jump [d_p] | kept / rejected / direct | DEM-time speed-up |",
             "|---" * 12 + "|"]
    rows, summary = earlier_rows(results)
    for name in ORDER:
        path = os.path.join(results, name + ".h5")
        if not sr.archived(path):
            if name in rows:
                row = rows[name]
                lines.append(row if row.startswith(f"| {name}*") else row.replace(f"| {name} |", f"| {name}* |", 1))
            continue
        scene, us, duration, _, _, folder, _ = CASES[name]
        directs = [ss.load(os.path.join(RESULTS, folder, d + ".h5")) for d in ("direct_a", "direct_b", "direct_c")
                   if os.path.exists(os.path.join(RESULTS, folder, d + ".h5"))]
        run = ss.load(path)
        pairs = [floor_on(run, directs[i], directs[j]) for i in range(len(directs)) for j in range(i + 1, len(directs))]
        floor = float(np.mean(pairs)) if pairs else float("nan")
        e = math.sqrt(np.mean([ss.rms_on(run, d) ** 2 for d in directs])) if directs else float("nan")
        c = run["controller"]
        status = run["status"]
        kept, rejected, direct = ss.step_counts(run)
        tol = np.asarray(c["tolerance"], float)[[s == "projected" for s in status]]  # of the jumps kept
        tol = tol[np.isfinite(tol)] if len(tol) else np.array([float("nan")])
        last = lambda k: float(np.asarray(c[k], float)[np.isfinite(np.asarray(c[k], float))][-1])  # noqa: E731
        sigma, budget, spent = last("ensemble_standard_error"), last("budget"), last("budget_spent")
        speed = float(run["simulated_time"]) / float(run["dem_time"])
        summary[name] = {"floor_pairs": pairs, "e": e, "e_over_floor": e / floor, "sigma": sigma, "budget": budget,
                         "spent": spent, "speedup_dem": speed, "kept": kept, "rejected": rejected, "direct": direct}
        lines.append(f"| {name} | {scene.split('_')[0]}, {us}, {duration:g} | {len(directs)} | {floor:.3f} ("
                     + ", ".join(f"{p:.3f}" for p in pairs) + f") | {e:.3f} | {e / floor:.2f} | {sigma:.3f} | "
                     f"{budget:.3f} | {spent:.3f} | {tol.min():.3f}-{tol.max():.3f} | {kept} / {rejected} / {direct} "
                     f"| {speed:.2f} |")
    with open(os.path.join(results, "analysis.md"), "w") as f:
        f.write("\n".join(lines) + "\n")
    with open(os.path.join(results, "analysis.json"), "w") as f:
        json.dump(summary, f, indent=1)
    print("\n".join(lines))


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--efdem", default=os.path.join(HERE, "..", "build", "mpi_driver", "efdem"))
    p.add_argument("--out", default=os.path.join(HERE, "..", "runs", "accuracy_study"), help="working folder")
    p.add_argument("--results", default=os.path.join(RESULTS, "accuracy_study"))
    p.add_argument("--only", nargs="*")
    p.add_argument("--analyse-only", action="store_true")
    args = p.parse_args()
    if not args.analyse_only:
        for name in ORDER:
            if args.only and name not in args.only:
                continue
            scene = os.path.join(HERE, "scenes", CASES[name][0])
            sr.ensure(os.path.abspath(args.efdem), 2, scene, args.out, name, "cpi", overrides(name),
                      os.path.join(args.results, name + ".h5"))
    analyse(args.results)


if __name__ == "__main__":
    main()
