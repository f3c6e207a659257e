#!/usr/bin/python3
"""The whole demixing (issue 34, item 4): direct ensembles and CPI runs over the whole process,
until the realizations have stopped demixing (U_s = 0.19) or the bed has reached its statistically
steady state (0.41). One folder per case under bench/results/whole_process/<case>/, one result
file per run (the kept groups of its run file, bench/study_runs.py; not committed), skipped when
there; an interrupted run continues from its newest checkpoint.

    /usr/bin/python3 bench/whole_process.py --efdem build/mpi_driver/efdem                 # every case
    /usr/bin/python3 bench/whole_process.py --case demo_u0.19_r4 --only direct_a direct_b   # a part
    /usr/bin/python3 bench/whole_process.py --analyse-only

Each case has three direct ensembles with their own seeds (101, 202, 303: the noise floor from three
pairs) and the CPI runs of its CPI list (seed 404, paired with each other). "Stopped demixing" is
judged per realization as in bench/stop_times.py: a realization whose light-particle ICDF never
moves again by more than 1e-6 d_p (a bed at rest moves by 1e-13).

Cost (AMD EPYC, 2 shared cores, R = 4): a demo-bed direct run of 1,000 units ~50 min; a tall-bed
direct run of 600 units ~2 h.
"""
import argparse
import os
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
import study_runs as sr  # noqa: E402

RESULTS = os.path.join(HERE, "results", "whole_process")
DIRECT = (("direct_a", 101), ("direct_b", 202), ("direct_c", 303))
# The CPI runs: adaptive with the accuracy key (no per-bed tolerance), realizations at rest held
# (cpi.at_rest = hold, the default) and the run ended at the end state (cpi.finish = steady).
ADAPTIVE = {"cpi.projection": "adaptive", "cpi.accuracy": 1.5, "cpi.healing": 10, "cpi.window": 10,
            "cpi.finish": "steady"}
SLOW = {
    "members_hold": {**ADAPTIVE, "cpi.lift": "members"},  # each realization kept apart
    "mean_hold": {**ADAPTIVE, "cpi.lift": "mean"},  # the paper's lift, those at rest held
}
# case: scene, U_s, duration, R, the CPI runs (name: keys beyond the case's own)
CASES = {
    "demo_u0.19_r4": ("demo_bed.cfg", 0.19, 1000.0, 4, SLOW),
}


def runs_of(case):
    """name -> (mode, overrides) of every run of CASE, directs first."""
    scene, us, duration, realizations, cpi = CASES[case]
    base = {"gas_drag.superficial_velocity": us, "run.duration": duration, "cpi.warmup": 10,
            "ensemble.realizations_per_rank": realizations // 2}
    out = {name: ("direct", {**base, "seed": seed}) for name, seed in DIRECT}
    out.update({name: ("cpi", {**base, "seed": 404, **extra}) for name, extra in cpi.items()})
    return out


def make(args, case):
    results = os.path.join(args.results, case)
    work = os.path.join(args.out, case)
    scene = os.path.join(HERE, "scenes", CASES[case][0])
    for name, (mode, overrides) in runs_of(case).items():
        if args.only and name not in args.only:
            continue
        dest = os.path.join(results, name + ".h5")
        if sr.archived(dest):
            print(f"  {case}/{name}: done before, skipped", flush=True)
            continue
        if sr.completed(work, name) or sr.run_case(os.path.abspath(args.efdem), 2, scene, work, name, mode,
                                                   overrides, label=f"{case}/{name}"):
            sr.archive(work, name, dest)


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--efdem", default=os.path.join(HERE, "..", "build", "mpi_driver", "efdem"))
    p.add_argument("--out", default=os.path.join(HERE, "..", "runs", "whole_process"), help="working folder")
    p.add_argument("--results", default=RESULTS)
    p.add_argument("--case", nargs="*", choices=sorted(CASES), help="these cases only (default: all)")
    p.add_argument("--only", nargs="*", help="these runs only")
    p.add_argument("--analyse-only", action="store_true")
    args = p.parse_args()
    if not args.analyse_only:
        for case in args.case or CASES:
            make(args, case)


if __name__ == "__main__":
    main()
