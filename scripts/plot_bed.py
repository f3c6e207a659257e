#!/usr/bin/python3
"""Plot the bed quantities an efdem run recorded with observe.bed = true: the pressure drop
over the bed weight per area, the bed height, each species' mean height and the Lacey mixing
index against time, and the solid-fraction profile phi(z) at a few times. Ensemble means as
lines, the realizations' range as a band.

    /usr/bin/python3 scripts/plot_bed.py RUN.h5 [RUN2.h5 ...] -o bed.png [--profiles 4]

Needs Debian's python3-matplotlib, python3-h5py and python3-numpy (run it with /usr/bin/python3).
Exit code 2 with a message for a file that is missing, not an HDF5 run file, or has no /bed.
"""
import argparse
import os
import sys

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import run_files  # noqa: E402

try:
    import h5py  # noqa: F401  (run_files opens the files with it)
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
except ImportError as e:  # another python3 than Debian's
    sys.exit(f"plot_bed.py: {e}; run it with /usr/bin/python3 (Debian python3-matplotlib python3-h5py)")


def load(path):
    with run_files.open_run(path, ["samples/time"]) as f:
        if "bed" not in f:
            raise run_files.UsageError(f"{path}: no /bed group: the run did not record the bed quantities "
                                       "(run it with observe.bed=true)")
        b = f["bed"]
        return {
            "name": os.path.basename(path), "mode": run_files.text(f.attrs["mode"]),
            "R": int(f.attrs.get("realizations", 1)), "t": f["samples/time"][:],
            "ratio": b["pressure_drop_ratio"][:], "height": b["height"][:], "mixing": b["mixing_index"][:],
            "species_height": b["species_height"][:], "species": [run_files.text(v) for v in b["species"][:]],
            "phi": b["mean/solid_fraction"][:], "z": b["z"][:], "dz": float(b.attrs["profile_dz"]),
        }


def band(ax, t, rows, label, style, colour=None):
    mean = np.nanmean(rows, axis=1)
    line, = ax.plot(t, mean, style, color=colour, lw=1.2, label=label)
    if rows.shape[1] > 1:
        ax.fill_between(t, np.nanmin(rows, axis=1), np.nanmax(rows, axis=1), color=line.get_color(), alpha=0.15, lw=0)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("runs", nargs="+", metavar="RUN.h5")
    ap.add_argument("-o", "--output", default="bed.png")
    ap.add_argument("--profiles", type=int, default=4, help="phi(z) at this many times (first run)")
    a = ap.parse_args(argv)
    try:
        runs = [load(p) for p in a.runs]
    except run_files.UsageError as e:
        run_files.fail("plot_bed.py", e)
    fig, axes = plt.subplots(2, 3, figsize=(14, 7.5))
    ax_dp, ax_h, ax_mix, ax_sp, ax_phi, ax_exp = axes.ravel()
    styles = ["-", "--", ":", "-."]
    for k, r in enumerate(runs):
        s = styles[k % len(styles)]
        label = f"{r['name']} ({r['mode']}, R = {r['R']})"
        band(ax_dp, r["t"], r["ratio"], label, s)
        band(ax_h, r["t"], r["height"], label, s)
        band(ax_mix, r["t"], r["mixing"], label, s)
        for j, name in enumerate(r["species"]):
            band(ax_sp, r["t"], r["species_height"][:, :, j], f"{name}, {r['name']}", s, f"C{j}")
        band(ax_exp, r["t"], r["height"] / r["height"][0], label, s)
    first = runs[0]
    n = len(first["t"])
    picks = sorted(set(np.linspace(0, n - 1, max(1, a.profiles)).round().astype(int)))
    for i in picks:
        ax_phi.plot(first["phi"][i], first["z"], lw=1.2, label=f"t = {first['t'][i]:.4g}")
    ax_dp.axhline(1.0, color="0.5", lw=0.8)
    ax_dp.set(xlabel=r"t [$\sqrt{d_p/g}$]", ylabel=r"$\Delta P\,/\,(W/A)$ [-]", title="pressure drop / bed weight per area")
    ax_h.set(xlabel=r"t [$\sqrt{d_p/g}$]", ylabel=r"bed height H$_{99}$ [$d_p$]", title="bed height (99 % of the solid volume below)")
    ax_mix.set(xlabel=r"t [$\sqrt{d_p/g}$]", ylabel="Lacey index M [-]", title="mixing index (1 mixed, 0 segregated)")
    ax_sp.set(xlabel=r"t [$\sqrt{d_p/g}$]", ylabel=r"mean height [$d_p$]", title="mean height of each species")
    ax_exp.set(xlabel=r"t [$\sqrt{d_p/g}$]", ylabel=r"H / H(first sample) [-]", title="bed expansion")
    ax_phi.set(xlabel=r"solid fraction $\phi$ [-]", ylabel=r"z [$d_p$]",
               title=f"$\\phi(z)$, ensemble mean of {first['name']} (slabs of {first['dz']:g} $d_p$)")
    for ax in axes.ravel():
        ax.grid(alpha=0.3)
        ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(a.output, dpi=110)
    print(f"plot_bed.py: wrote {a.output}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
