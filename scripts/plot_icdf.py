#!/usr/bin/python3
"""Plot the evolution of the ensemble-mean ICDF of an efdem run, with confidence bands, and
overlay several runs (e.g. a direct and a CPI ensemble of the same scene).

    /usr/bin/python3 scripts/plot_icdf.py RUN.h5 [RUN2.h5 ...] -o icdf.png [--nodes 0.1 0.5 0.9]

Each selected node p_i is drawn as a line Q(p_i)(t) with a 95 % band of the ensemble mean
(mean +- 1.96 sqrt(variance / R)). CPI runs show as bursts (their samples) separated by the
projective jumps, drawn as thin dotted connectors, like Fig. 2 of Moon et al. (2007).
Needs Debian's python3-matplotlib, python3-h5py and python3-numpy (run it with /usr/bin/python3).
"""
import argparse
import sys

import h5py
import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402


def load(path):
    with h5py.File(path, "r") as f:
        run = {
            "path": path,
            "mode": f.attrs["mode"],
            "R": int(f.attrs["realizations"]),
            "species": f.attrs.get("observed_species", "light"),
            "p": f["p"][:],
            "t": f["samples/time"][:],
            "mean": f["samples/mean"][:],
            "var": f["samples/variance"][:],
            "jumps": [],
        }
        if "cpi" in f and "t_end" in f["cpi"]:
            t_end = f["cpi/t_end"][:]
            dt = f["cpi/dt"][:]
            # A rejected jump (adaptive CPI) was redone: it is not part of the trajectory.
            status = [s.decode() if isinstance(s, bytes) else str(s) for s in f["cpi/status"][:]] \
                if "status" in f["cpi"] else [""] * len(dt)
            run["jumps"] = [(a, a + d) for a, d, s in zip(t_end, dt, status) if d > 0 and s != "rejected"]
    return run


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

    runs = [load(p) for p in args.runs]
    fig, ax = plt.subplots(figsize=(8, 5.5), dpi=120)
    styles = [dict(lw=1.2, alpha=0.9), dict(lw=2.6, alpha=0.85), dict(lw=1.8, ls="--", alpha=0.9)]
    colors = plt.rcParams["axes.prop_cycle"].by_key()["color"]
    for k, run in enumerate(runs):
        style = styles[k % len(styles)]
        p = run["p"]
        for j, target in enumerate(args.nodes):
            i = int(np.argmin(np.abs(p - target)))
            color = colors[j % len(colors)]
            half = 1.96 * np.sqrt(run["var"][:, i] / max(run["R"], 1))
            label_done = False
            for a, b in segments(run["t"], run["jumps"]):
                t = run["t"][a:b]
                m = run["mean"][a:b, i]
                lbl = None
                if not label_done:
                    lbl = f"{run['mode']} (R={run['R']}), p = {p[i]:.2f}"
                    label_done = True
                ax.plot(t, m, color=color, lw=style["lw"], ls=style.get("ls", "-"), alpha=style["alpha"], label=lbl)
                if run["R"] > 1:
                    ax.fill_between(t, m - half[a:b], m + half[a:b], color=color, alpha=0.15, lw=0)
            for t0, t1 in run["jumps"]:
                k0 = np.searchsorted(run["t"], t0 - 1e-9)
                k1 = np.searchsorted(run["t"], t1 - 1e-9)
                if k0 < len(run["t"]) and k1 < len(run["t"]):
                    ax.plot([run["t"][k0], run["t"][k1]], [run["mean"][k0, i], run["mean"][k1, i]],
                            color=color, lw=0.8, ls=":")
    species = runs[0]["species"]
    ax.set_xlabel(r"time  [$\sqrt{d_p/g}$]")
    ax.set_ylabel(f"height of the {species} particles, ICDF $Q(p)$  [$d_p$]")
    ax.set_title(args.title or "Ensemble-mean ICDF of particle heights (bands: 95 % of the mean)")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=7, ncol=2, loc="best")
    fig.tight_layout()
    fig.savefig(args.output)
    print(f"plot_icdf: wrote {args.output}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
