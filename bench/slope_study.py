#!/usr/bin/python3
"""Where the slope's noise goes over a long slow demixing (issue 33): adaptive CPI with the last
burst's slope, with pooled slopes (cpi.slope = pooled), with bursts whose healing is cut to what
the evidence asks for, and with either lift (cpi.lift = mean | members), against THREE direct
ensembles with their own seeds, so that the noise floor has an error bar of its own. Demo bed
(1,000 spheres), warm-up 10. Resumable: one result file per run under --results (not committed:
study run files stay out of git), a run whose result is there is not repeated.

    /usr/bin/python3 bench/slope_study.py --efdem build/mpi_driver/efdem                 # U_s 0.19, R 4, 600 units
    /usr/bin/python3 bench/slope_study.py --us 0.41 --realizations 8 --duration 200
    /usr/bin/python3 bench/slope_study.py --us 0.19 --realizations 8 --duration 200
    /usr/bin/python3 bench/slope_study.py ... --analyse-only

Results go to bench/results/slope_study_r<R>_u<U_s>_t<duration>/ unless --results says otherwise.
The direct runs of bench/adaptive_study.py (same bed, seeds 101 and 202, 200 units) can be copied
into that folder as direct_a.h5 and direct_b.h5: they are not repeated then.

Runs, in the order they are made (the CPI runs share seed 404: paired, their differences are the
estimator's and the lift's, not the seeds'):

  direct_a, direct_b, direct_c   mode=direct, seeds 101, 202, 303
 U_s = 0.19 (tolerance 0.16 d_p per jump):
  burst_h10w10     cpi.slope = burst, healing 10 + window 10 (the studies so far)
  burst_h2w18      cpi.slope = burst, healing 2 + window 18 (the same burst, the slope from 90 % of it)
  pooled_h10w10    cpi.slope = pooled, cpi.pool = 4, healing 10 + window 10
  auto_h10w10      cpi.healing_auto = true, burst 20 (healing 10 while a post-lift transient shows, else 2)
  members_h10w10, members_pooled_h10w10   burst_h10w10 and pooled_h10w10 with cpi.lift = members
  autowindow_h10w10  cpi.healing_auto and cpi.window_auto: healing and window from evidence
  quiet_h10w10     burst_h10w10 with cpi.noisy_curvature = ignored (every other run: counted, what
                   the runs made before the key did)
  own_h10w10       burst_h10w10 with cpi.lift = own (each realization jumps with its own slope)
  ranks_h10w10     burst_h10w10 with cpi.observable = ranks (each light node's rank in its own bed)
 U_s = 0.41 (tolerance 0.32 d_p per jump, the one that jumps at all in bench/adaptive_study.py;
 healing 2 + window 20: two wave periods, T ~ 9):
  burst_h2w20, pooled_h2w20, members_h2w20, members_pooled_h2w20
  autowindow_h2w20, quiet_h2w20   burst_h2w20 with cpi.window_auto (whole periods kept) and with
                   cpi.noisy_curvature = ignored

Error of a CPI run against the direct ensembles: e_j = RMS(X - D_j) over the CPI run's samples and
the 19 nodes; e^2 = mean_j e_j^2. The floor: RMS(D_i - D_j) for the three pairs (mean, and the
spread of the three). A CPI ensemble as good as a fourth direct one has E[e^2] = floor^2. Both are
also given per quarter of the run, where the accumulated jump noise shows as a growth. Speed-up:
simulated time / DEM time per realization (run attributes), and the wall time of the mean direct
run over the CPI run's.
Cost (AMD EPYC, 2 cores): a direct run of 600 units about 20-30 min, a CPI run a third of that.
"""
import argparse
import json
import math
import os
import sys

import h5py
import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, "..", "scripts"))
import accuracy_metrics as am  # noqa: E402
import run_files  # noqa: E402

sys.path.insert(0, HERE)
import study_runs as sr  # noqa: E402

SCENE = os.path.join(HERE, "scenes", "demo_bed.cfg")
DIRECT = (("direct_a", 101), ("direct_b", 202), ("direct_c", 303))
POOLED = {"cpi.slope": "pooled", "cpi.pool": 4}
MEMBERS = {"cpi.lift": "members"}
# Every run before cpi.noisy_curvature counted a curvature within its noise: say so, so that the
# runs stay comparable whatever the default.
SLOW = {"cpi.projection": "adaptive", "cpi.tolerance": 0.16, "cpi.healing": 10, "cpi.window": 10,
        "cpi.noisy_curvature": "counted"}
WAVES = {"cpi.projection": "adaptive", "cpi.tolerance": 0.32, "cpi.healing": 2, "cpi.window": 20,
         "cpi.noisy_curvature": "counted"}
CPI_BY_US = {
    0.19: (
        ("burst_h10w10", SLOW),
        ("burst_h2w18", {**SLOW, "cpi.healing": 2, "cpi.window": 18}),
        ("pooled_h10w10", {**SLOW, **POOLED}),
        ("auto_h10w10", {**SLOW, "cpi.healing_auto": "true"}),
        ("members_h10w10", {**SLOW, **MEMBERS}),
        ("members_pooled_h10w10", {**SLOW, **POOLED, **MEMBERS}),
        ("autowindow_h10w10", {**SLOW, "cpi.healing_auto": "true", "cpi.window_auto": "true"}),
        ("quiet_h10w10", {**SLOW, "cpi.noisy_curvature": "ignored"}),
        ("own_h10w10", {**SLOW, "cpi.lift": "own"}),
        ("ranks_h10w10", {**SLOW, "cpi.observable": "ranks"}),
    ),
    0.41: (
        ("burst_h2w20", WAVES),
        ("pooled_h2w20", {**WAVES, **POOLED}),
        ("members_h2w20", {**WAVES, **MEMBERS}),
        ("members_pooled_h2w20", {**WAVES, **POOLED, **MEMBERS}),
        ("autowindow_h2w20", {**WAVES, "cpi.window_auto": "true"}),
        ("quiet_h2w20", {**WAVES, "cpi.noisy_curvature": "ignored"}),
    ),
}
# Made in this order at U_s = 0.19: the first direct ensemble, the two burst variants (the most
# informative pair), the second and third direct ensembles (the floor with an error bar), pooled,
# evidence-sized healing, the members' lift. At 0.41: the directs first, then the CPI runs.
ORDER_BY_US = {
    0.19: ("direct_a", "burst_h2w18", "burst_h10w10", "ranks_h10w10", "direct_b", "direct_c", "pooled_h10w10",
           "auto_h10w10", "members_h10w10", "members_pooled_h10w10", "autowindow_h10w10", "quiet_h10w10",
           "own_h10w10"),
    0.41: ("direct_a", "direct_b", "direct_c", "burst_h2w20", "pooled_h2w20", "members_h2w20",
           "members_pooled_h2w20", "autowindow_h2w20", "quiet_h2w20"),
}
# Set from the command line in main(): the study's U_s, horizon, CPI runs and their order.
DURATION = 600.0
CPI = CPI_BY_US[0.19]
ORDER = ORDER_BY_US[0.19]
QUARTERS = []


def configure(us, duration):
    global DURATION, CPI, ORDER, QUARTERS
    DURATION, CPI, ORDER = duration, CPI_BY_US[us], ORDER_BY_US[us]
    QUARTERS = [(DURATION * k / 4, DURATION * (k + 1) / 4) for k in range(4)]


def specs(realizations, np_, us):
    base = {"gas_drag.superficial_velocity": us, "run.duration": DURATION, "cpi.warmup": 10,
            "ensemble.realizations_per_rank": realizations // np_}
    # The direct runs also record the bed (observe.bed: every realization's solid-fraction
    # profile, i.e. its whole-bed height distribution), from which the light quantiles' ranks in
    # the whole bed can be measured as a coordinate (direct_a was made before this was added).
    out = {name: ("direct", seed, {**base, "observe.bed": "true"}) for name, seed in DIRECT}
    out.update({name: ("cpi", 404, {**base, **extra}) for name, extra in CPI})
    return out


def result(args, name):
    return os.path.join(args.results, name + ".h5")


def load(path):
    with h5py.File(path, "r") as f:
        d = {k: sr.text(v) if isinstance(v, (bytes, str)) else v for k, v in f.attrs.items()}
        d["t"] = f["samples/time"][:]
        d["mean"] = run_files.get(f, "samples/mean_icdf")[:]
        if "cpi/controller" in f:
            c = f["cpi/controller"]
            d["controller"] = {k: c[k][:] for k in c.keys()}
            d["status"] = [sr.text(s) for s in f["cpi/status"][:]]
            d["dt"] = f["cpi/dt"][:]
    return d


def step_counts(run):
    """A CPI run's jumps kept, jumps rejected, and bursts run directly because the tolerance
    allowed DT < cpi.dt_min."""
    status, limited = run["status"], run["controller"]["limited_by"]
    kept = sum(s == "projected" for s in status)
    rejected = sum(s == "rejected" for s in status)
    direct = sum(1 for s, lim in zip(status, limited)
                 if s == "burst_only" and sr.text(lim) == "tolerance below dt_min")
    return int(kept), int(rejected), int(direct)


def rms_on(run, ref, window=None):
    """RMS(run - ref) over run's samples that ref has (and within window = (t0, t1))."""
    keep, y = am.align(ref["t"], ref["mean"], run["t"])
    x, t = run["mean"][keep], run["t"][keep]
    if window:
        sel = (t >= window[0]) & (t < window[1])
        x, y = x[sel], y[sel]
    return math.sqrt(float(np.mean((x - y) ** 2))) if len(x) else float("nan")


def analyse(args, realizations):
    runs = {name: load(result(args, name)) for name in ORDER if sr.archived(result(args, name))}
    directs = [runs[n] for n, _ in DIRECT if n in runs]
    flags = f"--us {args.us} --realizations {realizations} --duration {DURATION:g}"
    lines = [f"# Slope study (issue 33): demo bed, U_s = {args.us}, R = {realizations}, {DURATION:g} time units\n",
             f"Made by `/usr/bin/python3 bench/slope_study.py --efdem build/mpi_driver/efdem {flags}`; "
             "this file by `--analyse-only`.\n"]
    summary = {"floor": {}, "runs": {}}
    if len(directs) >= 2:
        pairs = [(i, j) for i in range(len(directs)) for j in range(i + 1, len(directs))]
        floors = [rms_on(directs[i], directs[j]) for i, j in pairs]
        q_floors = [[rms_on(directs[i], directs[j], q) for i, j in pairs] for q in QUARTERS]
        summary["floor"] = {"pairs": floors, "quarters": q_floors}
        lines.append(f"Noise floor (RMS between direct ensembles, {len(pairs)} pair(s)): "
                     + ", ".join(f"{f:.3f}" for f in floors) + f" d_p; mean {np.mean(floors):.3f}\n")
        lines.append("| quarter | " + " | ".join(f"{a:g}-{b:g}" for a, b in QUARTERS) + " |")
        lines.append("|---" * 5 + "|")
        lines.append("| floor (mean of pairs) | " + " | ".join(f"{np.mean(q):.3f}" for q in q_floors) + " |\n")
    dem_direct = [float(d["wall_seconds"]) for d in directs]
    lines.append("| run | e [d_p] | e / floor | e / floor per quarter | DEM-time speed-up | wall speed-up "
                 "| kept / rejected / direct bursts | mean DT | stat. charged / own / one burst (mean per jump) |")
    lines.append("|---" * 9 + "|")
    for name, _ in CPI:
        if name not in runs or not directs:
            continue
        r = runs[name]
        e = math.sqrt(np.mean([rms_on(r, d) ** 2 for d in directs]))
        floor = np.mean(summary["floor"]["pairs"]) if summary["floor"] else float("nan")
        eq = [math.sqrt(np.mean([rms_on(r, d, q) ** 2 for d in directs])) for q in QUARTERS]
        fq = [np.mean(q) for q in summary["floor"]["quarters"]] if summary["floor"] else [float("nan")] * 4
        c = r["controller"]
        kept = np.asarray(c["accepted"]) == 1
        proj = np.array([s == "projected" for s in r["status"]])
        n_proj, n_rej, n_direct = step_counts(r)
        speed = float(r["simulated_time"]) / float(r["dem_time"])
        wall = np.mean(dem_direct) / float(r["wall_seconds"]) if dem_direct else float("nan")
        mean_dt = float(np.mean(r["dt"][proj])) if proj.any() else float("nan")
        stat = [float(np.nanmean(c[k][kept])) if kept.any() and k in c else float("nan")
                for k in ("error_statistical", "error_statistical_jump", "error_statistical_burst")]
        summary["runs"][name] = {"e": e, "e_quarters": eq, "speedup_dem": speed, "speedup_wall": wall,
                                 "kept": n_proj, "rejected": n_rej, "direct": n_direct,
                                 "mean_dt": mean_dt, "statistical": stat}
        lines.append(f"| {name} | {e:.3f} | {e / floor:.2f} | " + " / ".join(f"{a / b:.2f}" for a, b in zip(eq, fq))
                     + f" | {speed:.2f} | {wall:.2f} | {n_proj} / {n_rej} / {n_direct} | "
                     f"{mean_dt:.1f} | " + " / ".join(f"{s:.3f}" for s in stat) + " |")
    os.makedirs(args.results, exist_ok=True)
    with open(os.path.join(args.results, "analysis.md"), "w") as f:
        f.write("\n".join(lines) + "\n")
    with open(os.path.join(args.results, "analysis.json"), "w") as f:
        json.dump(summary, f, indent=1)
    plot(args, runs, directs)
    print("\n".join(lines))


def plot(args, runs, directs):
    if not directs:
        return
    fig, ax = plt.subplots(1, 2, figsize=(12, 4.5))
    mid = 9  # p = 0.5
    for name, _ in DIRECT:
        if name in runs:
            ax[0].plot(runs[name]["t"], runs[name]["mean"][:, mid], color="grey", lw=1, label=name)
    for name, _ in CPI:
        if name in runs:
            ax[0].plot(runs[name]["t"], runs[name]["mean"][:, mid], ".", ms=2, label=name)
            eq = [math.sqrt(np.mean([rms_on(runs[name], d, q) ** 2 for d in directs])) for q in QUARTERS]
            ax[1].plot([np.mean(q) for q in QUARTERS], eq, "o-", label=name)
    if len(directs) >= 2:
        pairs = [(i, j) for i in range(len(directs)) for j in range(i + 1, len(directs))]
        fq = [[rms_on(directs[i], directs[j], q) for i, j in pairs] for q in QUARTERS]
        x = [np.mean(q) for q in QUARTERS]
        ax[1].fill_between(x, [min(v) for v in fq], [max(v) for v in fq], color="grey", alpha=0.3,
                           label="floor (range of direct pairs)")
    ax[0].set_xlabel("t [sqrt(d_p/g)]")
    ax[0].set_ylabel("median light height [d_p]")
    ax[0].legend(fontsize=7)
    ax[1].set_xlabel("t (quarter of the run) [sqrt(d_p/g)]")
    ax[1].set_ylabel("RMS error against the direct ensembles [d_p]")
    ax[1].legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(os.path.join(args.results, "slope_study.png"), dpi=110)


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--efdem", default=os.path.join(HERE, "..", "build", "mpi_driver", "efdem"))
    p.add_argument("--out", help="working folder of the runs (default runs/slope_study_r<R>_u<U_s>_t<duration>)")
    p.add_argument("--results", help="one result file per run (default bench/results/slope_study_r<R>_u<U_s>_t<duration>)")
    p.add_argument("--us", type=float, choices=sorted(CPI_BY_US), default=0.19, help="superficial velocity")
    p.add_argument("--duration", type=float, default=600.0, help="time units per run")
    p.add_argument("--realizations", type=int, default=4)
    p.add_argument("--np", type=int, default=2)
    p.add_argument("--only", nargs="*", help="make only these runs")
    p.add_argument("--analyse-only", action="store_true")
    args = p.parse_args()
    configure(args.us, args.duration)
    study = f"slope_study_r{args.realizations}_u{args.us:g}_t{args.duration:g}"
    args.out = args.out or os.path.join(HERE, "..", "runs", study)
    args.results = args.results or os.path.join(HERE, "results", study)
    if not args.analyse_only:
        todo = specs(args.realizations, args.np, args.us)
        for name in ORDER:
            if args.only and name not in args.only:
                continue
            if sr.archived(result(args, name)):
                print(f"  {name}: done before, skipped", flush=True)
                continue
            if sr.completed(args.out, name):
                sr.archive(args.out, name, result(args, name))
                continue
            mode, seed, over = todo[name]
            if sr.run_case(os.path.abspath(args.efdem), args.np, SCENE, args.out, name, mode, {**over, "seed": seed}):
                sr.archive(args.out, name, result(args, name))
    analyse(args, args.realizations)


if __name__ == "__main__":
    main()
