#!/usr/bin/python3
"""What accuracy costs in time: a brute-force (direct) ensemble as the reference, then CPI runs
sweeping the projective step, healing and window, ensemble size, observable, DEM time step and
slab thickness. For each run: wall time, particle-steps, effective speed-up and error against
the direct ensemble, in d_p and in units of the ensemble's standard error. Writes plots (PNG),
a Markdown table and a CSV into the output folder.

    /usr/bin/python3 scripts/accuracy_cost.py --efdem build/mpi_driver/efdem --out runs/accuracy [--quick]

Runs are resumable: a run whose .h5 file is complete is not repeated. --quick uses a tiny bed
and a handful of runs (under 15 minutes on 2 cores); the full study (the demo bed, 12 runs)
about an hour on a quiet 2-core machine.
"""
import argparse
import csv
import math
import os
import subprocess
import sys
import time

import h5py
import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import accuracy_metrics as am  # noqa: E402
import plot_layout  # noqa: E402
import run_files  # noqa: E402
from matplotlib.lines import Line2D  # noqa: E402

# The scenes of the study are checked in; the study only overrides keys. Full study: the demo bed
# (the paper's model, 1,000 spheres in 7.5 x 7.5: 1/12 of the particles). --quick: the tiny bed
# of the driver tests (256 spheres in 4.28 x 4.28), settled.
HERE = os.path.dirname(os.path.abspath(__file__))
SCENES = {
    False: (os.path.join(HERE, "..", "bench", "scenes", "demo_bed.cfg"),  # the demo bed, no cpi block
            {"run.duration": 200, "cpi.warmup": 10, "cpi.healing": 10, "cpi.window": 10, "cpi.dt": 40}),
    True: (os.path.join(HERE, "..", "tests", "scripts", "tiny_scene.cfg"),
           {"bed.settle": "true", "bed.settle.ke_threshold": 1e-5, "run.duration": 40, "cpi.warmup": 5,
            "cpi.healing": 3, "cpi.window": 3, "cpi.dt": 12}),
}


def study_runs(quick):
    """(name, U_s, mode, R, overrides) of every run, reference first for each U_s."""
    if quick:
        runs = [("ref_0.19", 0.19, "direct", 4, {})]
        for dt in (0, 6, 12, 24):
            runs.append((f"DT{dt}", 0.19, "cpi", 4, {"cpi.dt": dt}))
        runs.append(("R1_DT12", 0.19, "cpi", 1, {"cpi.dt": 12}))
        runs.append(("R2_DT12", 0.19, "cpi", 2, {"cpi.dt": 12}))
        runs.append(("compact_DT12", 0.19, "cpi", 4, {"cpi.dt": 12, "cpi.observable": "compact"}))
        return runs
    # Full study: sized to run in about an hour on a quiet 2-core machine (1,000 spheres at about
    # 1.2e7 particle-steps/s per core: a direct realization of 200 time units costs 3 core-minutes).
    # References R = 8; CPI sweeps at R = 8 unless R is the variable. DT = 0 (which only re-runs
    # the direct ensemble in bursts) and DT = burst are left to --quick and to the paper
    # reproduction (scripts/paper_reproduction.py), whose Fig. 4 direct ensemble has the settings
    # of ref_0.41 here. The U_s = 0.41 reference comes last: it is needed only for the analysis.
    burst = 20
    runs = [("ref_0.19", 0.19, "direct", 8, {})]
    for k in (2, 4, 8):
        runs.append((f"DT{k * burst}", 0.19, "cpi", 8, {"cpi.dt": k * burst}))
    for r in (1, 2, 4):
        runs.append((f"R{r}_DT80", 0.19, "cpi", r, {"cpi.dt": 80}))
    runs.append(("compact_DT80", 0.19, "cpi", 8, {"cpi.dt": 80, "cpi.observable": "compact"}))
    runs.append(("H5W15_DT80", 0.19, "cpi", 8, {"cpi.healing": 5, "cpi.window": 15, "cpi.dt": 80}))
    # dt about t_c/10 (t_c = 3.596e-3 for kn = 2e5, e = 0.9), as a whole fraction of the sampling
    # interval 0.5, which efdem requires: 0.5/1391 = t_c/10.004.
    runs.append(("dt_tc10_DT80", 0.19, "cpi", 8, {"cpi.dt": 80, "dt": 0.5 / math.ceil(0.5 / (3.596e-3 / 10))}))
    runs.append(("slab2_DT80", 0.19, "cpi", 8, {"cpi.dt": 80, "gas_drag.slab_thickness": 2}))
    runs.append(("U041_DT40", 0.41, "cpi", 8, {"cpi.dt": 40}))
    runs.append(("ref_0.41", 0.41, "direct", 8, {"observe.compact": "true"}))
    return runs


def run_efdem(args, us, name, mode, R, overrides):
    h5 = os.path.join(args.out, name + ".h5")
    if os.path.exists(h5):
        try:
            with h5py.File(h5, "r") as f:
                status = f.attrs.get("end_status", "")
                if (status.decode() if isinstance(status, bytes) else str(status)).startswith("completed"):
                    return h5
        except OSError:
            pass
    np_ = min(R, args.np)
    per_rank = R // np_
    scene, base = SCENES[args.quick]
    overrides = {**base, "gas_drag.superficial_velocity": us, **overrides}
    cmd = ["mpirun", "-np", str(np_), "--oversubscribe", args.efdem, scene, f"mode={mode}",
           f"ensemble.realizations_per_rank={per_rank}", f"output.directory={args.out}",
           f"output.prefix={name}", "output.overwrite=true"] + [f"{k}={v}" for k, v in overrides.items()]
    env = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1")
    t0 = time.time()
    with open(os.path.join(args.out, name + ".log"), "w") as log:
        code = subprocess.call(cmd, stdout=log, stderr=subprocess.STDOUT, env=env)
    print(f"  {name}: {'ok' if code == 0 else f'FAILED ({code})'} in {time.time() - t0:.0f} s", flush=True)
    if code != 0:
        raise SystemExit(f"accuracy_cost: run {name} failed; see {args.out}/{name}.log")
    return h5


def load(h5):
    with h5py.File(h5, "r") as f:
        d = {k: f.attrs[k] for k in ("realizations", "wall_seconds", "particle_steps", "simulated_time", "dem_time")}
        d["t"] = f["samples/time"][:]
        d["mean"] = run_files.get(f, "samples/mean_icdf")[:]
        d["var"] = f["samples/variance"][:]
        d["p"] = f["p"][:]
        d["scene"] = f["scene"][()].decode() if isinstance(f["scene"][()], bytes) else f["scene"][()]
        d["params"] = f["parameters"][()]
        if "cpi" in f:
            d["steps"] = len(f["cpi/t_start"])
            # Samples up to the end of the first burst come before any projection: with the
            # reference's seeds they equal it bit for bit and would dilute the error.
            d["first_projection"] = float(f["cpi/t_end"][0]) if d["steps"] else math.inf
            d["repairs"] = int(np.sum(f["cpi/repair_max_adjustment"][:] > 0))
        return d


def param(d, key, default=None):
    text = d["params"].decode() if isinstance(d["params"], bytes) else d["params"]
    for line in text.splitlines():
        if line.startswith(key + " = "):
            return line.split(" = ", 1)[1].split("   [")[0].strip()
    return default


def analyse(run, ref):
    """Error and cost of a CPI run against the direct reference, over the samples after its
    first projection (before it, a run with the reference's seeds is the reference)."""
    after = run["t"] > run.get("first_projection", -math.inf) + 1e-9
    if not after.any():
        raise SystemExit("accuracy_cost: a run made no projection inside its duration: nothing to compare")
    t = run["t"][after]
    keep, ref_mean = am.align(ref["t"], ref["mean"], t)
    _, ref_var = am.align(ref["t"], ref["var"], t)
    mean = run["mean"][after][keep]
    err = am.rms_error(mean, ref_mean)
    R = int(run["realizations"])
    nerr = am.normalized_error(mean, ref_mean, ref_var, int(ref["realizations"]), ref_var, R)
    se = am.standard_error(ref_var, R)
    sp = am.speedup(run["simulated_time"], run["wall_seconds"], R, ref["simulated_time"], ref["wall_seconds"],
                    int(ref["realizations"]))
    dt_proj = float(param(run, "cpi.dt", 0))
    window = float(param(run, "cpi.window", 0))
    interval = float(param(run, "observe.interval", 0.5))
    # The noise of one sample of an R-ensemble mean, from the reference's fluctuations about its
    # local trend over windows of the slope's length (scaled from R_ref to R realizations).
    sigma = am.temporal_noise(ref["t"], ref["mean"], window) * math.sqrt(int(ref["realizations"]) / R) \
        if window > 0 else math.nan
    pred = am.predicted_projection_noise(dt_proj, window, int(round(window / interval)) + 1, sigma)
    return dict(error=err, normalized=nerr, noise_floor=se, speedup=sp, predicted=pred, dt=dt_proj,
                ideal=run["simulated_time"] / max(run["dem_time"], 1e-12), R=R)


def run_codes(quick, names):
    """Legend lines that say what each run code in `names` means: its settings, from the study's
    own list (study_runs), after a line with the settings every CPI run shares."""
    _, base = SCENES[quick]
    shared = ", ".join(f"{k} = {base[k]}" for k in ("cpi.warmup", "cpi.healing", "cpi.window"))
    lines = [f"run codes (every CPI run: {shared} unless named):"]
    for name, us, mode, R, overrides in study_runs(quick):
        if name in names:
            settings = ", ".join(f"{k} = {v:.6g}" if isinstance(v, float) else f"{k} = {v}" for k, v in overrides.items())
            lines.append(f"{name}: {mode}, U_s = {us}, R = {R}" + (f", {settings}" if settings else ""))
    return [plot_layout.text_entry(line) for line in lines]


def finish(fig, ax, handles, rows, x, y, path, quick):
    """The legend and the run codes beside the axes, each point labelled with its code where the
    label covers no other, and the figure written."""
    plot_layout.legend_beside(fig, handles + run_codes(quick, {r["name"] for r in rows}), side="right")
    plot_layout.place_labels(ax, [r[x] for r in rows], [r[y] for r in rows], [r["name"] for r in rows], fontsize=6)
    fig.savefig(path)
    plt.close(fig)


def plots(args, rows, refs):
    out = args.out
    # 1. error vs wall time, Pareto front labelled
    fig, ax = plt.subplots(figsize=(12, 5.5), dpi=120)
    pts = [(r["wall"], r["error"]) for r in rows]
    front = set(am.pareto_front(pts))
    for i, r in enumerate(rows):
        ax.scatter(r["wall"], r["error"], c="C3" if i in front else "C0", s=30, zorder=3)
    fr = sorted(front, key=lambda i: pts[i][0])
    ax.plot([pts[i][0] for i in fr], [pts[i][1] for i in fr], "C3-", lw=1)
    handles = [Line2D([], [], color="C3", marker="o", lw=1, label="CPI run on the Pareto front"),
               Line2D([], [], color="C0", marker="o", ls="none", label="CPI run off the front")]
    for (us, ref), ls in zip(refs.items(), (":", "-.")):
        ax.axvline(ref["wall_seconds"], color="grey", ls=ls, lw=1)
        handles.append(Line2D([], [], color="grey", ls=ls, lw=1,
                              label=f"wall time of the direct reference, U_s = {us} (R = {int(ref['realizations'])})"))
    ax.set_xlabel("wall time of the run [s] (2 cores)")
    ax.set_ylabel("RMS error of the mean ICDF vs direct [$d_p$]")
    ax.set_title("Accuracy against cost")
    ax.grid(alpha=0.3)
    finish(fig, ax, handles, rows, "wall", "error", os.path.join(out, "error_vs_wall_time.png"), args.quick)
    # 2. speed-up vs DT, colour = error
    dt_rows = [r for r in rows if r["name"].startswith(("DT", "U041"))]
    if dt_rows:
        fig, ax = plt.subplots(figsize=(11, 5), dpi=120)
        sc = ax.scatter([r["dt"] for r in dt_rows], [r["speedup"] for r in dt_rows],
                        c=[r["error"] for r in dt_rows], cmap="viridis", s=60, label="wall-time speed-up (colour: error)")
        # The DEM-time ("ideal") speed-up: what the method buys, whatever the machine's load.
        ax.scatter([r["dt"] for r in dt_rows], [r["ideal"] for r in dt_rows], facecolors="none",
                   edgecolors="k", s=60, label="DEM-time speed-up (ideal)")
        fig.colorbar(sc, ax=ax, label="RMS error [$d_p$]")
        ax.set_xlabel(r"projective step DT [$\sqrt{d_p/g}$]")
        ax.set_ylabel("speed-up vs direct (equal R)")
        ax.grid(alpha=0.3)
        finish(fig, ax, ax.get_legend_handles_labels()[0], dt_rows, "dt", "speedup",
               os.path.join(out, "speedup_vs_dt.png"), args.quick)
    # 3. error vs R with the 1/sqrt(R) noise floor
    r_rows = [r for r in rows if r["name"].startswith("R") or r["name"] in ("DT80", "DT12")]
    if r_rows:
        fig, ax = plt.subplots(figsize=(9, 5), dpi=120)
        Rs = np.array([r["R"] for r in r_rows])
        ax.loglog(Rs, [r["error"] for r in r_rows], "o", label="measured RMS error")
        ax.loglog(Rs, [r["noise_floor"] for r in r_rows], "s", mfc="none", label="standard error of a mean of R")
        grid = np.logspace(0, np.log10(max(Rs.max(), 2)), 50)
        ax.loglog(grid, r_rows[0]["noise_floor"] * math.sqrt(r_rows[0]["R"]) / np.sqrt(grid), "k:", label=r"$\propto 1/\sqrt{R}$")
        ax.set_xlabel("realizations R")
        ax.set_ylabel("RMS error [$d_p$]")
        ax.grid(alpha=0.3, which="both")
        plot_layout.legend_beside(fig, ax.get_legend_handles_labels()[0], side="right")
        fig.savefig(os.path.join(out, "error_vs_realizations.png"))
        plt.close(fig)
    # 4. predicted noise amplification vs measured error
    pr = [r for r in rows if math.isfinite(r["predicted"]) and r["dt"] > 0]
    if pr:
        fig, ax = plt.subplots(figsize=(10, 5), dpi=120)
        ax.scatter([r["predicted"] for r in pr], [r["error"] for r in pr], label="CPI run")
        lim = max(max(r["predicted"] for r in pr), max(r["error"] for r in pr)) * 1.1
        ax.plot([0, lim], [0, lim], "k:", lw=1, label="measured = predicted")
        ax.set_xlabel(r"predicted projection noise $DT/W\,\sqrt{12/n}\,\sigma_R$ [$d_p$]")
        ax.set_ylabel("measured RMS error [$d_p$]")
        ax.grid(alpha=0.3)
        finish(fig, ax, ax.get_legend_handles_labels()[0], pr, "predicted", "error",
               os.path.join(out, "predicted_vs_measured.png"), args.quick)


def icdf_plot(args, rows):
    """ICDF trajectories: the reference and a CPI run, with their 95 % intervals."""
    out = args.out
    import plot_icdf
    # The reference and the paper-like step (DT = 4 x burst), or the largest DT of a quick study.
    main_run = next((r["name"] for r in rows if r["name"] in ("DT80", "DT12")), rows[0]["name"])
    pick = [os.path.join(out, n + ".h5") for n in ("ref_0.19", main_run)]
    plot_icdf.main([p for p in pick if os.path.exists(p)] + ["-o", os.path.join(out, "icdf_cpi_vs_direct.png"),
                   "--title", "CPI against the direct ensemble (U_s = 0.19)"])


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--efdem", required=True)
    ap.add_argument("--out", required=True)
    ap.add_argument("--quick", action="store_true")
    ap.add_argument("--np", type=int, default=2, help="MPI ranks per run")
    ap.add_argument("--only", nargs="+", metavar="NAME",
                    help="run and analyse only these runs of the study (the references are always included)")
    args = ap.parse_args(argv)
    os.makedirs(args.out, exist_ok=True)
    args.out = os.path.abspath(args.out)
    t0 = time.time()
    print(f"accuracy_cost: {'quick' if args.quick else 'full'} study into {args.out}", flush=True)
    runs = study_runs(args.quick)
    if args.only:
        unknown = set(args.only) - {r[0] for r in runs}
        if unknown:
            raise SystemExit(f"accuracy_cost: --only: no such run(s) {sorted(unknown)}; "
                             f"the study has {[r[0] for r in runs]}")
        runs = [r for r in runs if r[0] in args.only or r[0].startswith("ref_")]
    files = {name: run_efdem(args, us, name, mode, R, ov) for name, us, mode, R, ov in runs}
    loaded = {name: load(h5) for name, h5 in files.items()}
    refs = {us: loaded[f"ref_{us}"] for us in (0.19, 0.41) if f"ref_{us}" in loaded}
    rows = []
    for name, us, mode, R, ov in runs:
        if mode != "cpi":
            continue
        run = loaded[name]
        a = analyse(run, refs[us])
        rows.append(dict(name=name, us=us, wall=float(run["wall_seconds"]), particle_steps=float(run["particle_steps"]),
                         steps=run.get("steps", 0), repairs=run.get("repairs", 0), **a))
    plots(args, rows, refs)
    icdf_plot(args, rows)
    with open(os.path.join(args.out, "accuracy_cost.csv"), "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(rows[0].keys()))
        w.writeheader()
        w.writerows(rows)
    with open(os.path.join(args.out, "table.md"), "w") as f:
        f.write("| run | U_s | R | DT | wall [s] | particle-steps | speed-up, wall (ideal) | error [d_p] | error / s.e. | "
                "predicted [d_p] | coarse steps | repairs |\n|---|---|---|---|---|---|---|---|---|---|---|---|\n")
        for us, ref in refs.items():
            f.write(f"| direct (reference) | {us} | {int(ref['realizations'])} | - | {ref['wall_seconds']:.0f} | "
                    f"{ref['particle_steps']:.3g} | 1 | - | - | - | - | - |\n")
        for r in rows:
            f.write(f"| {r['name']} | {r['us']} | {r['R']} | {r['dt']:g} | {r['wall']:.0f} | {r['particle_steps']:.3g} | "
                    f"{r['speedup']:.2f} ({r['ideal']:.2f}) | {r['error']:.3f} | {r['normalized']:.2f} | "
                    f"{r['predicted']:.3f} | {r['steps']} | {r['repairs']} |\n")
    print(open(os.path.join(args.out, "table.md")).read())
    print(f"accuracy_cost: done in {time.time() - t0:.0f} s; plots, table.md and accuracy_cost.csv in {args.out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
