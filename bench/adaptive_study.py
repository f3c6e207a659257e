#!/usr/bin/python3
"""Adaptive against fixed-DT CPI, every ensemble with its own seeds (issue 16). A resumable study,
bursts of healing 10 + window 10, warm-up 10, at U_s = 0.19 and 0.41, on one of two beds (--bed):

  demo   the 1,000-sphere demo bed (15.5 d_p tall), 200 time units at both U_s (default)
  tall   the tall bed of examples/tall_bed (3,120 spheres, the paper's 48 d_p height at a
         quarter of its area), 400 time units at U_s = 0.19 and 200 at U_s = 0.41
  paper  the paper's bed itself (12,500 spheres, packed by LAMMPS, tests/data), 200 time units at
         U_s = 0.41 (100 were made first, bench/results/paper_check_100_r2: the bed expands for 62
         of them, the adaptive run's warm-up took those and left no room for a jump):
         direct_a, direct_b and adaptive_tol0.32 only (--realizations 2; the expected noise
         floor there is ~0.3 d_p: the tall bed's 0.41 at R = 4, halved by 4 x the area, x sqrt 2 for R = 2)

    /usr/bin/python3 bench/adaptive_study.py --efdem build/mpi_driver/efdem --realizations 8
    /usr/bin/python3 bench/adaptive_study.py --efdem build/mpi_driver/efdem --bed tall --realizations 4

Runs are made in a working folder each under --out/u<U_s>/ (default runs/<study>_r<R>, <study> =
adaptive_study for the demo bed, tall_study for the tall one); what the analysis reads of each
completed run (its samples, its /cpi records, its attributes and the command) is kept in one file
per run under --results (default bench/results/<study>_r<R>/u<U_s>/<run>.h5, committed). A run whose result file is there is not repeated: rerun the command in
a later session, or in a fresh clone, and it continues. Most informative first:

  direct_a, direct_b   mode=direct, seeds 101, 202: the empirical noise floor is their difference
  adaptive_tol<X>      seed 404, cpi.projection = adaptive, cpi.tolerance = X (3 values; on
                       the tall bed, whose noise floor is 3 x the demo bed's, 0.32 and 0.64 at
                       U_s = 0.19, 0.16, 0.32 and 0.64 at 0.41); at
                       U_s = 0.41 with healing 2 + window 20 (two wave periods, see ADAPTIVE_BURST)
  fixed_dt40           seed 303, cpi.dt = 40 (the demo bed's best fixed DT, docs/accuracy_vs_cost.md)
  adaptive_tol<X>_members  as adaptive_tol<X> (the first X) with cpi.lift = members (demo bed)
  fixed_dt80           seed 505, cpi.dt = 80 (the paper's DT at U_s = 0.19), last (demo bed)

Error of a CPI run: e^2 = (RMS^2(X - D_a) + RMS^2(X - D_b)) / 2 over the CPI run's samples (times
and p-nodes), X its ensemble-mean light ICDF, D_a, D_b the direct ensembles at the same times. The
floor: RMS(D_a - D_b) over the same samples. For a CPI ensemble that is as good as a third direct
ensemble, E[e^2] = floor^2 (each difference of two independent ensembles of R carries 2 var/R):
"within the noise floor" is e / floor ~ 1. Speed-up: simulated / DEM time (per realization), and
the wall time of the mean direct run over the CPI run's (same ranks and R; the runs are made one
after the other on a shared machine, so wall ratios carry its load).

--realizations R (default 4: ranks x 2) and --np (default 2).
Cost on 2 cores (AMD EPYC, 2026-12-02/03): demo bed R = 8, one direct run of 200 time units
~20-45 min; tall bed R = 4: a direct run of 200 time units at U_s = 0.41 took 13-15 min
(1.4-1.6e7 particle-steps/s per core, fluidized; settling included), 400 units at U_s = 0.19 are
slower per step (a barely fluidized bed).
--deadline HH:MM (UTC): start no run that, at the direct runs' pace, would end after it.
--only NAME...: make only these runs (e.g. direct_a direct_b, which do not depend on the controller).
--analyse-only: no runs. Writes analysis.md, analysis.json and error_vs_speedup.png into --results.
"""
import argparse
import datetime as dt_
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
import plot_layout  # noqa: E402
from matplotlib.lines import Line2D  # noqa: E402

sys.path.insert(0, HERE)
import study_runs as sr  # noqa: E402


class Bed:
    """One bed of the study: its scene (without a cpi block), U_s in the order they are run, the
    run length per U_s, the adaptive tolerances per U_s (d_p per jump; the first is run first) and
    whether the demo bed's extra runs (cpi.lift = members, fixed DT = 80) are made."""

    def __init__(self, scene, label, study, speeds, duration, tolerances, extras, fixed=True):
        self.scene = os.path.join(HERE, "scenes", scene)
        self.label, self.study, self.speeds = label, study, speeds
        self.duration, self.tolerances, self.extras, self.fixed = duration, tolerances, extras, fixed


BEDS = {
    "demo": Bed("demo_bed.cfg", "Demo bed (1,000 spheres, 7.5 x 7.5, 15.5 d_p packed)", "adaptive_study",
                (0.19, 0.41), {0.19: 200.0, 0.41: 200.0}, {u: (0.16, 0.08, 0.32) for u in (0.19, 0.41)}, True),
    # The paper's height: U_s = 0.41 over 200 units (made first), 0.19 over 400 (slower dynamics).
    # Its noise floor at R = 4 is ~0.4 d_p, three times the demo bed's, so a tolerance in d_p
    # means a third as much there: at U_s = 0.41, 0.16 allowed no jump (the statistical error of
    # one DT_min jump was 0.11-0.13 d_p). U_s = 0.19 is therefore run at 0.32 and 0.64, and 0.64
    # is added at 0.41 (last: the runs made before keep their names and results).
    "tall": Bed("tall_bed.cfg", "Tall bed (3,120 spheres, 7.5 x 7.5, 48 d_p packed)", "tall_study",
                (0.19, 0.41), {0.41: 200.0, 0.19: 400.0}, {0.41: (0.16, 0.32, 0.64), 0.19: (0.32, 0.64)},
                False),
    # The paper's bed itself (LAMMPS-packed, colours permuted per realization): one check at
    # U_s = 0.41 over 200 time units, direct against adaptive CPI (R = 2 fits 2 cores).
    "paper": Bed("reference_bed.cfg", "The paper's bed (12,500 spheres, 15 x 15, 48 d_p packed)", "paper_check",
                 (0.41,), {0.41: 200.0}, {0.41: (0.32,)}, False, fixed=False),
}


# At U_s = 0.41 the realizations' waves stay in phase (they all fluidize at t = 0), so the ensemble
# mean oscillates with T ~ 9 and a least-squares slope over less than two periods is biased by it
# beyond its standard error (bench/wave_slope_bias.py: z = 3-4 for windows of 4-10, 0.3 for 18).
# The adaptive runs there use a window of two periods; the fixed-DT run keeps the demo bed's best.
ADAPTIVE_BURST = {0.19: {}, 0.41: {"cpi.healing": 2, "cpi.window": 20}}


def runs(u=0.19, bed=BEDS["demo"]):
    """(name, mode, seed, overrides) in the order they are made, at U_s = u."""
    out = [("direct_a", "direct", 101, {}), ("direct_b", "direct", 202, {})]
    tolerances = bed.tolerances[u]
    adaptive = lambda tol: {"cpi.projection": "adaptive", "cpi.tolerance": tol, **ADAPTIVE_BURST[u]}  # noqa: E731
    out.append((f"adaptive_tol{tolerances[0]:g}", "cpi", 404, adaptive(tolerances[0])))
    if bed.fixed:
        out.append(("fixed_dt40", "cpi", 303, {"cpi.projection": "fixed", "cpi.dt": 40}))
    for tol in tolerances[1:]:
        out.append((f"adaptive_tol{tol:g}", "cpi", 404, adaptive(tol)))
    if bed.extras:
        out.append((f"adaptive_tol{tolerances[0]:g}_members", "cpi", 404,
                    {**adaptive(tolerances[0]), "cpi.lift": "members"}))
        out.append(("fixed_dt80", "cpi", 505, {"cpi.projection": "fixed", "cpi.dt": 80}))
    return out


def base(u, bed, realizations, np_):
    return {"gas_drag.superficial_velocity": u, "run.duration": bed.duration[u], "cpi.warmup": 10,
            "cpi.healing": 10, "cpi.window": 10, "ensemble.realizations_per_rank": realizations // np_}


attr_text = sr.text


def result(args, u, name):
    """The committed result file of run NAME at U_s = u."""
    return os.path.join(args.results, f"u{u:g}", name + ".h5")


def direct_pace(args, u):
    """Wall seconds per time unit of the direct runs made so far (None before the first)."""
    made = []
    for name in ("direct_a", "direct_b"):
        if sr.archived(result(args, u, name)):
            with h5py.File(result(args, u, name), "r") as f:
                made.append(float(f.attrs["wall_seconds"]) / float(f.attrs["dem_time"]))
    return float(np.mean(made)) if made else None


def run_one(args, folder, u, name, mode, seed, extra):
    if sr.archived(result(args, u, name)):
        print(f"  u{u:g}/{name}: done before, skipped", flush=True)
        return True
    if sr.completed(folder, name):  # the study was stopped after this run ended, before archiving
        sr.archive(folder, name, result(args, u, name))
        print(f"  u{u:g}/{name}: completed in {folder}, archived", flush=True)
        return True
    if args.deadline:
        pace = direct_pace(args, u) or 4.0 * args.realizations / 4
        est = pace * args.bed.duration[u] * (1.0 if mode == "direct" else 0.7)
        if dt_.datetime.now(dt_.timezone.utc) + dt_.timedelta(seconds=est) > args.deadline:
            print(f"  u{u:g}/{name}: not started: about {est / 60:.0f} min would end after {args.deadline:%H:%M} UTC",
                  flush=True)
            return False
    over = {**base(u, args.bed, args.realizations, args.np), "seed": seed, **extra}
    ok = sr.run_case(args.efdem, args.np, args.bed.scene, folder, name, mode, over, label=f"u{u:g}/{name}")
    if ok:
        sr.archive(folder, name, result(args, u, name))
    return ok


def load(path):
    with h5py.File(path, "r") as f:
        d = {k: attr_text(v) if isinstance(v, (bytes, str)) else v for k, v in f.attrs.items()}
        d["t"] = f["samples/time"][:]
        d["mean"] = run_files.get(f, "samples/mean_icdf")[:]
        d["var"] = f["samples/variance"][:]
        d["icdf"] = f["samples/icdf"][:]  # samples x R x nodes
        if "cpi/status" in f:
            d["status"] = [attr_text(s) for s in f["cpi/status"][:]]
            d["dt"] = f["cpi/dt"][:]
            if "cpi/controller" in f:
                c = f["cpi/controller"]
                d["controller"] = {k: c[k][:] for k in c.keys()}
            if "cpi/controller_summary" in f:
                d["summary"] = attr_text(f["cpi/controller_summary"][()])
    return d


def score(run, da, db):
    keep_a, ya = am.align(da["t"], da["mean"], run["t"])
    keep_b, yb = am.align(db["t"], db["mean"], run["t"])
    keep = keep_a & keep_b
    x = run["mean"][keep]
    ya = ya[keep[keep_a]]
    yb = yb[keep[keep_b]]
    e2 = 0.5 * (np.mean((x - ya) ** 2) + np.mean((x - yb) ** 2))
    floor = am.rms_error(ya, yb)
    return math.sqrt(e2), floor, int(keep.sum())


def analyse(args):
    floors = {}
    rows, report = [], ["# Adaptive vs fixed-DT CPI, independent seeds (bench/adaptive_study.py)", "",
                        f"{args.bed.label}, R = {args.realizations}, "
                        + ", ".join(f"{args.bed.duration[u]:g} time units at U_s = {u:g}" for u in args.bed.speeds)
                        + "; burst 10 + 10, warm-up 10. Error e and noise floor as in the script's docstring.", ""]
    for u in args.bed.speeds:
        done = lambda name: sr.archived(result(args, u, name))  # noqa: E731
        if not (done("direct_a") and done("direct_b")):
            report.append(f"U_s = {u:g}: the two direct ensembles are not complete yet; nothing to compare.\n")
            continue
        da, db = load(result(args, u, "direct_a")), load(result(args, u, "direct_b"))
        # The quicker of the two: a direct run that shared the machine with other work (builds,
        # tests) is slower for it, and the CPI runs are compared with the machine as quiet as it was.
        walls = {"direct_a": float(da["wall_seconds"]), "direct_b": float(db["wall_seconds"])}
        wall_direct = min(walls.values())
        floor_all = am.rms_error(da["mean"], am.align(db["t"], db["mean"], da["t"])[1])
        # What the floor should be from the spread (E (D_a - D_b)^2 = var_a/R + var_b/R), and how
        # much one pair's floor scatters: every split of each direct ensemble into two halves is
        # a floor of two ensembles of R/2; / sqrt(2) it estimates one of R (frozen offsets of
        # realizations make these differ far more than per-sample noise would).
        r_direct = int(da["realizations"])
        var_b = am.align(db["t"], db["var"], da["t"])[1]
        floor_spread = math.sqrt(float(np.mean((da["var"] + var_b) / r_direct)))
        splits = np.concatenate([am.split_floors(d["icdf"]) for d in (da, db)]) / math.sqrt(2.0)
        floors[f"{u:g}"] = {"floor": floor_all, "floor_spread": floor_spread, "split_min": float(splits.min()),
                            "split_median": float(np.median(splits)), "split_max": float(splits.max())}
        report += [f"## U_s = {u:g}", "", f"Noise floor RMS(D_a - D_b) over all samples: **{floor_all:.3f} d_p**; "
                   f"from the realizations' spread sqrt((var_a + var_b)/R): {floor_spread:.3f} d_p; one pair's floor "
                   f"scatters over {splits.min():.3f}-{splits.max():.3f} d_p (median {np.median(splits):.3f}; the "
                   f"{len(splits)} half-splits of the two direct ensembles, / sqrt(2)). "
                   f"Direct wall time {walls['direct_a']:.0f} s and {walls['direct_b']:.0f} s; the wall speed-ups are "
                   f"against the quicker, {wall_direct:.0f} s (the runs are made one after the other with one binary on "
                   "a machine shared with other work: wall ratios carry its load).", "",
                   "| run | error e [d_p] | floor on its samples | e / floor | e / spread floor | DEM-time speed-up | "
                   "wall speed-up | jumps kept / rejected / direct bursts | mean DT |",
                   "|---|---|---|---|---|---|---|---|---|"]
        for name, mode, _, _ in runs(u, args.bed):
            if mode != "cpi" or not done(name):
                continue
            r = load(result(args, u, name))
            e, floor, n = score(r, da, db)
            s_dem = float(r["simulated_time"]) / float(r["dem_time"])
            s_wall = wall_direct / float(r["wall_seconds"])
            st = r.get("status", [])
            kept = sum(1 for s in st if s == "projected")
            rej = sum(1 for s in st if s == "rejected")
            direct = max(0, sum(1 for s in st if s == "burst_only") - 1)  # less the first burst
            dts = [dt for dt, s in zip(r["dt"], st) if s == "projected"]
            rows.append({"u": u, "run": name, "error": e, "floor": floor, "ratio": e / floor,
                         "ratio_spread": e / floor_spread, "speedup_dem": s_dem,
                         "speedup_wall": s_wall, "kept": kept, "rejected": rej, "direct_bursts": direct,
                         "mean_dt": float(np.mean(dts)) if dts else 0.0, "samples": n,
                         "summary": r.get("summary", "")})
            report.append(f"| {name} | {e:.3f} | {floor:.3f} | {e / floor:.2f} | {e / floor_spread:.2f} | "
                          f"{s_dem:.2f} | {s_wall:.2f} | "
                          f"{kept} / {rej} / {direct} | {rows[-1]['mean_dt']:.1f} |")
        report.append("")
        for row in rows:
            if row["u"] == u and row["summary"]:
                report += [f"`{row['run']}`:", "```", row["summary"], "```", ""]
    os.makedirs(args.results, exist_ok=True)
    with open(os.path.join(args.results, "analysis.md"), "w") as f:
        f.write("\n".join(report) + "\n")
    with open(os.path.join(args.results, "analysis.json"), "w") as f:
        json.dump({"runs": rows, "noise_floors": floors}, f, indent=1)
    if rows:
        plot_error_vs_speedup(args, rows)
    print("\n".join(report))


def run_codes(args, shown):
    """Legend lines: what each plotted run code means, from runs() itself, per U_s where the
    settings differ between them."""
    shared = base(args.bed.speeds[0], args.bed, args.realizations, args.np)
    shared = ", ".join(f"{k} = {v}" for k, v in shared.items() if k.startswith("cpi."))
    lines = [f"run codes (every CPI run: {shared} unless named; tol: cpi.tolerance in d_p):"]
    for code in dict.fromkeys(name for u in args.bed.speeds for name, *_ in runs(u, args.bed)):
        if code not in shown:
            continue
        per_u = {u: next(((seed, extra) for name, _, seed, extra in runs(u, args.bed) if name == code), None)
                 for u in args.bed.speeds}
        settings = {u: f"seed {v[0]}, " + ", ".join(f"{k} = {x}" for k, x in v[1].items()) for u, v in per_u.items() if v}
        if len(set(settings.values())) == 1:
            lines.append(f"{code.replace('adaptive_', '')}: {next(iter(settings.values()))}")
        else:
            lines += [f"{code.replace('adaptive_', '')} (U_s = {u:g}): {text}" for u, text in settings.items()]
    return [plot_layout.text_entry(line) for line in lines]


def plot_error_vs_speedup(args, rows):
    fig, axes = plt.subplots(1, len(args.bed.speeds), figsize=(11, 8), sharey=True)
    axes = np.atleast_1d(axes)
    for ax, u in zip(axes, args.bed.speeds):
        mine = [r for r in rows if r["u"] == u]
        for row in mine:
            colour = "C0" if row["run"].startswith("adaptive") else "C3"
            ax.plot(row["speedup_dem"], row["ratio"], "o", color=colour)
            ax.plot(row["speedup_wall"], row["ratio"], "s", mfc="none", color=colour)
        ax.axhline(1.0, color="k", lw=0.8, ls="--")
        ax.set_title(f"{args.bed.label.split(' (')[0]}, U_s = {u:g}, R = {args.realizations}")
        ax.set_xlabel("speed-up over a direct ensemble [-]")
    axes[0].set_ylabel("error / empirical noise floor [-]")
    handles = [Line2D([], [], color="C0", marker="o", ls="none", label="adaptive CPI, speed-up in DEM time"),
               Line2D([], [], color="C0", marker="s", mfc="none", ls="none", label="adaptive CPI, speed-up in wall time"),
               Line2D([], [], color="C3", marker="o", ls="none", label="fixed-DT CPI, speed-up in DEM time"),
               Line2D([], [], color="C3", marker="s", mfc="none", ls="none", label="fixed-DT CPI, speed-up in wall time"),
               Line2D([], [], color="k", lw=0.8, ls="--", label="error = noise floor (as good as a direct ensemble)")]
    plot_layout.legend_beside(fig, handles + run_codes(args, {r["run"] for r in rows}), side="bottom")
    for ax, u in zip(axes, args.bed.speeds):
        mine = [r for r in rows if r["u"] == u]
        # Both markers of a run are avoided; the label goes to the DEM-time (filled) one.
        plot_layout.place_labels(ax, [r["speedup_dem"] for r in mine], [r["ratio"] for r in mine],
                                 [r["run"].replace("adaptive_", "") for r in mine], fontsize=8,
                                 avoid=[(r["speedup_wall"], r["ratio"]) for r in mine])
    fig.savefig(os.path.join(args.results, "error_vs_speedup.png"), dpi=120)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--efdem", default=os.path.join(HERE, "..", "build", "mpi_driver", "efdem"))
    ap.add_argument("--out", help="working folders (default runs/adaptive_study_r<R>)")
    ap.add_argument("--results", help="one result file per run (default bench/results/adaptive_study_r<R>)")
    ap.add_argument("--bed", choices=sorted(BEDS), default="demo")
    ap.add_argument("--realizations", type=int, default=4)
    ap.add_argument("--only", nargs="*", help="make only these runs (the analysis uses every completed one)")
    ap.add_argument("--np", type=int, default=2)
    ap.add_argument("--deadline", type=lambda s: dt_.datetime.combine(
        dt_.datetime.now(dt_.timezone.utc).date(), dt_.time.fromisoformat(s), dt_.timezone.utc))
    ap.add_argument("--analyse-only", action="store_true")
    args = ap.parse_args()
    args.bed = BEDS[args.bed]
    args.out = args.out or os.path.join(HERE, "..", "runs", f"{args.bed.study}_r{args.realizations}")
    args.results = args.results or os.path.join(HERE, "results", f"{args.bed.study}_r{args.realizations}")
    if not args.analyse_only:
        for u in args.bed.speeds:  # demo bed: U_s = 0.19 (the >= 5x target) first, then 0.41
            for name, mode, seed, extra in runs(u, args.bed):
                if args.only and name not in args.only:
                    continue
                folder = os.path.join(args.out, f"u{u:g}")
                os.makedirs(folder, exist_ok=True)
                run_one(args, folder, u, name, mode, seed, extra)
    analyse(args)


if __name__ == "__main__":
    main()
