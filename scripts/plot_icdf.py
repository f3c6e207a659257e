#!/usr/bin/python3
"""Plot the evolution of the ensemble-mean ICDF of an efdem run, with confidence bands, and
overlay several runs (e.g. a direct and a CPI ensemble of the same scene).

    /usr/bin/python3 scripts/plot_icdf.py RUN.h5 [RUN2.h5 ...] -o icdf.png [--nodes 0.1 0.5 0.9]

Each selected node p_i is drawn as a line Q(p_i)(t) with the 95 % Student-t interval of the
mean of the R realizations as a band (mean +- t(0.975, R - 1) sqrt(variance / R),
scripts/ensemble_bands.py; a run of R = 1 has no band and its legend entry says so); the legend,
beside the axes, names the band. The colour is the node, the line style the run's mode (the
run file's `mode` attribute): direct solid, CPI dashed (a second run of the same mode dotted or
dash-dotted). CPI runs show as bursts (their samples) separated by the projective jumps (from
/cpi/t_end, /cpi/dt, /cpi/status; rejected jumps are not part of the trajectory), drawn as thin
dotted connectors, like Fig. 2 of Moon et al. (2007); a vertical line marks where the last jump
landed. The legend names every run (mode, R, seed, jumps, end status if not completed).
Exit 2 with a message for a missing file, a file that is not an efdem run file, or one without
samples. Needs Debian's python3-matplotlib, python3-h5py, python3-numpy and python3-scipy
(/usr/bin/python3).
"""
import argparse
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.lines import Line2D  # noqa: E402
from matplotlib.patches import Patch  # noqa: E402

import ensemble_bands  # noqa: E402  (scripts/ensemble_bands.py, beside this script)
import plot_layout  # noqa: E402
import run_files  # noqa: E402


def load(path):
    f = run_files.open_run(path, ["p", "samples/time", "samples/mean_icdf", "samples/variance"])
    with f:
        run = {
            "path": path,
            "mode": run_files.text(f.attrs["mode"]),
            "R": int(f.attrs.get("realizations", 1)),
            "seed": int(f.attrs.get("seed", 0)),
            "status": run_files.text(f.attrs.get("end_status", "?")),
            "species": run_files.text(f.attrs.get("observed_species", "light")),
            "p": f["p"][:],
            "t": f["samples/time"][:],
            "mean": run_files.get(f, "samples/mean_icdf")[:],
            "var": f["samples/variance"][:],
            "R_used": run_files.realizations_per_sample(f),
            "jumps": [],
        }
        if "cpi" in f and "t_end" in f["cpi"] and "dt" in f["cpi"]:
            t_end = f["cpi/t_end"][:]
            dt = f["cpi/dt"][:]
            # A rejected jump (adaptive CPI) was redone: it is not part of the trajectory.
            status = [run_files.text(s) for s in f["cpi/status"][:]] if "status" in f["cpi"] else [""] * len(dt)
            run["jumps"] = [(a, a + d) for a, d, s in zip(t_end, dt, status) if d > 0 and s != "rejected"]
    if run["mean"].ndim != 2 or run["mean"].shape[1] != len(run["p"]):
        raise run_files.UsageError(f"{path}: /samples/mean has shape {run['mean'].shape}, not (samples, {len(run['p'])})")
    return run


def run_label(run):
    mode = "CPI" if run["mode"] == "cpi" else run["mode"]
    label = f"{mode}: {os.path.basename(run['path'])} (R = {run['R']}, seed {run['seed']}"
    if run["mode"] == "cpi":
        label += f", {len(run['jumps'])} jump{'s' if len(run['jumps']) != 1 else ''}"
    if not run["status"].startswith("completed"):
        label += f", {run['status'][:40]}"
    label += ")"
    if run["R"] < 2:
        label += "; " + ensemble_bands.NO_BAND_LABEL
    return label


def segments(t, jumps):
    """Index ranges of t between projective jumps (a burst is a contiguous run of samples)."""
    cuts = sorted(b for _, b in jumps)
    out, start = [], 0
    for c in cuts:
        k = np.searchsorted(t, c - 1e-9)
        if k > start:
            out.append((start, k))
            start = k
    out.append((start, len(t)))
    return [s for s in out if s[1] > s[0]]


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("runs", nargs="+", help="efdem run files (.h5)")
    ap.add_argument("-o", "--output", default="icdf.png", help="PNG file to write")
    ap.add_argument("--nodes", nargs="*", type=float, default=[0.1, 0.3, 0.5, 0.7, 0.9],
                    help="p values of the ICDF nodes to draw (nearest grid node is used)")
    ap.add_argument("--title", default=None)
    args = ap.parse_args(argv)

    try:
        runs = [load(p) for p in args.runs]
    except run_files.UsageError as e:
        run_files.fail("plot_icdf", e)
    fig, ax = plt.subplots(figsize=(12, 5.5), dpi=120)
    # The line style says the mode; a second run of the same mode gets the next variant.
    mode_styles = {"direct": [dict(lw=1.2, ls="-"), dict(lw=1.2, ls=(0, (1, 1)))],
                   "cpi": [dict(lw=2.2, ls="--"), dict(lw=2.2, ls="-.")]}
    seen = {}
    colors = plt.rcParams["axes.prop_cycle"].by_key()["color"]
    handles = []
    for run in runs:
        variants = mode_styles.get(run["mode"], [dict(lw=1.6, ls=":")])
        style = variants[seen.get(run["mode"], 0) % len(variants)]
        seen[run["mode"]] = seen.get(run["mode"], 0) + 1
        p = run["p"]
        for j, target in enumerate(args.nodes):
            i = int(np.argmin(np.abs(p - target)))
            color = colors[j % len(colors)]
            half = ensemble_bands.half_width(run["var"][:, i], run["R_used"])  # NaN where R < 2
            for a, b in segments(run["t"], run["jumps"]):
                t = run["t"][a:b]
                m = run["mean"][a:b, i]
                ax.plot(t, m, color=color, alpha=0.9, **style)
                if np.isfinite(half[a:b]).any():
                    ax.fill_between(t, m - half[a:b], m + half[a:b], color=color, alpha=0.15, lw=0)
            for t0, t1 in run["jumps"]:
                k0 = np.searchsorted(run["t"], t0 - 1e-9)
                k1 = np.searchsorted(run["t"], t1 - 1e-9)
                if k0 < len(run["t"]) and k1 < len(run["t"]):
                    ax.plot([run["t"][k0], run["t"][k1]], [run["mean"][k0, i], run["mean"][k1, i]],
                            color=color, lw=0.8, ls=":")
        handles.append(Line2D([], [], color="black", **style, label=run_label(run)))
        line = f"plot_icdf: {run_label(run)}: line style {style['ls']!r}"
        if run["jumps"]:
            last = max(t1 for _, t1 in run["jumps"])
            line += f", last projective jump lands at t = {last:.4g}"
            ax.axvline(last, color="grey", lw=1.0, ls=style["ls"])
            handles.append(Line2D([], [], color="grey", lw=1.0, ls=style["ls"],
                                  label=f"last projective jump of {os.path.basename(run['path'])} "
                                        f"(lands at t = {last:.4g})"))
        print(line)
    p0 = runs[0]["p"]
    for j, target in enumerate(args.nodes):
        i = int(np.argmin(np.abs(p0 - target)))
        handles.append(Line2D([], [], color=colors[j % len(colors)], lw=4, label=f"p = {p0[i]:.2f}"))
    if any(r["R"] > 1 for r in runs):
        handles.append(Patch(color="0.5", alpha=0.3, lw=0, label=f"band: {ensemble_bands.BAND_LABEL}\n"
                             r"(mean $\pm$ t(0.975, R$-$1) s/$\sqrt{R}$, s the realizations' sample std)"))
    species = runs[0]["species"]
    ax.set_xlabel(r"time  [$\sqrt{d_p/g}$]")
    ax.set_ylabel(f"height of the {species} particles, ICDF $Q(p)$  [$d_p$]")
    ax.set_title(args.title or "Ensemble-mean ICDF of particle heights")
    ax.grid(alpha=0.3)
    plot_layout.legend_beside(fig, handles, side="right")
    try:
        fig.savefig(args.output)
    except OSError as e:
        run_files.fail("plot_icdf", f"-o {args.output}: cannot be written ({e.strerror or e})")
    print(f"plot_icdf: wrote {args.output}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
