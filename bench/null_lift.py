#!/usr/bin/python3
"""Is the tall bed's slowness after a lift (bench/results/lift_velocity.md) the lift's relabelling,
or the jump? Lifts with (almost) no jump: projective steps of DT = 3 (each realization's own
lower nodes move 0.2 d_p), bursts 2 + 20 from t = 100 (the warm-up), on the tall bed at U_s = 0.41,
R = 4, seed 404, rank coordinates as the CPI runs of bench/whole_process.py's tall_u0.41_r8:

* `members_dt3`: each realization moved by the jump's increment (cpi.lift = members): few labels
  change, about what 0.2 d_p of each node needs;
* `mean_dt3`: every realization lifted to the projected mean (cpi.lift = mean, the lift of the
  tall-bed CPI runs): the realizations' spread (0.7-0.95 d_p in the lower nodes) is relabelled away;
* `mean_dt3_clustered`: the same lift with cpi.relabel = clustered (new lights where lights are);
* `mean_dt3_like`: with cpi.relabel = like_lights (new lights with the lights' neighbourhoods).

Each is compared burst by burst with the three direct ensembles of tall_u0.41_r8 (their committed
reductions), as in bench/lift_velocity.py. One result file per run (bench/results/null_lift/, its
reduction committed), skipped when there.

    /usr/bin/python3 bench/null_lift.py --efdem build/mpi_driver/efdem      # make what is missing
    /usr/bin/python3 bench/null_lift.py --analyse-only

Cost (AMD EPYC, 2 cores): 27-33 min a run beside another study (2026-12-06); the warm-up to t = 100
is a third of it.
"""
import argparse
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import lift_velocity as lv  # noqa: E402
import whole_process as wp  # noqa: E402

HERE = os.path.dirname(os.path.abspath(__file__))
RESULTS = os.path.join(HERE, "results", "null_lift")
DIRECTS = os.path.join(HERE, "results", "whole_process", "tall_u0.41_r8")
BASE = {"gas_drag.superficial_velocity": 0.41, "seed": 404, "ensemble.realizations_per_rank": 2,
        "cpi.observable": "ranks", "cpi.projection": "fixed", "cpi.dt": 3, "cpi.healing": 2,
        "cpi.window": 20, "cpi.warmup": 100, "run.duration": 300}
RUNS = {
    "members_dt3": {**BASE, "cpi.lift": "members"},
    "mean_dt3": {**BASE, "cpi.lift": "mean"},
    # mean_dt3 with the lift drawing its new lights where lights are (bench/results/lift_clusters.md)
    "mean_dt3_clustered": {**BASE, "cpi.lift": "mean", "cpi.relabel": "clustered"},
    # clustered overshoots (the tall CPI run's lower nodes ahead): new lights with the lights'
    # neighbourhoods, lights removed at random
    "mean_dt3_like": {**BASE, "cpi.lift": "mean", "cpi.relabel": "like_lights"},
}


LAG_TIMES = (100.0, 150.0, 200.0, 250.0, 295.0)


def lag_table():
    directs = [lv.load(DIRECTS, n)[:2] for n in ("direct_a", "direct_b", "direct_c")]
    td, dm = directs[0][0], np.mean([mean for _, mean in directs], axis=0)

    def nearest(times, t):
        return int(np.argmin(np.abs(times - t)))

    def cell(x, ref):
        return f"{(x - ref)[lv.LOWER].mean():+.2f} / {(x - ref).mean():+.2f}"
    lines = ["| run | " + " | ".join(f"t = {t:g}" for t in LAG_TIMES) + " |", "|---" * (len(LAG_TIMES) + 1) + "|"]
    for name in RUNS:
        if not os.path.exists(os.path.join(RESULTS, name + ".json")):
            continue
        t_run, mean, _ = lv.load(RESULTS, name)
        row = [cell(mean[i], dm[nearest(td, t_run[i])]) for i in (nearest(t_run, t) for t in LAG_TIMES)]
        lines.append(f"| {name} | " + " | ".join(row) + " |")
    a, b = directs[0][1], directs[1][1]
    lines.append("| direct_a - direct_b | " + " | ".join(
        cell(a[nearest(td, t)], b[nearest(td, t)]) for t in LAG_TIMES) + " |")
    return lines


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--efdem", default="build/mpi_driver/efdem")
    ap.add_argument("--out", default="runs/null_lift", help="where the run files go (not in git)")
    ap.add_argument("--only", nargs="*")
    ap.add_argument("--analyse-only", action="store_true")
    args = ap.parse_args()
    os.makedirs(RESULTS, exist_ok=True)
    if not args.analyse_only:
        wp.make_runs(args.efdem, os.path.join(HERE, "scenes", "tall_bed.cfg"),
                     {name: ("cpi", overrides) for name, overrides in RUNS.items()}, RESULTS, args.out,
                     args.only, "null_lift")
    lines = [f"Made by `/usr/bin/python3 bench/null_lift.py {' '.join(sys.argv[1:])}`.", "",
             "The lower light nodes' slope (p = 0.05-0.30) in each burst after a lift of DT = 3, "
             "minus the three direct ensembles' (tall_u0.41_r8) over the same times:", ""]
    lines += lv.deficit_table(DIRECTS, list(RUNS), runs_folder=RESULTS)
    lines += ["", "Where that leaves the runs: their ensemble-mean ICDF minus the three directs' (mean over the "
              "lower nodes p = 0.05-0.30 / over all 19) [d_p]; the last row, direct_a - direct_b (R = 8 each):", ""]
    lines += lag_table()
    text = "\n".join(lines) + "\n"
    print(text)
    with open(os.path.join(RESULTS, "analysis.md"), "w") as f:
        f.write(text)


if __name__ == "__main__":
    main()
