#!/usr/bin/python3
"""Plot the bed quantities an efdem run recorded with observe.bed = true: the pressure drop
over the bed weight per area, the bed height, each species' mean height and the Lacey mixing
index against time, and the solid-fraction profile phi(z) at a few times. Ensemble means as
lines, with the 95 % Student-t interval of the mean of the R realizations as a band (as in
plot_icdf.py, scripts/ensemble_bands.py; none for R = 1). One legend below the panels says what
every colour, line style and band means: a run is a colour and a line style in every time panel
(the species panel keeps the run's line style and gives each species its own colour, none of the
runs' colours), the phi(z) times are shades of grey.

    /usr/bin/python3 scripts/plot_bed.py RUN.h5 [RUN2.h5 ...] -o bed.png [--profiles 4]

Needs Debian's python3-matplotlib, python3-h5py, python3-numpy and python3-scipy (run it with
/usr/bin/python3).
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
    from matplotlib.lines import Line2D
    from matplotlib.patches import Patch

    import ensemble_bands
    import plot_layout
except ImportError as e:  # another python3 than Debian's
    sys.exit(f"plot_bed.py: {e}; run it with /usr/bin/python3 (Debian python3-matplotlib python3-h5py python3-scipy)")

# One meaning per colour: runs take RUN_COLOURS (with STYLES) in every time panel; species take
# SPECIES_COLOURS, none of the runs'; the phi(z) profiles' times are greys.
RUN_COLOURS = ["C0", "C1", "C9", "C8"]
SPECIES_COLOURS = ["C2", "C4", "C5", "C6"]
STYLES = ["-", "--", ":", "-."]


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
            "phi": run_files.get(f, "bed/ensemble_mean/solid_fraction")[:], "z": b["z"][:], "dz": float(b.attrs["profile_dz"]),
        }


def band(ax, t, rows, style, colour):
    """The mean of rows (samples, realizations; NaN for a dropped one) and its 95 % interval."""
    mean, half = ensemble_bands.sample_half_width(rows)
    ax.plot(t, mean, style, color=colour, lw=1.2)
    if np.isfinite(half).any():
        ax.fill_between(t, mean - half, mean + half, color=colour, alpha=0.15, lw=0)


def legend_entries(runs, first, picks):
    """The figure legend: runs, species, the band's meaning, the phi(z) times."""
    handles = []
    for k, r in enumerate(runs):
        label = f"{r['name']} ({r['mode']}, R = {r['R']})"
        if r["R"] < 2:
            label += "; " + ensemble_bands.NO_BAND_LABEL
        handles.append(Line2D([], [], color=RUN_COLOURS[k % len(RUN_COLOURS)], ls=STYLES[k % len(STYLES)],
                              label=label))
    for j, name in enumerate(first["species"]):
        handles.append(Line2D([], [], color=SPECIES_COLOURS[j % len(SPECIES_COLOURS)], lw=3,
                              label=f"{name} species (mean height panel; line style: the run)"))
    if any(r["R"] > 1 for r in runs):
        handles.append(Patch(color="0.5", alpha=0.3, lw=0, label=f"band: {ensemble_bands.BAND_LABEL}"))
    for n, i in enumerate(picks):
        handles.append(Line2D([], [], color=grey(n, len(picks)), lw=1.2,
                              label=f"$\\phi(z)$ at t = {first['t'][i]:.4g}"))
    return handles


def grey(n, count):
    return str(0.7 - 0.7 * n / max(count - 1, 1))


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
    fig, axes = plt.subplots(2, 3, figsize=(14, 8.5))
    ax_dp, ax_h, ax_mix, ax_sp, ax_phi, ax_exp = axes.ravel()
    for k, r in enumerate(runs):
        s, c = STYLES[k % len(STYLES)], RUN_COLOURS[k % len(RUN_COLOURS)]
        band(ax_dp, r["t"], r["ratio"], s, c)
        band(ax_h, r["t"], r["height"], s, c)
        band(ax_mix, r["t"], r["mixing"], s, c)
        for j in range(len(r["species"])):
            band(ax_sp, r["t"], r["species_height"][:, :, j], s, SPECIES_COLOURS[j % len(SPECIES_COLOURS)])
        band(ax_exp, r["t"], r["height"] / r["height"][0], s, c)
    first = runs[0]
    n = len(first["t"])
    picks = sorted(set(np.linspace(0, n - 1, max(1, a.profiles)).round().astype(int)))
    for m, i in enumerate(picks):
        ax_phi.plot(first["phi"][i], first["z"], lw=1.2, color=grey(m, len(picks)))
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
    plot_layout.legend_beside(fig, legend_entries(runs, first, picks), side="bottom", ncol=3)
    fig.savefig(a.output, dpi=110)
    print(f"plot_bed.py: wrote {a.output}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
