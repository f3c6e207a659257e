#!/usr/bin/python3
"""Do CPI's lifts keep beds from coming to rest (issue 34, item 2)? At U_s = 0.19 every direct
realization of the demo bed comes to rest (after 277-801 time units), no CPI realization ever has
(44 realizations, up to 640 units of DEM time each, 2026-12-05). Two explanations: (a) a bed must
run for so long in the DEM before it can freeze, and CPI runs a third of the time; (b) the lifts
(a relabelling of 30-60 particles per realization per jump) kick a bed that is about to freeze back
into motion. This study lifts as CPI does but jumps little or not at all, so that the DEM time is
nearly the simulated time: fixed DT = 0.5, 5 and 20 after bursts of 10 + 10, the lift of the
whole-process study (members, relabelling where the beds move), the initial beds of the direct
ensemble of seed 101 (bench/whole_process.py direct_a: stops at t = 277, 494, 525, 801), 600 units.
If beds come to rest under small lifts as often as direct ones that ran as long, (b) needs lifts
beyond a size; if not even DT = 0.5 lets them, any lift keeps a bed moving.

    /usr/bin/python3 bench/lift_kicks.py --efdem build/mpi_driver/efdem        # resumable
    /usr/bin/python3 bench/lift_kicks.py --analyse-only

One result file per run under bench/results/lift_kicks/ (not committed), skipped when there;
analysis.md there. About 10-15 min per run on 2 idle cores (R = 4).
"""
import argparse
import math
import os
import sys

import h5py
import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
import study_runs as sr  # noqa: E402
import whole_process as wp  # noqa: E402

RESULTS = os.path.join(HERE, "results", "lift_kicks")
DIRECT = os.path.join(HERE, "results", "whole_process", "demo_u0.19_r4", "direct_a.h5")
BASE = {"gas_drag.superficial_velocity": 0.19, "run.duration": 600.0, "ensemble.realizations_per_rank": 2,
        "seed": 101, "cpi.warmup": 10, "cpi.projection": "fixed", "cpi.healing": 10, "cpi.window": 10,
        "cpi.lift": "members", "cpi.relabel": "moving", "cpi.finish": "at_rest"}
RUNS = {f"dt{dt:g}": {**BASE, "cpi.dt": dt} for dt in (0.5, 5.0, 20.0)}


def labels_per_lift(path):
    """Labels changed per realization per lift (/cpi/lift_changed, mean over the lifts made)."""
    with h5py.File(path, "r") as f:
        n = f["cpi/lift_changed"][:] if "cpi/lift_changed" in f else np.zeros((0, 1))
    n = n[n.sum(axis=1) > 0]  # coarse steps that lifted
    return float(n.mean()) if n.size else 0.0


def earlier_rows(path):
    """The table rows of an earlier analysis.md, by their first cell: a run whose archive is not
    on this machine keeps the row it was measured with."""
    rows = {}
    if os.path.exists(path):
        with open(path) as f:
            for line in f:
                cells = line.split("|")
                if line.startswith("| ") and len(cells) > 6 and not cells[1].strip().startswith(("run", "---")):
                    rows[cells[1].strip()] = line.rstrip("\n")
    return rows


def analyse(args):
    lines = ["# Do lifts keep beds from coming to rest? (issue 34)\n",
             "Made by `/usr/bin/python3 bench/lift_kicks.py --efdem build/mpi_driver/efdem` (runs) and "
             "`--analyse-only`. Demo bed, U_s = 0.19, R = 4, seed 101 (the initial beds of the direct "
             "ensemble direct_a of bench/whole_process.py), bursts 10 + 10, `cpi.lift = members`, "
             "`cpi.relabel = moving`, fixed DT, 600 units.\n",
             "| run | DEM time per realization | labels changed per realization per lift | realizations at rest "
             "(since) | stopped demixing (since) | direct realizations stopped by that DEM time |",
             "|---|---|---|---|---|---|"]
    earlier = earlier_rows(os.path.join(args.results, "analysis.md"))
    direct = wp.load_archive(DIRECT) if sr.archived(DIRECT) else None
    quiet_direct = wp.demixing_stops(direct) if direct else []
    if direct:
        lines.append(f"| direct_a (no lift) | {float(direct['t'][-1]):g} | 0 | "
                     + ", ".join("moving" if not np.isfinite(x) else f"{x:g}" for x in wp.stops(direct))
                     + " | " + ", ".join("moving" if not np.isfinite(x) else f"{x:g}" for x in quiet_direct)
                     + " | - |")
    elif "direct_a (no lift)" in earlier:  # its archive is gone: the row and stops measured before
        lines.append(earlier["direct_a (no lift)"])
        quiet_direct = [float(x) if x.strip() != "moving" else math.nan
                        for x in earlier["direct_a (no lift)"].split("|")[5].split(",")]
    for name in RUNS:
        path = os.path.join(args.results, name + ".h5")
        if not sr.archived(path):
            if name in earlier:  # made before, its archive not on this machine
                lines.append(earlier[name])
            continue
        run = wp.load_archive(path)
        dem = float(run["dem_time"])
        st, qt = wp.stops(run), wp.demixing_stops(run)
        by = sum(1 for q in quiet_direct if np.isfinite(q) and q <= dem)
        lines.append(f"| {name} | {dem:g} | {labels_per_lift(path):.1f} | {int(np.isfinite(st).sum())} of {len(st)} ("
                     + ", ".join("moving" if not np.isfinite(x) else f"{x:g}" for x in st) + f") | "
                     f"{int(np.isfinite(qt).sum())} of {len(qt)} ("
                     + ", ".join("moving" if not np.isfinite(x) else f"{x:g}" for x in qt) + f") | {by} of "
                     f"{len(quiet_direct)} |")
    os.makedirs(args.results, exist_ok=True)
    with open(os.path.join(args.results, "analysis.md"), "w") as f:
        f.write("\n".join(lines) + "\n")
    print("\n".join(lines))


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--efdem", default=os.path.join(HERE, "..", "build", "mpi_driver", "efdem"))
    p.add_argument("--out", default=os.path.join(HERE, "..", "runs", "lift_kicks"), help="working folder")
    p.add_argument("--results", default=RESULTS)
    p.add_argument("--only", nargs="*", help="these runs only")
    p.add_argument("--analyse-only", action="store_true")
    args = p.parse_args()
    if not args.analyse_only:
        scene = os.path.join(HERE, "scenes", "demo_bed.cfg")
        for name, overrides in RUNS.items():
            if args.only and name not in args.only:
                continue
            sr.ensure(os.path.abspath(args.efdem), 2, scene, args.out, name, "cpi", overrides,
                      os.path.join(args.results, name + ".h5"))
    analyse(args)


if __name__ == "__main__":
    main()
